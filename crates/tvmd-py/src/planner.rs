//! `tvmd.AttitudePlanner` (eqs. 9-11) and its `PlannerResult`.

use pyo3::prelude::*;

use tvmd_core::{AttitudePlanner, PlannerOutput, Relaxation};

use crate::afs::PyAfs;
use crate::convert::{class_arg, finite_matrix3, finite_vector3, matrix_array};
use crate::errors::OrRaise;
use crate::record::record;

/// Default iteration cap of the core's planner.
const DEFAULT_MAX_ITERATIONS: u32 = 64;

/// The iteration cap argument: default 64, else in `0..=u32::MAX` (0 is rejected by the core).
pub(crate) fn iteration_cap(value: Option<i64>) -> PyResult<u32> {
    match value {
        None => Ok(DEFAULT_MAX_ITERATIONS),
        Some(v) => u32::try_from(v).map_err(|_| {
            pyo3::exceptions::PyValueError::new_err(format!(
                "`max_iterations` must be in [1, 2**32), got {v}"
            ))
        }),
    }
}

/// The relaxation `s` from the keyword `relaxation` or its alias `s` (at most one of them),
/// else `default`.
pub(crate) fn relaxation_arg(
    relaxation: Option<f64>,
    s: Option<f64>,
    default: Option<f64>,
) -> PyResult<Relaxation<f64>> {
    let value = match (relaxation, s) {
        (Some(_), Some(_)) => {
            return Err(pyo3::exceptions::PyTypeError::new_err(
                "give `relaxation` or its alias `s`, not both",
            ))
        }
        (Some(v), None) | (None, Some(v)) => v,
        (None, None) => default.ok_or_else(|| {
            pyo3::exceptions::PyTypeError::new_err("missing required argument `relaxation`")
        })?,
    };
    Relaxation::new(value).or_raise()
}

/// The bisection attitude planner of eqs. (9)-(11): the smallest tilt `theta` of the reference
/// attitude `R_r` toward the force request `f_r` that makes `R_d^T f_r` attainable (in the AFS
/// with relaxation `s`). `b_zd = rot(b_zr, k, theta)`, `k = (b_zr x f_r)/||.||`,
/// `b_yd = (b_zd x b_xr)/||.||`, `b_xd = b_yd x b_zd`.
///
/// Returns the last *feasible* bisection point, stops on `tolerance` or `max_iterations`,
/// and rolls about `b_xr` when `f_r` is (anti)parallel to `b_zr`.
///
/// Args:
///     relaxation: AFS relaxation `s` in (0, 1] (`s=` is an alias).
///     tolerance: bisection tolerance on `theta` (rad); default `max(1e-10, 8 eps)`.
///     max_iterations: bisection iteration cap (>= 1); default 64.
///
/// Raises:
///     ConfigError: `s` outside (0, 1], a non-positive tolerance or a zero iteration cap.
#[pyclass(module = "tvmd", name = "AttitudePlanner", frozen)]
pub struct PyAttitudePlanner {
    inner: AttitudePlanner<f64>,
    max_iterations: u32,
}

#[pymethods]
impl PyAttitudePlanner {
    #[new]
    #[pyo3(signature = (relaxation = None, tolerance = None, max_iterations = None, *, s = None))]
    fn new(
        relaxation: Option<f64>,
        tolerance: Option<f64>,
        max_iterations: Option<i64>,
        s: Option<f64>,
    ) -> PyResult<Self> {
        let planner = AttitudePlanner::new(relaxation_arg(relaxation, s, None)?);
        let max_iterations = iteration_cap(max_iterations)?;
        let inner = planner
            .with_tolerance(tolerance.unwrap_or(planner.tolerance()), max_iterations)
            .or_raise()?;
        Ok(Self {
            inner,
            max_iterations,
        })
    }

    /// The relaxation `s`.
    #[getter]
    fn relaxation(&self) -> f64 {
        self.inner.relaxation().get()
    }

    /// The bisection tolerance (rad).
    #[getter]
    fn tolerance(&self) -> f64 {
        self.inner.tolerance()
    }

    /// The bisection iteration cap.
    #[getter]
    fn max_iterations(&self) -> u32 {
        self.max_iterations
    }

    /// Plans `R_d` for the reference attitude `R_r` and the inertial force request
    /// `f_r = t_Tf R u_fr` (eq. 9).
    ///
    /// Args:
    ///     afs: the team's `AttainableForceSpace`.
    ///     R_r: (3, 3) reference attitude (body to inertial).
    ///     f_r: (3,) inertial force request (N).
    ///
    /// Returns:
    ///     PlannerResult(R_d, theta, iterations, status).
    ///
    /// Raises:
    ///     ValueError: wrong shapes, or NaN/inf inputs.
    #[allow(non_snake_case)]
    fn plan(
        &self,
        afs: &Bound<'_, PyAny>,
        R_r: &Bound<'_, PyAny>,
        f_r: &Bound<'_, PyAny>,
    ) -> PyResult<PyPlannerResult> {
        let r_r = finite_matrix3(R_r, "R_r")?;
        let f_r = finite_vector3(f_r, "f_r")?;
        let afs = class_arg::<PyAfs>(afs, "afs")?.get();
        let inner = self.inner.plan(&afs.inner.afs, &r_r, &f_r).or_raise()?;
        Ok(PyPlannerResult { inner })
    }

    fn __repr__(&self) -> String {
        format!(
            "AttitudePlanner(relaxation={}, tolerance={:e}, max_iterations={})",
            self.relaxation(),
            self.tolerance(),
            self.max_iterations
        )
    }
}

record! {
    /// The planner's output (eqs. 9-11).
    ///
    /// Attributes:
    ///     R_d: (3, 3) planned attitude `[b_xd b_yd b_zd]`.
    ///     theta: the tilt `theta*` from `b_zr` toward `f_r` (rad).
    ///     iterations: bisection iterations used (0 unless status is "planned").
    ///     status: "already-feasible" (`R_d = R_r`), "planned" (bisection), "zero-force"
    ///         (`f_r = 0`, `R_d = R_r`) or "unreachable" (`||f_r|| > n sigma_Tf`: `b_zd` along
    ///         `f_r`).
    "PlannerResult" in "tvmd" => PyPlannerResult(PlannerOutput<f64>) |py, o| {
        /// (3, 3) planned attitude `R_d`.
        r_d as "R_d" => matrix_array(py, &o.r_d),
        /// `theta*` (rad).
        theta => o.theta,
        /// Bisection iterations used.
        iterations => o.iterations,
        /// "already-feasible", "planned", "zero-force" or "unreachable".
        status => o.status.as_str(),
    }
}

/// Registers the planner classes.
pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyAttitudePlanner>()?;
    m.add_class::<PyPlannerResult>()?;
    Ok(())
}
