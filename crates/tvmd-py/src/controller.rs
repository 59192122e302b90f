//! `tvmd.Controller` (one `step` per control period) and its `StepOutput`.

use pyo3::prelude::*;

use tvmd_core::{AnyAllocator, ControlOutput, Controller, ControllerSettings, NullSpaceReport};
use tvmd_scenario::NullSpaceConfig;

use crate::afs::{PyAfs, PyForceProjection};
use crate::allocation::{make_allocator, rate_limits_arg, AllocationData, PyAllocation};
use crate::convert::{class_arg, commands_array, iteration_cap, matrix, null_space_arg};
use crate::convert::{relaxation_arg, Int, CAPACITY};
use crate::errors::{cycle_error, value_error, OrRaise};
use crate::law::{gains_arg, reference_arg, state_arg, PyGains, PyLawOutput};
use crate::planner::{planner, PyPlannerResult};
use crate::record::record;
use crate::team::{failure_mask, PyHoverCapability, PyTeam};

/// The controller borrowed for a call; a clear error if another thread holds it (only possible
/// from code that re-enters the controller while it runs, as the GIL serializes the calls).
fn borrow<'py>(slf: &Bound<'py, PyController>) -> PyResult<PyRef<'py, PyController>> {
    slf.try_borrow().map_err(|_| busy())
}

fn borrow_mut<'py>(slf: &Bound<'py, PyController>) -> PyResult<PyRefMut<'py, PyController>> {
    slf.try_borrow_mut().map_err(|_| busy())
}

fn busy() -> PyErr {
    pyo3::exceptions::PyRuntimeError::new_err(
        "tvmd.Controller is in use by another call (a controller may be shared between threads; \
         its calls run one at a time)",
    )
}

/// The full-pose controller: one `step` per control period. See the stub for arguments.
#[pyclass(module = "tvmd", name = "Controller")]
pub struct PyController {
    inner: Controller<f64, CAPACITY, AnyAllocator<f64, CAPACITY>>,
    max_iterations: u32,
    null_space: Option<NullSpaceConfig>,
}

#[pymethods]
impl PyController {
    #[new]
    #[pyo3(signature = (team, gains = None, relaxation = None, gravity = 9.81, period = 0.01, allocator = "exact-boundary-redistribution", rate_limits = None, failed = None, weights = None, regularization = None, planner_tolerance = None, planner_max_iterations = None, *, s = None, null_space = None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        team: &Bound<'_, PyAny>,
        gains: Option<&Bound<'_, PyAny>>,
        relaxation: Option<f64>,
        gravity: f64,
        period: f64,
        allocator: &str,
        rate_limits: Option<&Bound<'_, PyAny>>,
        failed: Option<&Bound<'_, PyAny>>,
        weights: Option<&Bound<'_, PyAny>>,
        regularization: Option<f64>,
        planner_tolerance: Option<f64>,
        planner_max_iterations: Option<Int>,
        s: Option<f64>,
        null_space: Option<&str>,
    ) -> PyResult<Self> {
        let team = class_arg::<PyTeam>(team, "team")?.get().inner;
        let relaxation = relaxation_arg(relaxation, s, Some(0.5))?;
        let null_space = null_space_arg(null_space)?;
        let stage = match &null_space {
            Some(c) => Some(c.stage::<f64>().map_err(value_error)?),
            None => None,
        };
        let settings = ControllerSettings {
            gains: gains_arg(gains)?,
            relaxation,
            gravity,
            period,
            rate_limits: rate_limits_arg(rate_limits)?,
            null_space: stage,
            gain_schedule: tvmd_core::GainSchedule::AsGiven,
            offset_free: None,
            attitude_rate: None,
        };
        let allocator = make_allocator(allocator, weights, regularization, team.len())?;
        let mask = failure_mask(&team, failed)?;
        let mut inner = Controller::new(team, settings, allocator).or_raise()?;
        inner.set_failures(mask).or_raise()?;
        let max_iterations =
            iteration_cap(planner_max_iterations.as_ref(), "planner_max_iterations")?;
        if planner_tolerance.is_some() || planner_max_iterations.is_some() {
            inner.set_planner(planner(relaxation, planner_tolerance, max_iterations)?);
        }
        Ok(Self {
            inner,
            max_iterations,
            null_space,
        })
    }

    /// Marks agents failed (None or [] for none); returns the `HoverCapability` of the
    /// working agents. See the stub.
    #[pyo3(signature = (failed = None))]
    fn set_failures(
        slf: &Bound<'_, Self>,
        failed: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<PyHoverCapability> {
        // Convert first (a conversion may run Python code and let another thread in), then
        // borrow: a shared controller is never found borrowed by a waiting thread.
        let team = *borrow(slf)?.inner.team();
        let mask = failure_mask(&team, failed)?;
        let inner = borrow_mut(slf)?.inner.set_failures(mask).or_raise()?;
        Ok(PyHoverCapability { inner })
    }

    /// The `HoverCapability` classified when the failures were last set.
    #[getter]
    fn hover_capability(&self) -> PyHoverCapability {
        PyHoverCapability {
            inner: *self.inner.hover_capability(),
        }
    }

    /// Forgets the previous command.
    fn reset(&mut self) {
        self.inner.reset();
    }

    /// One control period. See the stub for arguments.
    fn step(
        slf: &Bound<'_, Self>,
        py: Python<'_>,
        state: &Bound<'_, PyAny>,
        reference: &Bound<'_, PyAny>,
    ) -> PyResult<PyStepOutput> {
        // Arguments are converted before the controller is borrowed (see `set_failures`).
        let (state, reference) = (state_arg(state)?, reference_arg(reference)?);
        let mut this = borrow_mut(slf)?;
        let this = &mut *this;
        let n = this.inner.team().len();
        match this.inner.step(&state, &reference) {
            Ok(out) => {
                let allocation = AllocationData::new(out.allocation, n, this.inner.allocator());
                let inner = StepData {
                    out: Box::new(out),
                    n,
                    allocation,
                };
                Ok(PyStepOutput { inner })
            }
            Err(error) => {
                let commands = commands_array(py, &error.commands, n);
                Err(cycle_error(py, &error, commands))
            }
        }
    }

    /// The team.
    #[getter]
    fn team(&self) -> PyTeam {
        PyTeam {
            inner: *self.inner.team(),
        }
    }

    /// The gains.
    #[getter]
    fn gains(&self) -> PyGains {
        PyGains {
            inner: self.inner.settings().gains,
        }
    }

    /// The planner relaxation `s`.
    #[getter]
    fn relaxation(&self) -> f64 {
        self.inner.settings().relaxation.get()
    }

    /// `g` (m/s^2).
    #[getter]
    fn gravity(&self) -> f64 {
        self.inner.settings().gravity
    }

    /// The control period (s).
    #[getter]
    fn period(&self) -> f64 {
        self.inner.settings().period
    }

    /// The gimbal rate limits (rad/s), or None.
    #[getter]
    fn rate_limits(&self) -> Option<(f64, f64)> {
        let rates = self.inner.settings().rate_limits;
        rates.map(|r| (r.eta_x(), r.eta_y()))
    }

    /// The allocator's name.
    #[getter]
    fn allocator(&self) -> &'static str {
        self.inner.allocator().name()
    }

    /// The null-space stage ("margin", "inward-tilt=<rad>"), or None.
    #[getter]
    fn null_space(&self) -> Option<String> {
        self.null_space.map(|n| n.to_string())
    }

    /// The planner's bisection iteration cap.
    #[getter]
    fn planner_max_iterations(&self) -> u32 {
        self.max_iterations
    }

    /// Indices of the failed agents.
    #[getter]
    fn failed(&self) -> Vec<usize> {
        let mask = self.inner.failures();
        (0..self.inner.team().len())
            .filter(|i| mask.is_failed(*i))
            .collect()
    }

    /// The AFS of the working agents.
    #[getter]
    fn afs(&self) -> PyAfs {
        PyAfs::of(*self.inner.afs(), self.inner.team().limits())
    }

    /// (n, 4) previous period's commands.
    #[getter]
    fn previous_commands<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        commands_array(py, self.inner.previous_commands(), self.inner.team().len())
    }

    fn __repr__(&self) -> String {
        format!(
            "Controller(n={}, relaxation={}, allocator='{}', failed={:?})",
            self.inner.team().len(),
            self.relaxation(),
            self.allocator(),
            self.failed()
        )
    }
}

