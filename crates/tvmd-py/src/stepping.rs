//! The simulator stepped from Python: `tvmd.sim.Simulation` (tvmd-sim's steppable
//! `Simulation`: `reset`, `step` with per-agent commands, `step_wrench` with a body wrench),
//! the `Observation` of a tick, and `ScenarioController`, the tvmd controller as `run` flies it,
//! as one client of the same steps. Thin: the arguments are converted by [`crate::convert`],
//! the scenario built by [`RunArgs`], the flight is tvmd-sim's.

use std::sync::Mutex;

use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict, PyType};

use tvmd_plant::actuators::ActuatorCommand;
use tvmd_sim::control::{core_reference, core_state};
use tvmd_sim::runner::RunSpec;
use tvmd_sim::sim::{Observation, SimOptions, Simulation, Verdict};
use tvmd_sim::{AnyTvmdController, FlightController, FlightOutput};

use crate::convert::{commands_arg, matrix, record_to_py, shaped};
use crate::convert::{finite, link_stats_to_py, wrench_arg, Int};
use crate::errors::value_error;
use crate::law::{PyReference, PyState};
use crate::record::record;
use crate::replay::{Action, ReplayLog};
use crate::runs::{control_args, spec};
use crate::sim_result::{PySimResult, SimData};

/// An observation and whether the run is over.
pub(crate) struct ObservationData {
    observation: Observation,
    done: bool,
    /// Per agent, what the plant clamped off the last step's commands.
    saturation: Vec<ActuatorCommand>,
}

record! {
    /// One controller tick as a controller sees it: `t` (s), `state` (the fed-back
    /// `tvmd.State`, noise and latency applied), `true_state`, `velocity_world` (3,),
    /// `reference` (a `tvmd.Reference`), `failed` (n,), `done`, `saturation` (n, 3) and
    /// `reports` (n, 4) or None.
    "Observation" in "tvmd.sim" => PyObservation(ObservationData) |py, o| {
        /// Simulation time `t_k` (s).
        t => o.observation.t,
        /// The fed-back state (noise and latency applied) as a `tvmd.State`.
        state => PyState { inner: core_state::<f64>(&o.observation.state) },
        /// The true state as a `tvmd.State`.
        true_state => PyState { inner: core_state::<f64>(&o.observation.truth) },
        /// (3,) world-frame velocity `x_dot` of the fed-back state (m/s).
        velocity_world => matrix(py, &o.observation.state.velocity)?,
        /// The reference at `t_k` as a `tvmd.Reference`.
        reference => PyReference { inner: core_reference::<f64>(&o.observation.reference) },
        /// (n,) bool: the failures the controller is told of.
        failed => shaped(py, o.observation.failed.clone(), &[o.observation.failed.len()])?,
        /// The scenario's duration is reached (no step follows).
        done => o.done,
        /// (n, 3) by how much the plant clamped the last step's commands to the hardware's
        /// range: the command minus what it held (`eta_x`, `eta_y` rad, thrust N); zero inside
        /// the range and after a reset.
        saturation => {
            let s = &o.saturation;
            shaped(py, s.iter().flat_map(|c| [c.eta_x, c.eta_y, c.thrust]).collect(), &[s.len(), 3])?
        },
        /// (n, 4) each agent's newest report arrived: rotor speed as thrust (N), `eta_x`,
        /// `eta_y` (rad), age (s); NaN before its first; None without the scenario's `[reports]`.
        reports => {
            let r = &o.observation.reports;
            let rows = r.iter().flat_map(|x| x.map_or([f64::NAN; 4], |x| [x.thrust, x.eta_x, x.eta_y, x.age]));
            (!r.is_empty()).then(|| shaped(py, rows.collect(), &[r.len(), 4])).transpose()?
        },
    }
}

/// A tvmd-sim error of a step as the Python exception.
fn step_error(e: tvmd_sim::SimError) -> PyErr {
    value_error(e)
}

/// The simulator stepped one controller period at a time with your own controller.
///
/// `Simulation(scenario="hover", *, toml, team, relaxation, allocator, precision, null_space,
/// law, max_samples, fault_detection, max_rounds)`: the plant of `run` (actuators, failures,
/// disturbances, noise). `reset()`
/// returns the first `Observation`; `step(commands)` holds (n, 3) `eta_x, eta_y, thrust` (or
/// (n, 4), or normalized rotor speeds with `rotor_speeds=True`, or a `ScenarioController`'s
/// output) and `step_wrench(u)` the allocation of a (6,) body wrench `[u_tau; u_f]` for one
/// controller period, each returning the next `Observation`; `result()` is the flight so far.
/// Bad actions raise `ValueError` and change nothing. `copy.deepcopy` and `pickle` replay the
/// steps since the last reset: the copy goes on exactly as the original.
#[pyclass(module = "tvmd.sim", name = "Simulation")]
pub(crate) struct PySimulation {
    sim: Simulation,
    spec: RunSpec,
    /// `max_samples` as given (`pickle` builds the copy with it).
    max_samples: Option<u64>,
    /// What the simulation did since its last reset (copies replay it).
    log: ReplayLog,
}

