//! `tvmd.Controller`: one `step` per control period (its output in [`crate::step_output`]),
//! with the law the `law` argument names (default the offset-free law).

use pyo3::intern;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyType};

use tvmd_core::{AnyAllocator, Controller, ControllerSettings};
use tvmd_scenario::{LawConfig, NullSpaceConfig};
use tvmd_sim::control::law_settings;

use crate::afs::PyAfs;
use crate::allocation::{make_allocator, rate_limits_arg, AllocationData};
use crate::controller_args::{argument_error, deep_copy, period_arg};
use crate::convert::{class_arg, commands_array, finite, iteration_cap, law_arg, matrix};
use crate::convert::{fault_detection_arg, record_to_py, reports_arg, round_cap_arg, set_reports};
use crate::convert::{relaxation_arg, Int, CAPACITY};
use crate::errors::{cycle_error, OrRaise};
use crate::law::{gains_arg, reference_arg, state_arg, PyGains};
use crate::planner::{planner, PyPlannerResult};
use crate::step_output::{AllocationStageData, PyAllocationStage, PyLawStage};
use crate::step_output::{PyStepOutput, StepData};
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

#[doc = include_str!("../docstrings/tvmd.Controller.txt")]
#[pyclass(module = "tvmd", name = "Controller")]
pub struct PyController {
    inner: Controller<f64, CAPACITY, AnyAllocator<f64, CAPACITY>>,
    max_iterations: u32,
    null_space: Option<NullSpaceConfig>,
    /// The law as asked for (`law`), whose settings the core holds.
    law: LawConfig,
    /// The constructor's arguments by name (deep-copied), which `pickle` rebuilds from.
    arguments: Py<PyDict>,
}

