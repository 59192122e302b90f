//! Control allocation: `tvmd.allocate` and `tvmd.Allocation`, over the core's allocators
//! chosen by name at run time (`tvmd_core::AnyAllocator`).

use nalgebra::{Vector3, Vector6};
use numpy::{PyArray1, PyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use tvmd_core::admissible::admissible_sets;
use tvmd_core::allocation::{
    AllocatorOptions as CoreAllocatorOptions, CLARABEL, WEIGHTED_PSEUDO_INVERSE,
};
use tvmd_core::{
    AdmissibleSet, Allocation, AllocationRequest, Allocator, AnyAllocator, ConfigError,
    ConfigField, GimbalCommand, RateLimits,
};

use crate::convert::{
    any, array1, bool_array, check_finite, class_arg, finite_scalar, float_array, record_dict,
    record_repr, rows_array, shape_error, shape_str, vector6,
};
use crate::errors::OrRaise;
use crate::team::{failure_mask, PyTeam};
use crate::CAPACITY;

/// Names of the allocators this build provides (the core's one table).
pub(crate) const ALLOCATORS: &[&str] = AnyAllocator::<f64, CAPACITY>::NAMES;

/// The default allocator (also the controller's).
pub(crate) const DEFAULT_ALLOCATOR: &str = AnyAllocator::<f64, CAPACITY>::DEFAULT_NAME;

/// Options of the allocators that take any.
pub(crate) struct AllocatorOptions<'a, 'py> {
    /// Per-agent weights `w_i` (n,) of "weighted-pseudo-inverse", or the wrench weights `W`
    /// (6,) of "clarabel".
    pub(crate) weights: Option<&'a Bound<'py, PyAny>>,
    /// `lambda` of "clarabel".
    pub(crate) regularization: Option<f64>,
}

/// Builds the allocator named `method` for a team of `n` agents
/// ([`AnyAllocator::from_name`]); returns it with its name.
pub(crate) fn make_allocator(
    method: &str,
    options: &AllocatorOptions<'_, '_>,
    n: usize,
) -> PyResult<(AnyAllocator<f64, CAPACITY>, &'static str)> {
    let weights = options.weights.filter(|w| !w.is_none());
    let mut core_options = CoreAllocatorOptions::<f64, CAPACITY> {
        regularization: options.regularization,
        ..Default::default()
    };
    // `weights` means per-agent weights or wrench weights depending on the allocator.
    match (method, weights) {
        (WEIGHTED_PSEUDO_INVERSE, None) => {
            return Err(PyValueError::new_err(format!(
                "allocator '{WEIGHTED_PSEUDO_INVERSE}' needs `weights`, shape ({n},)"
            )))
        }
        (WEIGHTED_PSEUDO_INVERSE, Some(weights)) => {
            let view = float_array(weights, "weights")?;
            let array = view.as_array();
            if array.shape() != [n] {
                return Err(shape_error("weights", &shape_str(&[n]), array.shape()));
            }
            let mut padded = [1.0; CAPACITY];
            for (slot, w) in padded.iter_mut().zip(array.iter()) {
                *slot = *w;
            }
            core_options.agent_weights = Some(padded);
        }
        (CLARABEL, Some(weights)) if cfg!(feature = "clarabel") => {
            core_options.wrench_weights = Some(vector6(weights, "weights")?);
        }
        // Any other allocator refuses them (the core says so).
        (_, Some(_)) => core_options.agent_weights = Some([1.0; CAPACITY]),
        (_, None) => {}
    }
    let allocator = AnyAllocator::from_name(method, &core_options).map_err(|e| match e {
        ConfigError::UnknownAllocator => PyValueError::new_err(format!(
            "unknown allocator '{method}'; expected one of: {}",
            ALLOCATORS.join(", ")
        )),
        ConfigError::AllocatorUnavailable { .. } => PyValueError::new_err(
            "allocator 'clarabel' is not available: tvmd was built without the cargo feature \
`clarabel` (rebuild with `maturin build --features clarabel`)",
        ),
        ConfigError::UnusedOption { field } => PyValueError::new_err(format!(
            "allocator '{method}' takes no `{}`",
            if field == ConfigField::ClarabelLambda {
                "regularization"
            } else {
                "weights"
            }
        )),
        e => crate::errors::ConfigError::new_err(e.to_string()),
    })?;
    let name = allocator.name();
    Ok((allocator, name))
}

/// The last solve report of a Clarabel allocator, as text.
#[cfg(feature = "clarabel")]
pub(crate) fn report(allocator: &AnyAllocator<f64, CAPACITY>) -> Option<String> {
    match allocator {
        AnyAllocator::Clarabel(a) => a.last_report().map(ToString::to_string),
        _ => None,
    }
}

/// The last solve report of a Clarabel allocator, as text (none in this build).
#[cfg(not(feature = "clarabel"))]
pub(crate) fn report(_allocator: &AnyAllocator<f64, CAPACITY>) -> Option<String> {
    None
}

/// Per-agent previous gimbal commands: `(n, k)`, `k` in 2..=4, columns `eta_x, eta_y[, thrust,
/// omega]` (so `StepOutput.commands` can be passed as it is).
fn previous_commands(obj: &Bound<'_, PyAny>, n: usize) -> PyResult<Vec<GimbalCommand<f64>>> {
    let view = float_array(obj, "previous")?;
    let array = view.as_array();
    let k = match array.shape() {
        [rows, k] if *rows == n && (2..=4).contains(k) => *k,
        other => {
            return Err(shape_error(
                "previous",
                &format!(
                    "({n}, 2), ({n}, 3) or ({n}, 4) with columns eta_x, eta_y[, thrust, omega]"
                ),
                other,
            ))
        }
    };
    check_finite(array.iter(), "previous")?;
    let values: Vec<f64> = array.iter().copied().collect();
    Ok(values
        .chunks_exact(k)
        .map(|row| GimbalCommand {
            eta_x: row.first().copied().unwrap_or(0.0),
            eta_y: row.get(1).copied().unwrap_or(0.0),
            thrust: row.get(2).copied().unwrap_or(0.0),
        })
        .collect())
}

/// The rate-limit argument `(eta_x_rate, eta_y_rate)` (rad/s).
pub(crate) fn rate_limits_arg(obj: Option<&Bound<'_, PyAny>>) -> PyResult<Option<RateLimits<f64>>> {
    match obj {
        Some(o) if !o.is_none() => {
            let [x, y] = crate::convert::fixed::<2>(o, "rate_limits", &[2])?;
            RateLimits::new(x, y).or_raise().map(Some)
        }
        _ => Ok(None),
    }
}

/// Allocates a desired wrench `u_d` over the team's working agents: inverts `u_d = M f`
/// (eq. 4) into agent-frame forces inside each agent's admissible set `E_f` (eq. 6).
///
/// Methods:
///     "pseudo-inverse": `f = M^T (M M^T)^-1 u_d`, then each agent outside `E_f` is clamped.
///     "weighted-pseudo-inverse": minimizes `sum_i w_i ||f_i||^2` s.t. `M f = u_d`, clamped;
///         `weights` (n,) positive per-agent weights are required.
///     "redistributed-pseudo-inverse" (default): Jin 2005 redistribution: the agent leaving
///         `E_f` furthest is saturated and fixed, the rest of the wrench is redistributed.
///     "clarabel": `min ||W (M f - u_d)||^2 + lambda ||f||^2` over a convex inner bound of
///         `E_f` (SOC-constrained QP); needs the cargo feature `clarabel`. `weights` (6,) is the
///         diagonal of `W`, `regularization` is `lambda` (default 1e-6).
///
/// Args:
///     team: the `Team`.
///     wrench: (6,) desired wrench `u_d = [u_tau; u_f]` in the team frame.
///     method: the allocator name (see `tvmd.ALLOCATORS`).
///     weights: see the methods.
///     failed: None or failed agent indices (they get zero force).
///     previous: (n, 2..4) previous commands, columns `eta_x, eta_y[, thrust, omega]`; only
///         with `rate_limits` (default: centred gimbals).
///     rate_limits: `(eta_x_rate, eta_y_rate)` (rad/s): narrows each gimbal range to
///         `|eta - eta_prev| <= rate dt`.
///     dt: the control period (s), required with `rate_limits`.
///     regularization: `lambda` of "clarabel".
///
/// Returns:
///     Allocation(forces, wrench, e_f, wrench_error, rounds, saturated, fallback, method, report).
///
/// Raises:
///     ValueError: an unknown method, "clarabel" without the feature, options that do not
///         apply to the method, wrong shapes, NaN/inf input.
///     ConfigError: a degraded team that cannot produce every wrench, bad weights or rates.
#[pyfunction]
#[pyo3(signature = (team, wrench, method = DEFAULT_ALLOCATOR, weights = None, failed = None, previous = None, rate_limits = None, dt = None, regularization = None))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn allocate(
    team: &Bound<'_, PyAny>,
    wrench: &Bound<'_, PyAny>,
    method: &str,
    weights: Option<&Bound<'_, PyAny>>,
    failed: Option<&Bound<'_, PyAny>>,
    previous: Option<&Bound<'_, PyAny>>,
    rate_limits: Option<&Bound<'_, PyAny>>,
    dt: Option<f64>,
    regularization: Option<f64>,
) -> PyResult<PyAllocation> {
    let team = &class_arg::<PyTeam>(team, "team")?.get().inner;
    let n = team.len();
    let options = AllocatorOptions {
        weights,
        regularization,
    };
    let (mut allocator, name) = make_allocator(method, &options, n)?;
    let u_d = vector6(wrench, "wrench")?;
    check_finite(u_d.iter(), "wrench")?;
    let mask = failure_mask(team, failed)?;
    team.validate_failures(&mask).or_raise()?;

    let base = AdmissibleSet::from_limits(team.limits());
    let mut sets = [base; CAPACITY];
    let previous = previous.filter(|p| !p.is_none());
    match rate_limits_arg(rate_limits)? {
        Some(rates) => {
            let dt = dt.ok_or_else(|| PyValueError::new_err("`rate_limits` needs `dt`"))?;
            finite_scalar(dt, "dt")?;
            if dt <= 0.0 {
                return Err(crate::errors::ConfigError::new_err(
                    "`dt` must be positive and finite",
                ));
            }
            let previous = match previous {
                Some(p) => previous_commands(p, n)?,
                None => vec![GimbalCommand::idle(); n],
            };
            sets = admissible_sets(&base, Some((&rates, dt)), previous);
        }
        None => {
            if previous.is_some() || dt.is_some() {
                return Err(PyValueError::new_err(
                    "`previous` and `dt` only apply with `rate_limits`",
                ));
            }
        }
    }

    let effectiveness = team.effectiveness(&mask);
    allocator.configure(&effectiveness);
    let request = AllocationRequest {
        effectiveness: &effectiveness,
        sets: &sets,
        wrench: Vector6::from(u_d),
    };
    let allocation = allocator.allocate(&request);
    Ok(PyAllocation::new(&allocation, n, name, report(&allocator)))
}