impl PySimulation {
    fn observation(&mut self) -> PyResult<PyObservation> {
        let done = self.sim.is_finished();
        let observation = self.sim.observe().map_err(step_error)?.clone();
        let saturation = self.sim.saturation().to_vec();
        Ok(PyObservation {
            inner: ObservationData {
                observation,
                done,
                saturation,
            },
        })
    }
}

#[pymethods]
impl PySimulation {
    #[new]
    #[pyo3(signature = (scenario = None, *, toml = None, team = None, relaxation = None, allocator = None, precision = None, null_space = None, law = None, max_samples = None, fault_detection = None, max_rounds = None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        scenario: Option<&Bound<'_, PyAny>>,
        toml: Option<String>,
        team: Option<&Bound<'_, PyAny>>,
        relaxation: Option<f64>,
        allocator: Option<String>,
        precision: Option<String>,
        null_space: Option<String>,
        law: Option<&Bound<'_, PyAny>>,
        max_samples: Option<Int>,
        fault_detection: Option<&Bound<'_, PyAny>>,
        max_rounds: Option<Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let control = control_args(fault_detection, max_rounds.as_ref())?;
        let spec = spec(
            py,
            scenario,
            toml,
            team,
            relaxation,
            allocator,
            precision,
            null_space,
            law,
            max_samples.as_ref(),
            control,
        )?;
        let options = SimOptions {
            samples: spec.samples,
        };
        let sim = Simulation::with_options(&spec.scenario, options).map_err(value_error)?;
        Ok(Self {
            sim,
            spec,
            max_samples: max_samples.as_ref().and_then(Int::get::<u64>),
            log: ReplayLog::default(),
        })
    }

    /// An independent simulation in the same state (`copy.copy`, `copy.deepcopy`): the
    /// same scenario with every reset and step since the last reset replayed, so what follows
    /// is what would have followed on the original (only `result().summary`'s wall time
    /// differs).
    fn __copy__(&self) -> PyResult<Self> {
        let options = SimOptions {
            samples: self.spec.samples,
        };
        let mut sim =
            Simulation::with_options(&self.spec.scenario, options).map_err(value_error)?;
        self.log.replay(&mut sim).map_err(PyRuntimeError::new_err)?;
        Ok(Self {
            sim,
            spec: self.spec.clone(),
            max_samples: self.max_samples,
            log: self.log.clone(),
        })
    }

    /// As `__copy__`.
    fn __deepcopy__(&self, _memo: &Bound<'_, PyAny>) -> PyResult<Self> {
        self.__copy__()
    }

    /// `pickle` support: the scenario as TOML, `max_samples` and the replay log; unpickling
    /// (`Simulation._restore`) builds the simulation and replays the log, as `__copy__`.
    #[allow(clippy::type_complexity)]
    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> PyResult<(
        Bound<'py, PyAny>,
        (String, Option<u64>, Bound<'py, PyBytes>),
    )> {
        let this = slf.borrow();
        let toml = this.scenario_toml()?;
        let log = this
            .log
            .to_bytes()
            .map_err(|e| PyRuntimeError::new_err(format!("cannot pickle a Simulation: {e}")))?;
        let restore = slf.get_type().getattr("_restore")?;
        Ok((
            restore,
            (toml, this.max_samples, PyBytes::new(slf.py(), &log)),
        ))
    }

    /// The simulation of `__reduce__`'s data.
    #[classmethod]
    fn _restore<'py>(
        cls: &Bound<'py, PyType>,
        toml: String,
        max_samples: Option<u64>,
        log: &[u8],
    ) -> PyResult<Bound<'py, PyAny>> {
        let kwargs = PyDict::new(cls.py());
        kwargs.set_item("toml", toml)?;
        kwargs.set_item("max_samples", max_samples)?;
        let restored = cls.call((), Some(&kwargs))?;
        {
            let sim = restored.cast::<Self>()?;
            let mut this = sim.borrow_mut();
            let this = &mut *this;
            this.log = ReplayLog::from_bytes(log).map_err(|e| {
                PyValueError::new_err(format!("not a pickled Simulation's log: {e}"))
            })?;
            this.log
                .replay(&mut this.sim)
                .map_err(PyRuntimeError::new_err)?;
        }
        Ok(restored)
    }

    /// Starts over (optionally reseeding the state noise, from another initial pose); the
    /// first observation. `seed` reseeds the state noise, links and reports; `position` (3,) and `attitude_rpy`
    /// (3,) replace the scenario's initial pose.
    #[pyo3(signature = (seed = None, *, position = None, attitude_rpy = None))]
    fn reset(
        &mut self,
        seed: Option<Int>,
        position: Option<&Bound<'_, PyAny>>,
        attitude_rpy: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<PyObservation> {
        let seed = seed
            .map(|s| s.to("seed", 0, i128::from(u64::MAX)))
            .transpose()?;
        let position = position
            .map(|p| finite::<3, 1>(p, "position"))
            .transpose()?;
        let attitude = attitude_rpy
            .map(|a| finite::<3, 1>(a, "attitude_rpy"))
            .transpose()?;
        let action = Action::Reset {
            seed,
            position: position.map(Into::into),
            attitude: attitude.map(Into::into),
        };
        self.log.apply(&mut self.sim, action).map_err(step_error)?;
        self.observation()
    }

    /// The current tick's observation (its noise is drawn once per tick).
    fn observe(&mut self) -> PyResult<PyObservation> {
        self.observation()
    }

    /// Holds per-agent commands (or a `ScenarioController`'s output) for one controller
    /// period; the next observation. `commands`: (n, 3) rows `eta_x, eta_y` (rad), `thrust` (N);
    /// (n, 4) in `tvmd.Controller`'s layout; with `rotor_speeds=True` the last column is the
    /// normalized rotor speed (thrust `max_thrust * omega**2`).
    #[pyo3(signature = (commands, *, rotor_speeds = false))]
    fn step(&mut self, commands: &Bound<'_, PyAny>, rotor_speeds: bool) -> PyResult<PyObservation> {
        if let Ok(out) = commands.cast::<PyControllerOutput>() {
            let action = Action::output(&out.get().inner);
            self.log.apply(&mut self.sim, action).map_err(step_error)?;
        } else {
            let n = self.sim.agents();
            let commands = commands_arg(commands, n, rotor_speeds, self.sim.max_thrust())?;
            let action = Action::Output {
                commands,
                diagnostics: None,
            };
            self.log.apply(&mut self.sim, action).map_err(step_error)?;
        }
        self.observation()
    }

    /// Holds the admissible commands of a body wrench for one controller period; the next
    /// observation. `wrench`: (6,) `[u_tau; u_f]` (N m, N), body frame, about the centre of
    /// mass; the scenario controller's allocation stage makes it admissible commands.
    fn step_wrench(&mut self, wrench: &Bound<'_, PyAny>) -> PyResult<PyObservation> {
        let wrench = wrench_arg(wrench)?;
        let action = Action::Wrench(wrench);
        self.log.apply(&mut self.sim, action).map_err(step_error)?;
        self.observation()
    }

    /// The flight so far as a `SimResult` (copied; the simulation goes on).
    fn result(&self) -> PySimResult {
        let mut result = self.sim.result();
        result.summary.verdict = Verdict::judge(&result.summary, &self.spec.scenario.success);
        PySimResult {
            inner: SimData::new(self.spec.clone(), result)
                .own_controller(self.log.own_controller()),
        }
    }

    /// The true state now, as a `tvmd.State`.
    #[getter]
    fn state(&self) -> PyState {
        PyState {
            inner: core_state::<f64>(&self.sim.state()),
        }
    }

    /// Simulation time (s).
    #[getter]
    fn time(&self) -> f64 {
        self.sim.time()
    }

    /// The scenario's duration is reached.
    #[getter]
    fn done(&self) -> bool {
        self.sim.is_finished()
    }

    /// The command links' counts per agent so far: a dict of (n,) int arrays `sent`, `lost`,
    /// `stale` (arrived after a newer one), `failsafes`; None without the scenario's `[links]`.
    fn link_stats<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        self.sim
            .link_stats()
            .map(|s| link_stats_to_py(py, &s))
            .transpose()
    }

    /// Number of agents `n`.
    #[getter]
    fn n_agents(&self) -> usize {
        self.sim.agents()
    }

    /// Team mass `m_C` (kg).
    #[getter]
    fn mass(&self) -> f64 {
        self.sim.team().mass()
    }

    /// Largest thrust of one agent `sigma_Tf` (N).
    #[getter]
    fn max_thrust(&self) -> f64 {
        self.sim.max_thrust()
    }

    /// (n, 3) the agents' positions `p_i` relative to the centre of mass (m, body frame).
    #[getter]
    fn agent_positions<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let agents = &self.sim.team().agents;
        let values = agents.iter().flat_map(|a| a.position).collect();
        shaped(py, values, &[agents.len(), 3])
    }

    /// `(sigma_x, sigma_y)`: the gimbal limits `|eta_x| <= sigma_x`, `|eta_y| <= sigma_y` (rad).
    #[getter]
    fn gimbal_limits(&self) -> (f64, f64) {
        let limits = &self.sim.scenario().limits;
        (limits.sigma_x, limits.sigma_y)
    }

    /// Controller period (s): the time one step holds its commands.
    #[getter]
    fn controller_period(&self) -> f64 {
        self.sim.scenario().controller_period
    }

    /// The scenario's duration (s).
    #[getter]
    fn duration(&self) -> f64 {
        self.sim.scenario().duration
    }

    /// The scenario (overrides applied) as TOML.
    #[getter]
    fn scenario_toml(&self) -> PyResult<String> {
        self.sim.scenario().to_toml_string().map_err(value_error)
    }

    fn __repr__(&self) -> String {
        format!(
            "Simulation(scenario_name='{}', n_agents={}, time={})",
            self.sim.scenario().name,
            self.sim.agents(),
            self.sim.time()
        )
    }
}

