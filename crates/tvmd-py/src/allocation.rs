//! Control allocation: `tvmd.allocate` and `tvmd.Allocation`, over the core's allocators
//! chosen by name at run time (`tvmd_core::AnyAllocator`).

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use tvmd_core::admissible::admissible_sets;
use tvmd_core::allocation::{
    AllocatorOptions, CLARABEL, CLARABEL_SEQUENTIAL, WEIGHTED_PSEUDO_INVERSE,
};
use tvmd_core::{AdmissibleSet, Allocation, AllocationRequest, Allocator, AnyAllocator};
use tvmd_core::{ConfigError, ConfigField, GimbalCommand, RateLimits};

use crate::convert::{arg, array, check_finite, class_arg, finite, finite_scalar, matrix};
use crate::convert::{round_cap_arg, shape_error, shaped, CAPACITY};
use crate::errors::{config_error, ConfigError as PyConfigError, OrRaise};
use crate::record::record;
use crate::team::{failure_mask, PyTeam};
use tvmd_core::RoundCap;

/// Names of the allocators this build provides (the core's one table).
pub(crate) const ALLOCATORS: &[&str] = AnyAllocator::<f64, CAPACITY>::NAMES;

/// The allocator named `method` for a team of `n` agents ([`AnyAllocator::from_name`]).
/// `weights` are per-agent weights (n,) or wrench weights (6,), depending on the allocator;
/// `max_rounds` caps the exact-boundary redistribution's walk (`None`: the default cap).
pub(crate) fn make_allocator(
    method: &str,
    weights: Option<&Bound<'_, PyAny>>,
    regularization: Option<f64>,
    max_rounds: Option<RoundCap>,
    n: usize,
) -> PyResult<AnyAllocator<f64, CAPACITY>> {
    let mut options = AllocatorOptions::<f64, CAPACITY> {
        regularization,
        max_rounds,
        ..Default::default()
    };
    match (method, weights.filter(|w| !w.is_none())) {
        (WEIGHTED_PSEUDO_INVERSE, None) => {
            return Err(PyValueError::new_err(format!(
                "allocator '{WEIGHTED_PSEUDO_INVERSE}' needs `weights`, shape ({n},)"
            )))
        }
        (WEIGHTED_PSEUDO_INVERSE, Some(weights)) => {
            let w = array(weights, "weights")?;
            if w.shape() != [n] {
                return Err(shape_error("weights", &format!("({n},)"), w.shape()));
            }
            let mut padded = [1.0; CAPACITY];
            padded.iter_mut().zip(&w).for_each(|(slot, w)| *slot = *w);
            options.agent_weights = Some(padded);
        }
        (CLARABEL | CLARABEL_SEQUENTIAL, Some(weights)) if cfg!(feature = "clarabel") => {
            options.wrench_weights = Some(arg::<6, 1>(weights, "weights")?.into());
        }
        // Any other allocator refuses them (the core says so).
        (_, Some(_)) => options.agent_weights = Some([1.0; CAPACITY]),
        (_, None) => {}
    }
    AnyAllocator::from_name(method, &options).map_err(|e| match e {
        ConfigError::UnknownAllocator => PyValueError::new_err(format!(
            "unknown allocator '{method}'; expected one of: {}",
            ALLOCATORS.join(", ")
        )),
        ConfigError::AllocatorUnavailable { .. } => PyValueError::new_err(format!(
            "allocator '{method}' is not available: tvmd was built without the cargo feature \
`clarabel` (rebuild with `maturin build --features clarabel`)"
        )),
        ConfigError::UnusedOption { field } => {
            let option = match field {
                ConfigField::ClarabelLambda => "regularization",
                ConfigField::AllocatorMaxRounds => "max_rounds",
                _ => "weights",
            };
            PyValueError::new_err(format!("allocator '{method}' takes no `{option}`"))
        }
        e => config_error(e),
    })
}

/// The last solve report of a Clarabel allocator, as text.
pub(crate) fn report(allocator: &AnyAllocator<f64, CAPACITY>) -> Option<String> {
    #[cfg(feature = "clarabel")]
    match allocator {
        AnyAllocator::Clarabel(a) => return a.last_report().map(ToString::to_string),
        AnyAllocator::ClarabelSequential(a) => return a.last_report().map(ToString::to_string),
        _ => {}
    }
    let _ = allocator;
    None
}

/// Previous commands `(n, k)`, `k` in 2..=4, columns `eta_x, eta_y[, thrust, omega]` (so
/// `StepOutput.commands` can be passed as it is).
fn previous_commands(obj: &Bound<'_, PyAny>, n: usize) -> PyResult<Vec<GimbalCommand<f64>>> {
    let a = array(obj, "previous")?;
    let k = match a.shape() {
        [rows, k] if *rows == n && (2..=4).contains(k) => *k,
        other => {
            let expected = format!(
                "({n}, 2), ({n}, 3) or ({n}, 4) with columns eta_x, eta_y[, thrust, omega]"
            );
            return Err(shape_error("previous", &expected, other));
        }
    };
    check_finite(a.iter(), "previous")?;
    let values: Vec<f64> = a.iter().copied().collect();
    let command = |row: &[f64]| match *row {
        [eta_x, eta_y, ref rest @ ..] => GimbalCommand {
            eta_x,
            eta_y,
            thrust: rest.first().copied().unwrap_or(0.0),
        },
        _ => GimbalCommand::idle(),
    };
    Ok(values.chunks_exact(k).map(command).collect())
}

