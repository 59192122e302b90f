//! `tvmd.Controller` (one `step` per control period) and its `StepOutput`.

use numpy::PyArray2;
use pyo3::prelude::*;

use tvmd_core::team::presets;
use tvmd_core::{AnyAllocator, AttitudePlanner, ControlOutput, Controller, ControllerSettings};

use crate::afs::{PyAfs, PyForceProjection};
use crate::allocation::{
    make_allocator, rate_limits_arg, report, AllocationData, AllocatorOptions, PyAllocation,
};
use crate::convert::{array1, class_arg, commands_array};
use crate::errors::{cycle_error, OrRaise};
use crate::law::{gains_arg, reference_arg, state_arg, PyGains, PyLawOutput};
use crate::planner::{iteration_cap, relaxation_arg, PyPlannerResult};
use crate::record::record;
use crate::team::{failed_list, failure_mask, PyTeam};
use crate::CAPACITY;

/// The full-pose controller of a team (`tvmd_core::Controller`): per control period, the force
/// request `u_fr`, the projection `t_Tf`, the attitude planner (`R_d`, eqs. 9-11), `K_f` and the
/// torque part of the law (eq. 12), the allocation and the inversion into gimbal angles and
/// rotor speeds inside `E_f` (eq. 6).
///
/// Args:
///     team: the `Team`.
///     gains: `Gains`; None for the paper's (`Gains.paper()`).
///     relaxation: AFS relaxation `s` of the planner, in (0, 1]; default 0.5 (`s=` is an
///         alias).
///     gravity: `g` (m/s^2).
///     period: control period `dt` (s) (used by the rate limits).
///     allocator: allocator name (see `tvmd.ALLOCATORS` and `tvmd.allocate`).
///     rate_limits: optional `(eta_x_rate, eta_y_rate)` gimbal rate limits (rad/s).
///     failed: None or failed agent indices.
///     weights: allocator weights (see `tvmd.allocate`).
///     regularization: `lambda` of the "clarabel" allocator.
///     planner_tolerance: bisection tolerance (rad); default `max(1e-10, 8 eps)`.
///     planner_max_iterations: bisection iteration cap; default 64.
///
/// Raises:
///     ConfigError: invalid gains, `s`, gravity, period, rates, or a degraded team that cannot
///         produce every wrench.
///     ValueError: unknown allocator, "clarabel" without the cargo feature, wrong shapes.
#[pyclass(module = "tvmd", name = "Controller")]
pub struct PyController {
    inner: Controller<f64, CAPACITY, AnyAllocator<f64, CAPACITY>>,
    allocator: &'static str,
    max_iterations: u32,
}