/// A `ScenarioController`'s output for one tick: `commands` (n, 3) and `diagnostics` (dict);
/// `Simulation.step` takes it as it is.
#[pyclass(module = "tvmd.sim", name = "ControllerOutput", frozen)]
pub(crate) struct PyControllerOutput {
    inner: FlightOutput,
}

#[pymethods]
impl PyControllerOutput {
    /// (n, 3) commands `eta_x, eta_y, thrust` (rad, rad, N).
    #[getter]
    fn commands<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let c = &self.inner.commands;
        let values = c
            .iter()
            .flat_map(|c| [c.eta_x, c.eta_y, c.thrust])
            .collect();
        shaped(py, values, &[c.len(), 3])
    }

    /// The controller's diagnostics of the tick (planner, law, allocation) as a dict.
    #[getter]
    fn diagnostics<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        record_to_py(py, &self.inner.diagnostics)
    }
}

/// The tvmd controller of a scenario exactly as `run` flies it (same arguments as
/// `Simulation`): `sim.step(ctrl.step(obs))` from `reset()` to `done` reproduces `run`.
#[pyclass(module = "tvmd.sim", name = "ScenarioController")]
pub(crate) struct PyScenarioController {
    /// In a mutex: a Python class must be `Sync`, the controller is `Send` only.
    inner: Mutex<AnyTvmdController>,
    /// The number of agents of its team (an observation of another team is refused).
    n: usize,
}