/// The result of one allocation.
///
/// Attributes:
///     forces: (n, 3) agent-frame forces `f_i`, each inside its admissible set (zero for
///         failed agents).
///     wrench: (6,) `u = M f`, the wrench they produce.
///     e_f: `||u_fd - u_f||`, the paper's allocation error (force part).
///     wrench_error: `||u_d - M f||` over the whole wrench.
///     rounds: solve rounds (pseudo-inverse 1, redistribution up to n, Clarabel iterations).
///     saturated: (n,) bool, agents saturated onto the boundary of their admissible set.
///     fallback: the allocator fell back to the redistributed pseudo-inverse (Clarabel).
///     method: the allocator's name.
///     report: Clarabel's solve report (text), None for the other allocators.
#[pyclass(module = "tvmd", name = "Allocation", frozen)]
pub struct PyAllocation {
    forces: Vec<[f64; 3]>,
    wrench: [f64; 6],
    e_f: f64,
    wrench_error: f64,
    rounds: u32,
    saturated: Vec<bool>,
    fallback: bool,
    method: &'static str,
    report: Option<String>,
}

impl PyAllocation {
    /// The first `n` agents of a core allocation.
    pub(crate) fn new(
        allocation: &Allocation<f64, CAPACITY>,
        n: usize,
        method: &'static str,
        report: Option<String>,
    ) -> Self {
        let mut wrench = [0.0; 6];
        for (w, x) in wrench.iter_mut().zip(allocation.wrench.iter()) {
            *w = *x;
        }
        Self {
            forces: allocation
                .forces
                .iter()
                .take(n)
                .map(|f: &Vector3<f64>| [f.x, f.y, f.z])
                .collect(),
            wrench,
            e_f: allocation.e_f,
            wrench_error: allocation.wrench_error,
            rounds: allocation.rounds,
            saturated: allocation.saturated.iter().take(n).copied().collect(),
            fallback: allocation.fallback,
            method,
            report,
        }
    }