/// The rate-limit argument `(eta_x_rate, eta_y_rate)` (rad/s).
pub(crate) fn rate_limits_arg(obj: Option<&Bound<'_, PyAny>>) -> PyResult<Option<RateLimits<f64>>> {
    match obj.filter(|o| !o.is_none()) {
        Some(o) => {
            let r = arg::<2, 1>(o, "rate_limits")?;
            RateLimits::new(r.x, r.y).or_raise().map(Some)
        }
        None => Ok(None),
    }
}

#[doc = include_str!("../docstrings/tvmd.allocate.txt")]
#[pyfunction]
#[pyo3(signature = (team, wrench, method = "exact-boundary-redistribution", weights = None, failed = None, previous = None, rate_limits = None, dt = None, regularization = None, max_rounds = None))]
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
    max_rounds: Option<Bound<'_, PyAny>>,
) -> PyResult<PyAllocation> {
    let team = &class_arg::<PyTeam>(team, "team")?.get().inner;
    let n = team.len();
    let mut allocator = make_allocator(
        method,
        weights,
        regularization,
        round_cap_arg(max_rounds.as_ref())?,
        n,
    )?;
    let wrench = finite::<6, 1>(wrench, "wrench")?;
    let mask = failure_mask(team, failed)?;
    team.validate_failures(&mask).or_raise()?;

    let base = AdmissibleSet::from_limits(team.limits());
    let previous = previous.filter(|p| !p.is_none());
    let sets = match (rate_limits_arg(rate_limits)?, dt) {
        (Some(_), None) => return Err(PyValueError::new_err("`rate_limits` needs `dt`")),
        (Some(rates), Some(dt)) => {
            if finite_scalar(dt, "dt")? <= 0.0 {
                return Err(PyConfigError::new_err("`dt` must be positive and finite"));
            }
            let previous = match previous {
                Some(p) => previous_commands(p, n)?,
                None => vec![GimbalCommand::idle(); n],
            };
            admissible_sets(&base, Some((&rates, dt)), previous)
        }
        (None, Some(_)) => return Err(only_with_rate_limits()),
        (None, None) if previous.is_some() => return Err(only_with_rate_limits()),
        (None, None) => [base; CAPACITY],
    };

    let effectiveness = team.effectiveness(&mask);
    allocator.configure(&effectiveness);
    let request = AllocationRequest {
        effectiveness: &effectiveness,
        sets: &sets,
        wrench,
    };
    let allocation = allocator.allocate(&request);
    Ok(PyAllocation {
        inner: AllocationData::new(allocation, n, &allocator),
    })
}

fn only_with_rate_limits() -> PyErr {
    PyValueError::new_err("`previous` and `dt` only apply with `rate_limits`")
}

/// A core allocation with the agent count, the allocator's name and Clarabel's report.
#[derive(Clone)]
pub(crate) struct AllocationData {
    allocation: Allocation<f64, CAPACITY>,
    n: usize,
    method: &'static str,
    report: Option<String>,
}

impl AllocationData {
    /// A record of its parts (a pickled `StepOutput`'s).
    pub(crate) fn from_parts(
        allocation: Allocation<f64, CAPACITY>,
        n: usize,
        method: &'static str,
        report: Option<String>,
    ) -> Self {
        Self {
            allocation,
            n,
            method,
            report,
        }
    }

    /// The allocator's name and its report.
    pub(crate) fn method_and_report(&self) -> (&'static str, Option<String>) {
        (self.method, self.report.clone())
    }

    pub(crate) fn new(
        allocation: Allocation<f64, CAPACITY>,
        n: usize,
        allocator: &AnyAllocator<f64, CAPACITY>,
    ) -> Self {
        let (method, report) = (allocator.name(), report(allocator));
        Self {
            allocation,
            n,
            method,
            report,
        }
    }
}

record! {
    /// The result of one allocation.
    "Allocation" in "tvmd" => PyAllocation(AllocationData) |py, o| {
        /// (n, 3) agent-frame forces.
        forces => shaped(py, o.allocation.forces.iter().take(o.n).flat_map(|f| f.iter().copied()).collect(), &[o.n, 3])?,
        /// (6,) `M f`.
        wrench => matrix(py, &o.allocation.wrench)?,
        /// `||u_fd - u_f||`.
        e_f => o.allocation.e_f,
        /// `||u_d - M f||`.
        wrench_error => o.allocation.wrench_error,
        /// Solve rounds.
        rounds => o.allocation.rounds,
        /// (n,) saturated agents.
        saturated => shaped(py, o.allocation.saturated.iter().take(o.n).copied().collect(), &[o.n])?,
        /// The allocator fell back to the redistributed pseudo-inverse.
        fallback => o.allocation.fallback,
        /// The allocator's name.
        method => o.method,
        /// Clarabel's solve report, None otherwise.
        report => o.report.clone(),
    }
}

/// Registers `allocate` and `Allocation`.
pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyAllocation>()?;
    m.add_function(wrap_pyfunction!(allocate, m)?)?;
    Ok(())
}