#[pymethods]
impl PyController {
    // `law = None` is the offset-free law (a default here must be of the argument's type); the
    // text signature (kept equal to `signature`, checked by stubtest) shows it by its name.
    #[new]
    #[pyo3(signature = (team, gains = None, relaxation = None, gravity = 9.81, period = 0.01, allocator = "exact-boundary-redistribution", rate_limits = None, failed = None, weights = None, regularization = None, planner_tolerance = None, planner_max_iterations = None, *, s = None, null_space = None, law = None, fault_detection = None, max_rounds = None))]
    #[pyo3(
        text_signature = "(team, gains=None, relaxation=None, gravity=9.81, period=0.01, allocator=\"exact-boundary-redistribution\", rate_limits=None, failed=None, weights=None, regularization=None, planner_tolerance=None, planner_max_iterations=None, *, s=None, null_space=None, law=\"offset-free\", fault_detection=None, max_rounds=None)"
    )]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
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
        law: Option<&Bound<'_, PyAny>>,
        fault_detection: Option<&Bound<'_, PyAny>>,
        max_rounds: Option<Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let arguments = PyDict::new(py);
        arguments.set_item("team", team)?;
        let named: [(&str, Option<&Bound<'_, PyAny>>); 6] = [
            ("gains", gains),
            ("rate_limits", rate_limits),
            ("failed", failed),
            ("weights", weights),
            ("law", law),
            ("fault_detection", fault_detection),
        ];
        for (name, value) in named {
            arguments.set_item(name, value)?;
        }
        arguments.set_item("relaxation", relaxation)?;
        arguments.set_item("gravity", gravity)?;
        arguments.set_item("period", period)?;
        arguments.set_item("allocator", allocator)?;
        arguments.set_item("regularization", regularization)?;
        arguments.set_item("planner_tolerance", planner_tolerance)?;
        // Integers as Python ints (a constructed controller's fit i64).
        let int = |i: &Option<Int>| i.as_ref().and_then(Int::get::<i64>);
        arguments.set_item("planner_max_iterations", int(&planner_max_iterations))?;
        arguments.set_item("s", s)?;
        arguments.set_item("null_space", null_space)?;
        arguments.set_item("max_rounds", &max_rounds)?;
        let team = class_arg::<PyTeam>(team, "team")?.get().inner;
        period_arg(period)?;
        let relaxation = relaxation_arg(relaxation, s, Some(0.5))?;
        let null_space = null_space
            .map(tvmd_sim::RunRequest::parse_null_space)
            .transpose()
            .map_err(|e| argument_error("null_space", e))?;
        let stage = match &null_space {
            Some(c) => Some(
                c.stage::<f64>()
                    .map_err(|e| argument_error("null_space", e))?,
            ),
            None => None,
        };
        let law = law.map_or(Ok(LawConfig::default()), |l| law_arg(l, "law"))?;
        let (gain_schedule, offset_free, attitude_rate) =
            law_settings::<f64>(&law).map_err(|e| argument_error("law", e))?;
        let fault_detection = match fault_detection {
            Some(f) => Some(
                tvmd_sim::control::fault_detection::<f64>(&fault_detection_arg(
                    f,
                    "fault_detection",
                )?)
                .map_err(|e| argument_error("fault_detection", e))?,
            ),
            None => None,
        };
        let settings = ControllerSettings {
            gains: gains_arg(gains)?,
            relaxation,
            gravity,
            period,
            rate_limits: rate_limits_arg(rate_limits)?,
            null_space: stage,
            gain_schedule,
            offset_free,
            attitude_rate,
            fault_detection,
        };
        let allocator = make_allocator(
            allocator,
            weights,
            regularization,
            round_cap_arg(max_rounds.as_ref())?,
            team.len(),
        )?;
        let mask = failure_mask(&team, failed)?;
        let mut inner = Controller::new(team, settings, allocator).or_raise()?;
        inner.set_failures(mask).or_raise()?;
        let max_iterations =
            iteration_cap(planner_max_iterations.as_ref(), "planner_max_iterations")?;
        if planner_tolerance.is_some() || planner_max_iterations.is_some() {
            inner.set_planner(planner(relaxation, planner_tolerance, max_iterations)?);
        }
        let arguments = deep_copy(arguments)?;
        Ok(Self {
            inner,
            max_iterations,
            null_space,
            law,
            arguments,
        })
    }

    /// `pickle` support: the controller as constructed (`Controller._restore` calls the
    /// constructor with the same arguments), with its current failures and landed flag. The
    /// flight state (previous commands, offset-free state, planned-rate filter, fault
    /// detector) starts afresh, as after `reset()`; `copy.deepcopy` keeps it.
    #[allow(clippy::type_complexity)]
    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> PyResult<(Bound<'py, PyAny>, (Py<PyDict>, Vec<usize>, bool))> {
        let restore = slf.get_type().getattr(intern!(slf.py(), "_restore"))?;
        let this = borrow(slf)?;
        let arguments = this.arguments.clone_ref(slf.py());
        Ok((restore, (arguments, this.failed(), this.inner.landed())))
    }

    /// The controller of `__reduce__`'s data.
    #[classmethod]
    fn _restore<'py>(
        cls: &Bound<'py, PyType>,
        arguments: &Bound<'py, PyDict>,
        failed: Vec<usize>,
        landed: bool,
    ) -> PyResult<Bound<'py, PyAny>> {
        let controller = cls.call((), Some(arguments))?;
        controller.call_method1(intern!(cls.py(), "set_failures"), (failed,))?;
        controller.call_method1(intern!(cls.py(), "set_landed"), (landed,))?;
        Ok(controller)
    }

    /// An independent controller in the same state (`copy.copy`): what follows, on either,
    /// is what would have followed on the original.
    fn __copy__(slf: &Bound<'_, Self>) -> PyResult<Self> {
        let this = borrow(slf)?;
        Ok(Self {
            inner: this.inner.clone(),
            max_iterations: this.max_iterations,
            null_space: this.null_space,
            law: this.law,
            arguments: this.arguments.clone_ref(slf.py()),
        })
    }

    /// As `__copy__` (`copy.deepcopy`): the controller owns no Python object.
    fn __deepcopy__(slf: &Bound<'_, Self>, _memo: &Bound<'_, PyAny>) -> PyResult<Self> {
        Self::__copy__(slf)
    }

    #[doc = include_str!("../docstrings/tvmd.Controller.fault_report.txt")]
    fn fault_report<'py>(slf: &Bound<'py, Self>) -> PyResult<Option<Bound<'py, PyAny>>> {
        let this = borrow(slf)?;
        let Some(report) = this.inner.fault_report() else {
            return Ok(None);
        };
        let mut diagnostics = tvmd_sim::control::fault_diagnostics(report);
        diagnostics.masked = this.inner.fault_masking().map(|m| m.agent);
        record_to_py(slf.py(), &diagnostics).map(Some)
    }

    #[doc = include_str!("../docstrings/tvmd.Controller.set_reports.txt")]
    fn set_reports(slf: &Bound<'_, Self>, reports: &Bound<'_, PyAny>) -> PyResult<()> {
        let readings = reports_arg(reports, borrow(slf)?.inner.team().len())?;
        set_reports(&mut borrow_mut(slf)?.inner, &readings)
    }

    #[doc = include_str!("../docstrings/tvmd.Controller.set_failures.txt")]
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
            inner: self.inner.hover_capability(),
        }
    }

    /// Forgets the previous command, the offset-free state and the planned-rate filter (not
    /// the landed flag).
    fn reset(&mut self) {
        self.inner.reset();
    }

    #[doc = include_str!("../docstrings/tvmd.Controller.set_landed.txt")]
    fn set_landed(&mut self, landed: &Bound<'_, PyAny>) -> PyResult<()> {
        // A flag as flight code passes it: a bool, or the integers 0 and 1 (as C's `landed`).
        let flag = match landed.extract::<bool>() {
            Ok(b) => b,
            Err(_) => match landed.extract::<i64>() {
                Ok(i @ (0 | 1)) => i == 1,
                _ => {
                    return Err(pyo3::exceptions::PyTypeError::new_err(format!(
                        "`landed` must be a bool (or 0 or 1), got {}",
                        landed.repr()?
                    )))
                }
            },
        };
        self.inner.set_landed(flag);
        Ok(())
    }

    /// Whether the landed hold is on (`set_landed`).
    #[getter]
    fn landed(&self) -> bool {
        self.inner.landed()
    }

    /// `(force, torque)`: the wrench the offset-free state adds to the next period's request,
    /// force (3,) (N) in the inertial frame, torque (3,) (N m) in the body frame.
    #[getter]
    fn offset_free_compensation<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        let c = self.inner.offset_free_compensation();
        Ok((matrix(py, &c.force)?, matrix(py, &c.torque)?))
    }

    /// `(Omega_d, Omega_d_dot)` of the planned attitude in the last period (rad/s, rad/s^2,
    /// body frame), or None without the planned-rate filter.
    #[getter]
    fn planned_rates<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<Option<(Bound<'py, PyAny>, Bound<'py, PyAny>)>> {
        self.inner
            .planned_rates()
            .map(|r| Ok((matrix(py, &r.omega_d)?, matrix(py, &r.omega_d_dot)?)))
            .transpose()
    }

    /// The law's name: "paper", "offset-free" or "custom".
    #[getter]
    fn law(&self) -> &'static str {
        self.law.name()
    }

    #[doc = include_str!("../docstrings/tvmd.Controller.step.txt")]
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
                let inner = StepData::new(out, n, allocation);
                Ok(PyStepOutput { inner })
            }
            Err(error) => {
                let commands = commands_array(py, &error.commands, n);
                Err(cycle_error(py, &error, commands))
            }
        }
    }

    #[doc = include_str!("../docstrings/tvmd.Controller.law_stage.txt")]
    fn law_stage(
        slf: &Bound<'_, Self>,
        py: Python<'_>,
        state: &Bound<'_, PyAny>,
        reference: &Bound<'_, PyAny>,
    ) -> PyResult<PyLawStage> {
        let (state, reference) = (state_arg(state)?, reference_arg(reference)?);
        let mut this = borrow_mut(slf)?;
        let n = this.inner.team().len();
        match this.inner.law(&state, &reference) {
            Ok(inner) => Ok(PyLawStage { inner }),
            Err(error) => Err(cycle_error(
                py,
                &error,
                commands_array(py, &error.commands, n),
            )),
        }
    }

    #[doc = include_str!("../docstrings/tvmd.Controller.allocate.txt")]
    fn allocate(
        slf: &Bound<'_, Self>,
        py: Python<'_>,
        wrench: &Bound<'_, PyAny>,
    ) -> PyResult<PyAllocationStage> {
        let wrench = finite::<6, 1>(wrench, "wrench")?;
        let mut this = borrow_mut(slf)?;
        let this = &mut *this;
        let n = this.inner.team().len();
        match this.inner.allocate(&wrench) {
            Ok(stage) => {
                let allocation = AllocationData::new(stage.allocation, n, this.inner.allocator());
                Ok(PyAllocationStage {
                    inner: AllocationStageData::new(stage, n, allocation),
                })
            }
            Err(error) => Err(cycle_error(
                py,
                &error,
                commands_array(py, &error.commands, n),
            )),
        }
    }

    #[doc = include_str!("../docstrings/tvmd.Controller.plan.txt")]
    fn plan(
        &self,
        reference_attitude: &Bound<'_, PyAny>,
        force: &Bound<'_, PyAny>,
    ) -> PyResult<PyPlannerResult> {
        let r_r = finite::<3, 3>(reference_attitude, "reference_attitude")?;
        let f = finite::<3, 1>(force, "force")?;
        let inner = self.inner.plan(&r_r, &f).or_raise()?;
        Ok(PyPlannerResult { inner })
    }

    /// The team.
    #[getter]
    fn team(&self) -> PyTeam {
        PyTeam {
            inner: *self.inner.team(),
        }
    }

    /// The law's gains: `gains` as given (law "paper"), scaled by the team ("team-scaled") or
    /// from the natural frequencies ("offset-free").
    #[getter]
    fn gains(&self) -> PyGains {
        PyGains {
            inner: *self.inner.gains(),
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
            "Controller(n={}, law='{}', relaxation={}, allocator='{}', failed={:?})",
            self.inner.team().len(),
            self.law(),
            self.relaxation(),
            self.allocator(),
            self.failed()
        )
    }
}

/// Registers the controller classes.
pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyController>()?;
    Ok(())
}