    fn fields<'py>(&self, py: Python<'py>) -> PyResult<Vec<(&'static str, Bound<'py, PyAny>)>> {
        Ok(vec![
            ("forces", self.forces(py).into_any()),
            ("wrench", self.wrench(py).into_any()),
            ("e_f", any(py, self.e_f)?),
            ("wrench_error", any(py, self.wrench_error)?),
            ("rounds", any(py, self.rounds)?),
            ("saturated", self.saturated(py).into_any()),
            ("fallback", any(py, self.fallback)?),
            ("method", any(py, self.method)?),
            ("report", any(py, self.report.clone())?),
        ])
    }
}

#[pymethods]
impl PyAllocation {
    /// (n, 3) agent-frame forces.
    #[getter]
    fn forces<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        rows_array(py, &self.forces)
    }

    /// (6,) `u = M f`.
    #[getter]
    fn wrench<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        array1(py, &self.wrench)
    }

    /// `e_f = ||u_fd - u_f||`.
    #[getter]
    fn e_f(&self) -> f64 {
        self.e_f
    }

    /// `||u_d - M f||`.
    #[getter]
    fn wrench_error(&self) -> f64 {
        self.wrench_error
    }

    /// Solve rounds.
    #[getter]
    fn rounds(&self) -> u32 {
        self.rounds
    }

    /// (n,) saturated agents.
    #[getter]
    fn saturated<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<bool>> {
        bool_array(py, &self.saturated)
    }

    /// Whether the allocator fell back to the redistributed pseudo-inverse.
    #[getter]
    fn fallback(&self) -> bool {
        self.fallback
    }

    /// The allocator's name.
    #[getter]
    fn method(&self) -> &'static str {
        self.method
    }

    /// Clarabel's solve report, None otherwise.
    #[getter]
    fn report(&self) -> Option<String> {
        self.report.clone()
    }

    /// The fields as a dict.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        record_dict(py, self.fields(py)?)
    }

    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        record_repr("Allocation", &self.fields(py)?)
    }
}

/// Registers `allocate` and `Allocation`.
pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyAllocation>()?;
    m.add_function(wrap_pyfunction!(allocate, m)?)?;
    Ok(())
}
