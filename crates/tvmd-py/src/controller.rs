//! `tvmd.Controller` (one `step` per control period) and its `StepOutput`.

use numpy::{PyArray1, PyArray2};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};

use tvmd_core::team::presets;
use tvmd_core::{
    AnyAllocator, AttitudePlanner, ControlOutput, Controller, ControllerSettings, Relaxation,
};

use crate::afs::PyAfs;
use crate::allocation::{
    make_allocator, rate_limits_arg, report, AllocatorOptions, DEFAULT_ALLOCATOR,
};
use crate::convert::{
    any, array1, bool_array, class_arg, commands_array, matrix_array, record_dict, record_repr,
    rows_array,
};
use crate::errors::{cycle_error, OrRaise};
use crate::law::{gains_arg, reference_arg, state_arg, PyGains};
use crate::planner::iteration_cap;
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
///     s: AFS relaxation of the planner, in (0, 1].
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
    #[pyo3(signature = (team, gains = None, s = 0.5, gravity = presets::GRAVITY, period = 0.01, allocator = DEFAULT_ALLOCATOR, rate_limits = None, failed = None, weights = None, regularization = None, planner_tolerance = None, planner_max_iterations = None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        team: &Bound<'_, PyAny>,
        gains: Option<&Bound<'_, PyAny>>,
        s: f64,
        gravity: f64,
        period: f64,
        allocator: &str,
        rate_limits: Option<&Bound<'_, PyAny>>,
        failed: Option<&Bound<'_, PyAny>>,
        weights: Option<&Bound<'_, PyAny>>,
        regularization: Option<f64>,
        planner_tolerance: Option<f64>,
        planner_max_iterations: Option<i64>,
    ) -> PyResult<Self> {
        let team = class_arg::<PyTeam>(team, "team")?.get().inner;
        let relaxation = Relaxation::new(s).or_raise()?;
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
                out: Box::new(out),
                n,
                report: report(self.inner.allocator()),
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
    fn s(&self) -> f64 {
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
            "Controller(n={}, s={}, allocator='{}', failed={:?})",
            self.inner.team().len(),
            self.s(),
            self.allocator,
            self.failed()
        )
    }
}

/// Everything one `Controller.step` computed (read-only; arrays are fresh copies).
///
/// Attributes:
///     R_d: (3, 3) planned attitude. theta: planned tilt (rad).
///     planner_status: "already-feasible", "planned", "zero-force" or "unreachable".
///     planner_iterations: bisection iterations.
///     t_Tf, t_eta: the force-projection factors, `K_f = diag(t_eta t_Tf, t_eta t_Tf, t_Tf)`.
///     f_r: (3,) `t_Tf R u_fr`, the inertial force the planner aligns with.
///     u_r: (6,) `[u_tau_r; u_fr]`. u_d: (6,) `blockdiag(I, K_f) u_r`.
///     wrench: (6,) `M f`, the allocated wrench.
///     e_f: `||u_fd - u_f||`. wrench_error: `||u_d - M f||`.
///     e_x: (3,). e_R: (3,). e_xi: (6,) `[e_Omega; e_v]`. V_R, V_x: Lyapunov values.
///     forces: (n, 3) agent-frame forces. commands: (n, 4) columns `eta_x, eta_y, thrust, omega`
///         (idle for failed agents). saturated: (n,) bool. rounds: allocator rounds.
///     fallback: the allocator fell back to the redistributed pseudo-inverse.
///     command_clamp: the largest clamp the command inversion applied (normalized).
///     allocator_report: Clarabel's solve report (text), None for the other allocators.
#[pyclass(module = "tvmd", name = "StepOutput", frozen)]
pub struct PyStepOutput {
    out: Box<ControlOutput<f64, CAPACITY>>,
    n: usize,
    report: Option<String>,
}

/// The field names of `StepOutput`, in `to_dict` / `repr` order.
const STEP_FIELDS: &[&str] = &[
    "R_d",
    "theta",
    "planner_status",
    "planner_iterations",
    "t_Tf",
    "t_eta",
    "f_r",
    "u_r",
    "u_d",
    "wrench",
    "e_f",
    "wrench_error",
    "e_x",
    "e_R",
    "e_xi",
    "V_R",
    "V_x",
    "forces",
    "commands",
    "saturated",
    "rounds",
    "fallback",
    "command_clamp",
    "allocator_report",
];

impl PyStepOutput {
    fn field<'py>(&self, py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyAny>> {
        let o = &self.out;
        Ok(match name {
            "R_d" => self.r_d(py).into_any(),
            "theta" => any(py, o.planner.theta)?,
            "planner_status" => any(py, o.planner.status.as_str())?,
            "planner_iterations" => any(py, o.planner.iterations)?,
            "t_Tf" => any(py, o.projection.t_tf)?,
            "t_eta" => any(py, o.projection.t_eta)?,
            "f_r" => self.f_r(py).into_any(),
            "u_r" => self.u_r(py).into_any(),
            "u_d" => self.u_d(py).into_any(),
            "wrench" => self.wrench(py).into_any(),
            "e_f" => any(py, o.allocation.e_f)?,
            "wrench_error" => any(py, o.allocation.wrench_error)?,
            "e_x" => self.e_x(py).into_any(),
            "e_R" => self.e_r(py).into_any(),
            "e_xi" => self.e_xi(py).into_any(),
            "V_R" => any(py, o.law.v_r)?,
            "V_x" => any(py, o.law.v_x)?,
            "forces" => self.forces(py).into_any(),
            "commands" => self.commands(py).into_any(),
            "saturated" => self.saturated(py).into_any(),
            "rounds" => any(py, o.allocation.rounds)?,
            "fallback" => any(py, o.allocation.fallback)?,
            "command_clamp" => any(py, o.command_clamp)?,
            "allocator_report" => any(py, self.report.clone())?,
            other => {
                return Err(pyo3::exceptions::PyAttributeError::new_err(format!(
                    "StepOutput has no field '{other}'"
                )))
            }
        })
    }

    fn fields<'py>(&self, py: Python<'py>) -> PyResult<Vec<(&'static str, Bound<'py, PyAny>)>> {
        STEP_FIELDS
            .iter()
            .map(|name| Ok((*name, self.field(py, name)?)))
            .collect()
    }
}