#[pymethods]
impl PyController {
    #[new]
    #[pyo3(signature = (team, gains = None, relaxation = None, gravity = presets::GRAVITY, period = 0.01, allocator = "redistributed-pseudo-inverse", rate_limits = None, failed = None, weights = None, regularization = None, planner_tolerance = None, planner_max_iterations = None, *, s = None))]
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
        planner_max_iterations: Option<i64>,
        s: Option<f64>,
    ) -> PyResult<Self> {
        let team = class_arg::<PyTeam>(team, "team")?.get().inner;
        let relaxation = relaxation_arg(relaxation, s, Some(0.5))?;
        let settings = ControllerSettings {
            gains: gains_arg(gains)?,
            relaxation,
            gravity,
            period,
            rate_limits: rate_limits_arg(rate_limits)?,
        };
        let options = AllocatorOptions {
            weights,
            regularization,
        };
        let (any_allocator, name) = make_allocator(allocator, &options, team.len())?;
        let mask = failure_mask(&team, failed)?;
        let mut inner = Controller::new(team, settings, any_allocator).or_raise()?;
        inner.set_failures(mask).or_raise()?;
        let max_iterations = iteration_cap(planner_max_iterations)?;
        if planner_tolerance.is_some() || planner_max_iterations.is_some() {
            let planner = AttitudePlanner::new(relaxation);
            let planner = planner
                .with_tolerance(
                    planner_tolerance.unwrap_or(planner.tolerance()),
                    max_iterations,
                )
                .or_raise()?;
            inner.set_planner(planner);
        }
        Ok(Self {
            inner,
            allocator: name,
            max_iterations,
        })
    }

    /// Marks agents failed (None or [] for none). A failed agent leaves `n`, `n_x`/`n_y` and `M`
    /// and is commanded idle.
    ///
    /// Raises:
    ///     ConfigError: an index the team does not have, or a remaining team that cannot
    ///         produce every wrench (the previous mask is kept).
    #[pyo3(signature = (failed = None))]
    fn set_failures(&mut self, failed: Option<&Bound<'_, PyAny>>) -> PyResult<()> {
        let mask = failure_mask(self.inner.team(), failed)?;
        self.inner.set_failures(mask).or_raise()
    }

    /// Forgets the previous command (rate limits restart from centred gimbals; a rejected
    /// cycle then holds idle commands).
    fn reset(&mut self) {
        self.inner.reset();
    }

    /// One control period.
    ///
    /// Args:
    ///     state: `State` or dict with keys position (3,), attitude (3, 3),
    ///         angular_velocity (3,), velocity (3,) (only `position` required).
    ///     reference: `Reference` or dict with keys position, velocity, acceleration,
    ///         attitude, angular_velocity, angular_acceleration (only `position` required).
    ///
    /// Returns:
    ///     StepOutput.
    ///
    /// Raises:
    ///     CycleError (a ValueError): NaN/inf input or a non-rotation attitude; the exception's
    ///         `commands` (n, 4) are the previous period's commands to hold.
    ///     ValueError / TypeError: wrong shapes or argument types.
    fn step(
        &mut self,
        py: Python<'_>,
        state: &Bound<'_, PyAny>,
        reference: &Bound<'_, PyAny>,
    ) -> PyResult<PyStepOutput> {
        let state = state_arg(state)?;
        let reference = reference_arg(reference)?;
        let n = self.inner.team().len();
        match self.inner.step(&state, &reference) {
            Ok(out) => Ok(PyStepOutput {
                inner: StepData {
                    out: Box::new(out),
                    n,
                    method: self.allocator,
                    report: report(self.inner.allocator()),
                },
            }),
            Err(error) => Err(cycle_error(py, &error, n)),
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

    /// The gimbal rate limits `(eta_x_rate, eta_y_rate)` (rad/s), or None.
    #[getter]
    fn rate_limits(&self) -> Option<(f64, f64)> {
        self.inner
            .settings()
            .rate_limits
            .map(|r| (r.eta_x, r.eta_y))
    }

    /// The allocator's name.
    #[getter]
    fn allocator(&self) -> &'static str {
        self.allocator
    }

    /// The planner's bisection iteration cap.
    #[getter]
    fn planner_max_iterations(&self) -> u32 {
        self.max_iterations
    }

    /// Indices of the failed agents.
    #[getter]
    fn failed(&self) -> Vec<usize> {
        failed_list(self.inner.failures(), self.inner.team().len())
    }

    /// The AFS of the working agents.
    #[getter]
    fn afs(&self) -> PyAfs {
        let limits = self.inner.team().limits();
        PyAfs::from_parts(
            *self.inner.afs(),
            limits.sigma_x(),
            limits.sigma_y(),
            limits.max_thrust(),
        )
    }

    /// (n, 4) previous period's commands, columns `eta_x, eta_y, thrust, omega`.
    #[getter]
    fn previous_commands<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        commands_array(py, self.inner.previous_commands(), self.inner.team().len())
    }

    fn __repr__(&self) -> String {
        format!(
            "Controller(n={}, relaxation={}, allocator='{}', failed={:?})",
            self.inner.team().len(),
            self.relaxation(),
            self.allocator,
            self.failed()
        )
    }
}

/// One `Controller.step` as the bindings keep it: the core's output and what `StepOutput`
/// adds (the agent count, the allocator's name and Clarabel's report).
pub(crate) struct StepData {
    out: Box<ControlOutput<f64, CAPACITY>>,
    n: usize,
    method: &'static str,
    report: Option<String>,
}

record! {
    /// Everything one `Controller.step` computed, nested like the core's `ControlOutput`
    /// (read-only; each access returns fresh arrays).
    ///
    /// Attributes:
    ///     planner: PlannerResult (`R_d`, `theta`, `iterations`, `status`).
    ///     projection: ForceProjection (`force = K_f u_fr`, `t_Tf`, `t_eta`).
    ///     f_r: (3,) `t_Tf R u_fr`, the inertial force the planner aligns with.
    ///     law: LawOutput (`e_x`, `e_R`, `e_xi`, `u_r`, `u_d`, `V_R`, `V_x`).
    ///     allocation: Allocation (`forces`, `wrench` = `M f`, `e_f`, `wrench_error`, `rounds`,
    ///         `saturated`, `fallback`, `method`, `report`).
    ///     commands: (n, 4) columns `eta_x, eta_y, thrust, omega` (idle for failed agents).
    ///     command_clamp: the largest clamp the command inversion applied (normalized).
    "StepOutput" in "tvmd" => PyStepOutput(StepData) |py, o| {
        /// The planner's result (eqs. 9-11).
        planner => PyPlannerResult { inner: o.out.planner },
        /// The force projection `K_f` (eqs. 12-13).
        projection => PyForceProjection { inner: o.out.projection },
        /// (3,) `f_r = t_Tf R u_fr` (inertial).
        f_r => array1(py, o.out.f_r.as_slice()),
        /// The control law's output (eq. 12).
        law => PyLawOutput { inner: o.out.law },
        /// The allocation (eqs. 4 and 6).
        allocation => PyAllocation {
            inner: AllocationData {
                allocation: o.out.allocation,
                n: o.n,
                method: o.method,
                report: o.report.clone(),
            },
        },
        /// (n, 4) commands, columns `eta_x, eta_y, thrust, omega`.
        commands => commands_array(py, &o.out.commands, o.n),
        /// Largest clamp of the command inversion (normalized).
        command_clamp => o.out.command_clamp,
    }
}

/// Registers the controller classes.
pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyController>()?;
    m.add_class::<PyStepOutput>()?;
    Ok(())
}