/// One `Controller.step`: the core's output, the agent count and the allocation record.
pub(crate) struct StepData {
    out: Box<ControlOutput<f64, CAPACITY>>,
    n: usize,
    allocation: AllocationData,
}

record! {
    /// Everything one `Controller.step` computed, nested like the core's `ControlOutput`.
    "StepOutput" in "tvmd" => PyStepOutput(StepData) |py, o| {
        /// The planner's result (eqs. 9-11).
        planner => PyPlannerResult { inner: o.out.planner },
        /// The force projection `K_f` (eqs. 12-13).
        projection => PyForceProjection { inner: o.out.projection },
        /// (3,) `t_Tf R u_fr` (inertial).
        f_r => matrix(py, &o.out.f_r)?,
        /// The control law's output (eq. 12).
        law => PyLawOutput { inner: o.out.law },
        /// The allocation (eqs. 4 and 6).
        allocation => PyAllocation { inner: o.allocation.clone() },
        /// (n, 4) commands, columns `eta_x, eta_y, thrust, omega`.
        commands => commands_array(py, &o.out.commands, o.n)?,
        /// Largest clamp of the command inversion (normalized).
        command_clamp => o.out.command_clamp,
        /// What the null-space stage changed.
        null_space => PyNullSpaceReport { inner: o.out.null_space },
    }
}

record! {
    /// What the null-space stage changed in one period. See the stub.
    "NullSpaceReport" in "tvmd" => PyNullSpaceReport(NullSpaceReport<f64>) |py, o| {
        /// The stage ran on this period's allocation.
        ran => o.ran,
        /// Accepted steps (0: the allocator's forces unchanged).
        iterations => o.iterations,
        /// The objective at the allocator's forces.
        objective_before => o.objective_before,
        /// The objective at the returned forces.
        objective_after => o.objective_after,
        /// Smallest normalized margin to the admissible boundary at the allocator's forces.
        margin_before => o.margin_before,
        /// The same at the returned forces.
        margin_after => o.margin_after,
        /// Largest change of one agent's force (N).
        largest_force_change => o.largest_force_change,
        /// `||M f' - M f||`, the wrench the stage moved (round-off).
        wrench_drift => o.wrench_drift,
    }
}

/// Registers the controller classes.
pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyController>()?;
    m.add_class::<PyStepOutput>()?;
    m.add_class::<PyNullSpaceReport>()?;
    Ok(())
}