#[pymethods]
impl PyStepOutput {
    /// (3, 3) planned attitude `R_d`.
    #[getter(R_d)]
    fn r_d<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        matrix_array(py, &self.out.planner.r_d)
    }

    /// Planned tilt `theta*` (rad).
    #[getter]
    fn theta(&self) -> f64 {
        self.out.planner.theta
    }

    /// "already-feasible", "planned", "zero-force" or "unreachable".
    #[getter]
    fn planner_status(&self) -> &'static str {
        self.out.planner.status.as_str()
    }

    /// Bisection iterations.
    #[getter]
    fn planner_iterations(&self) -> u32 {
        self.out.planner.iterations
    }

    /// `t_Tf`.
    #[getter(t_Tf)]
    fn t_tf(&self) -> f64 {
        self.out.projection.t_tf
    }

    /// `t_eta`.
    #[getter]
    fn t_eta(&self) -> f64 {
        self.out.projection.t_eta
    }

    /// (3,) `f_r = t_Tf R u_fr` (inertial).
    #[getter]
    fn f_r<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        array1(py, self.out.f_r.as_slice())
    }

    /// (6,) `u_r = [u_tau_r; u_fr]`.
    #[getter]
    fn u_r<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        array1(py, self.out.law.u_r.as_slice())
    }

    /// (6,) `u_d = blockdiag(I, K_f) u_r`.
    #[getter]
    fn u_d<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        array1(py, self.out.law.u_d.as_slice())
    }

    /// (6,) `M f`, the allocated wrench.
    #[getter]
    fn wrench<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        array1(py, self.out.allocation.wrench.as_slice())
    }

    /// `e_f = ||u_fd - u_f||`.
    #[getter]
    fn e_f(&self) -> f64 {
        self.out.allocation.e_f
    }

    /// `||u_d - M f||`.
    #[getter]
    fn wrench_error(&self) -> f64 {
        self.out.allocation.wrench_error
    }

    /// (3,) `e_x = x - x_r`.
    #[getter]
    fn e_x<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        array1(py, self.out.law.e_x.as_slice())
    }

    /// (3,) `e_R`.
    #[getter(e_R)]
    fn e_r<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        array1(py, self.out.law.e_r.as_slice())
    }

    /// (6,) `e_xi = [e_Omega; e_v]`.
    #[getter]
    fn e_xi<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        array1(py, self.out.law.e_xi.as_slice())
    }

    /// `V_R`.
    #[getter(V_R)]
    fn v_r(&self) -> f64 {
        self.out.law.v_r
    }

    /// `V_x`.
    #[getter(V_x)]
    fn v_x(&self) -> f64 {
        self.out.law.v_x
    }

    /// (n, 3) agent-frame forces.
    #[getter]
    fn forces<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let rows: Vec<[f64; 3]> = self
            .out
            .allocation
            .forces
            .iter()
            .take(self.n)
            .map(|f| [f.x, f.y, f.z])
            .collect();
        rows_array(py, &rows)
    }

    /// (n, 4) commands, columns `eta_x, eta_y, thrust, omega`.
    #[getter]
    fn commands<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        commands_array(py, &self.out.commands, self.n)
    }

    /// (n,) saturated agents.
    #[getter]
    fn saturated<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<bool>> {
        let saturated: Vec<bool> = self
            .out
            .allocation
            .saturated
            .iter()
            .take(self.n)
            .copied()
            .collect();
        bool_array(py, &saturated)
    }

    /// Allocator rounds.
    #[getter]
    fn rounds(&self) -> u32 {
        self.out.allocation.rounds
    }

    /// Whether the allocator fell back to the redistributed pseudo-inverse.
    #[getter]
    fn fallback(&self) -> bool {
        self.out.allocation.fallback
    }

    /// Largest clamp of the command inversion (normalized).
    #[getter]
    fn command_clamp(&self) -> f64 {
        self.out.command_clamp
    }

    /// Clarabel's solve report, None otherwise.
    #[getter]
    fn allocator_report(&self) -> Option<String> {
        self.report.clone()
    }

    /// The field names, in `to_dict` order.
    #[classattr]
    #[pyo3(name = "FIELDS")]
    fn field_names<'py>(py: Python<'py>) -> PyResult<Bound<'py, PyTuple>> {
        PyTuple::new(py, STEP_FIELDS)
    }

    /// The fields as a dict.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        record_dict(py, self.fields(py)?)
    }

    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        record_repr("StepOutput", &self.fields(py)?)
    }
}

/// Registers the controller classes.
pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyController>()?;
    m.add_class::<PyStepOutput>()?;
    Ok(())
}