#[pymethods]
impl PyScenarioController {
    #[new]
    #[pyo3(signature = (scenario = None, *, toml = None, team = None, relaxation = None, allocator = None, precision = None, null_space = None, law = None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        scenario: Option<&Bound<'_, PyAny>>,
        toml: Option<String>,
        team: Option<&Bound<'_, PyAny>>,
        relaxation: Option<f64>,
        allocator: Option<String>,
        precision: Option<String>,
        null_space: Option<String>,
        law: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let spec = spec(
            py,
            scenario,
            toml,
            team,
            relaxation,
            allocator,
            precision,
            null_space,
            law,
            None,
            (None, None),
        )?;
        let inner = AnyTvmdController::from_scenario(&spec.scenario).map_err(value_error)?;
        let n = spec.scenario.team_body().map_err(value_error)?.len();
        Ok(Self {
            inner: Mutex::new(inner),
            n,
        })
    }

    /// The commands and diagnostics for one tick's observation (call it once per tick).
    fn step(&mut self, observation: &Bound<'_, PyObservation>) -> PyResult<PyControllerOutput> {
        let o = &observation.get().inner.observation;
        if o.failed.len() != self.n {
            return Err(pyo3::exceptions::PyValueError::new_err(format!(
                "`observation` is of a team of {} agents; this controller flies {}",
                o.failed.len(),
                self.n
            )));
        }
        let mut controller = self
            .inner
            .lock()
            .map_err(|_| PyRuntimeError::new_err("the controller failed in another thread"))?;
        let inner = controller.step(&o.input()).map_err(|e| {
            PyRuntimeError::new_err(format!("controller failed at t = {:.3} s: {e}", o.t))
        })?;
        Ok(PyControllerOutput { inner })
    }
}

/// Registers `Simulation`, `Observation`, `ScenarioController` and `ControllerOutput` on the
/// `sim` submodule.
pub(crate) fn register(sim: &Bound<'_, PyModule>) -> PyResult<()> {
    sim.add_class::<PySimulation>()?;
    sim.add_class::<PyObservation>()?;
    sim.add_class::<PyScenarioController>()?;
    sim.add_class::<PyControllerOutput>()
}
