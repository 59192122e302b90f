//! `tvmd.AttitudePlanner` (eqs. 9-11) and its `PlannerResult`.

use pyo3::prelude::*;

use tvmd_core::{AttitudePlanner, PlannerOutput, Relaxation};

use crate::afs::PyAfs;
use crate::convert::{class_arg, finite, iteration_cap, matrix, relaxation_arg, Int};
use crate::errors::OrRaise;
use crate::record::record;

/// A planner with the core's default tolerance unless `tolerance` is given.
pub(crate) fn planner(
    relaxation: Relaxation<f64>,
    tolerance: Option<f64>,
    max_iterations: u32,
) -> PyResult<AttitudePlanner<f64>> {
    let planner = AttitudePlanner::new(relaxation);
    let tolerance = tolerance.unwrap_or(planner.tolerance());
    planner.with_tolerance(tolerance, max_iterations).or_raise()
}

#[doc = include_str!("../docstrings/tvmd.AttitudePlanner.txt")]
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
        max_iterations: Option<Int>,
        s: Option<f64>,
    ) -> PyResult<Self> {
        let relaxation = relaxation_arg(relaxation, s, None)?;
        let max_iterations = iteration_cap(max_iterations.as_ref(), "max_iterations")?;
        let inner = planner(relaxation, tolerance, max_iterations)?;
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

    #[doc = include_str!("../docstrings/tvmd.AttitudePlanner.plan.txt")]
    #[allow(non_snake_case)]
    fn plan(
        &self,
        afs: &Bound<'_, PyAny>,
        R_r: &Bound<'_, PyAny>,
        f_r: &Bound<'_, PyAny>,
    ) -> PyResult<PyPlannerResult> {
        let (r_r, f_r) = (finite(R_r, "R_r")?, finite(f_r, "f_r")?);
        let afs = &class_arg::<PyAfs>(afs, "afs")?.get().inner.afs;
        let inner = self.inner.plan(afs, &r_r, &f_r).or_raise()?;
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
    "PlannerResult" in "tvmd" => PyPlannerResult(PlannerOutput<f64>) |py, o| {
        /// (3, 3) planned attitude.
        r_d as "R_d" => matrix(py, &o.r_d)?,
        /// `theta*` (rad).
        theta => o.theta,
        /// Bisection iterations used.
        iterations => o.iterations,
        /// How the output was reached: "already-feasible", "planned", "zero-force" or
        /// "unreachable".
        status => o.status.as_str(),
    }
}

/// Registers the planner classes.
pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyAttitudePlanner>()?;
    m.add_class::<PyPlannerResult>()?;
    Ok(())
}
