//! `tvmd.AttitudePlanner` (eqs. 9-11) and its `PlannerResult`.

use nalgebra::Matrix3;
use numpy::PyArray2;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use tvmd_core::{AttitudePlanner, PlannerStatus, Relaxation};

use crate::afs::PyAfs;
use crate::convert::{
    any, class_arg, finite_matrix3, finite_vector3, matrix_array, record_dict, record_repr,
};
use crate::errors::OrRaise;

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

/// The bisection attitude planner of eqs. (9)-(11): the smallest tilt `theta` of the reference
/// attitude `R_r` toward the force request `f_r` that makes `R_d^T f_r` attainable (in the AFS
/// with relaxation `s`). `b_zd = rot(b_zr, k, theta)`, `k = (b_zr x f_r)/||.||`,
/// `b_yd = (b_zd x b_xr)/||.||`, `b_xd = b_yd x b_zd`.
///
/// Returns the last *feasible* bisection point, stops on `tolerance` or `max_iterations`,
/// and rolls about `b_xr` when `f_r` is (anti)parallel to `b_zr`.
///
/// Args:
///     s: AFS relaxation in (0, 1].
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
    #[pyo3(signature = (s, tolerance = None, max_iterations = None))]
    fn new(s: f64, tolerance: Option<f64>, max_iterations: Option<i64>) -> PyResult<Self> {
        let planner = AttitudePlanner::new(Relaxation::new(s).or_raise()?);
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
    fn s(&self) -> f64 {
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
        let out = self.inner.plan(&afs.inner, &r_r, &f_r).or_raise()?;
        Ok(PyPlannerResult {
            r_d: out.r_d,
            theta: out.theta,
            iterations: out.iterations,
            status: out.status,
        })
    }

    fn __repr__(&self) -> String {
        format!(
            "AttitudePlanner(s={}, tolerance={:e}, max_iterations={})",
            self.s(),
            self.tolerance(),
            self.max_iterations
        )
    }
}

/// The planner's output (eqs. 9-11).
///
/// Attributes:
///     R_d: (3, 3) planned attitude `[b_xd b_yd b_zd]`.
///     theta: the tilt `theta*` from `b_zr` toward `f_r` (rad).
///     iterations: bisection iterations used (0 unless status is "planned").
///     status: "already-feasible" (`R_d = R_r`), "planned" (bisection), "zero-force"
///         (`f_r = 0`, `R_d = R_r`) or "unreachable" (`||f_r|| > n sigma_Tf`: `b_zd` along `f_r`).
#[pyclass(module = "tvmd", name = "PlannerResult", frozen)]
pub struct PyPlannerResult {
    r_d: Matrix3<f64>,
    theta: f64,
    iterations: u32,
    status: PlannerStatus,
}

impl PyPlannerResult {
    fn fields<'py>(&self, py: Python<'py>) -> PyResult<Vec<(&'static str, Bound<'py, PyAny>)>> {
        Ok(vec![
            ("R_d", self.r_d(py).into_any()),
            ("theta", any(py, self.theta)?),
            ("iterations", any(py, self.iterations)?),
            ("status", any(py, self.status())?),
        ])
    }
}

#[pymethods]
impl PyPlannerResult {
    /// (3, 3) planned attitude `R_d`.
    #[getter(R_d)]
    fn r_d<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        matrix_array(py, &self.r_d)
    }

    /// `theta*` (rad).
    #[getter]
    fn theta(&self) -> f64 {
        self.theta
    }

    /// Bisection iterations used.
    #[getter]
    fn iterations(&self) -> u32 {
        self.iterations
    }

    /// "already-feasible", "planned", "zero-force" or "unreachable".
    #[getter]
    fn status(&self) -> &'static str {
        self.status.as_str()
    }

    /// The fields as a dict.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        record_dict(py, self.fields(py)?)
    }

    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        record_repr("PlannerResult", &self.fields(py)?)
    }
}

/// Registers the planner classes.
pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyAttitudePlanner>()?;
    m.add_class::<PyPlannerResult>()?;
    Ok(())
}
