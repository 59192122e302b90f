//! `tvmd.sim.SimResult`: one simulated run as NumPy time series and summary dicts, and its
//! pickle (CBOR) for executors.

use std::path::PathBuf;

use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;

use tvmd_plant::actuators::ActuatorCommand;
use tvmd_scenario::Scenario;
use tvmd_sim::control::hover_roll_limit;
use tvmd_sim::runner::RunSpec;
use tvmd_sim::sim::{agent_forces, PaperMetrics, RunResult, RunSummary, Sample};

use crate::convert::{record_to_py, shaped};
use crate::errors::value_error;
use crate::record::record;

/// A scenario in a `SimResult`'s pickle: its TOML (every field, validated on the way back).
mod scenario_as_toml {
    use serde::{Deserialize, Deserializer, Serializer};
    use tvmd_scenario::Scenario;

    pub(super) fn serialize<S: Serializer>(s: &Scenario, out: S) -> Result<S::Ok, S::Error> {
        let text = s.to_toml_string().map_err(serde::ser::Error::custom)?;
        out.serialize_str(&text)
    }

    pub(super) fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Scenario, D::Error> {
        let text = String::deserialize(d)?;
        Scenario::from_toml_str(&text).map_err(serde::de::Error::custom)
    }
}

/// One run as `SimResult` keeps it: the scenario that ran, its samples and metrics.
#[derive(serde::Serialize, serde::Deserialize)]
pub(crate) struct SimData {
    #[serde(with = "scenario_as_toml")]
    scenario: Scenario,
    mcap: Option<PathBuf>,
    samples: Vec<Sample>,
    sample_stride: usize,
    summary: RunSummary,
    paper: PaperMetrics,
    hover_roll_limit: Option<f64>,
    mass: Option<f64>,
    n: usize,
    /// Your own controller flew (`Simulation.step` with commands or `step_wrench`): the
    /// scenario's law and relaxation did not.
    #[serde(default)]
    own_controller: bool,
}

impl SimData {
    pub(crate) fn new(spec: RunSpec, result: RunResult) -> Self {
        let scenario = spec.scenario;
        let team = scenario.team_body().ok();
        let n = result.samples.first().map(|s| s.commands.len());
        Self {
            mass: team.as_ref().map(|t| t.mass()),
            paper: result.paper,
            hover_roll_limit: hover_roll_limit(&scenario, scenario.relaxation).ok(),
            n: n.or_else(|| team.as_ref().map(|t| t.len())).unwrap_or(0),
            mcap: spec.log,
            samples: result.samples,
            sample_stride: result.sample_stride,
            summary: result.summary,
            scenario,
            own_controller: false,
        }
    }

    /// The run of your own controller (`Simulation`): `law` and `relaxation` are None.
    pub(crate) fn own_controller(mut self, own: bool) -> Self {
        self.own_controller = own;
        self
    }

    /// The law that flew, or None for your own controller.
    fn law(&self) -> Option<&'static str> {
        (!self.own_controller).then(|| self.scenario.law.name())
    }

    /// The relaxation `s` that flew, or None for your own controller.
    fn relaxation(&self) -> Option<f64> {
        (!self.own_controller).then_some(self.scenario.relaxation)
    }

    fn mcap_string(&self) -> Option<String> {
        self.mcap.as_ref().map(|p| p.display().to_string())
    }

    /// A (K, ...) array of `K` per-sample values of `shape` each.
    fn column<'py, T: numpy::Element, I: IntoIterator<Item = T>>(
        &self,
        py: Python<'py>,
        shape: &[usize],
        f: impl Fn(&Sample) -> I,
    ) -> PyResult<Bound<'py, PyAny>> {
        let values = self.samples.iter().flat_map(f).collect();
        shaped(py, values, &[&[self.samples.len()], shape].concat())
    }

    /// (K,) values; NaN where a sample has none.
    fn scalar<'py>(
        &self,
        py: Python<'py>,
        f: impl Fn(&Sample) -> Option<f64>,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.column(py, &[], |s| [f(s).unwrap_or(f64::NAN)])
    }

    /// (K, 3) values; NaN rows where a sample has none.
    fn vector<'py>(
        &self,
        py: Python<'py>,
        f: impl Fn(&Sample) -> Option<[f64; 3]>,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.column(py, &[3], |s| f(s).unwrap_or([f64::NAN; 3]))
    }

    /// (K, n, 3) actuator values `eta_x, eta_y, thrust`.
    fn agents<'py>(
        &self,
        py: Python<'py>,
        f: impl Fn(&Sample) -> &[ActuatorCommand],
    ) -> PyResult<Bound<'py, PyAny>> {
        self.column(py, &[self.n, 3], |s| {
            let agent = |i| {
                f(s).get(i).map_or([f64::NAN; 3], |c: &ActuatorCommand| {
                    [c.eta_x, c.eta_y, c.thrust]
                })
            };
            (0..self.n).flat_map(agent).collect::<Vec<_>>()
        })
    }

    /// (K, n, 3) the agents' body-frame forces of the actual outputs; NaN if the team cannot
    /// be built.
    fn forces<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let team = self.scenario.team_body().ok();
        self.column(py, &[self.n, 3], |s| {
            let forces = team
                .as_ref()
                .map(|t| agent_forces(&s.actual, t, &self.scenario.plant))
                .unwrap_or_default();
            (0..self.n)
                .flat_map(|i| forces.get(i).copied().unwrap_or([f64::NAN; 3]))
                .collect::<Vec<_>>()
        })
    }

    /// (K, n) normalized commanded rotor speeds `sqrt(T / sigma_Tf)`.
    fn rotor_speeds<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let max = self.scenario.max_thrust().unwrap_or(f64::NAN);
        self.column(py, &[self.n], |s| {
            (0..self.n)
                .map(|i| {
                    s.commands
                        .get(i)
                        .map_or(f64::NAN, |c| (c.thrust.max(0.0) / max).sqrt())
                })
                .collect::<Vec<_>>()
        })
    }

    fn repr(&self) -> String {
        let mcap = self.mcap_string();
        format!(
            "SimResult(scenario_name='{}', law={}, relaxation={}, allocator='{}', \
             precision='{}', samples={}, n_agents={}, mcap_path={})",
            self.scenario.name,
            self.law()
                .map_or_else(|| "None".to_string(), |l| format!("'{l}'")),
            self.relaxation()
                .map_or_else(|| "None".to_string(), |s| s.to_string()),
            self.scenario.allocator,
            self.scenario.controller_precision,
            self.samples.len(),
            self.n,
            mcap.map_or_else(|| "None".to_string(), |p| format!("'{p}'"))
        )
    }
}

record! {
    #[doc = include_str!("../docstrings/tvmd.sim.SimResult.txt")]
    "SimResult" in "tvmd.sim" => PySimResult(SimData) repr SimData::repr |py, o| {
        /// Name of the scenario that ran.
        scenario_name => o.scenario.name.as_str(),
        /// Planner relaxation `s` of the run; None for your own controller's (`Simulation`).
        relaxation => o.relaxation(),
        /// Allocator of the run.
        allocator => o.scenario.allocator.as_str(),
        /// The null-space stage of the run ("margin", "inward-tilt=<rad>"), or None.
        null_space => o.scenario.null_space.map(|n| n.to_string()),
        /// The control law that flew: "paper", "offset-free" or "custom"; None for your own
        /// controller's flight (`Simulation.step` with commands, `step_wrench`).
        law => o.law(),
        /// The float type the controller flew in, "f64" or "f32".
        precision => o.scenario.controller_precision.as_str(),
        /// Where the controller ran: "host", or the emulated target of a processor-in-the-loop
        /// run (e.g. "cortex-m4 (qemu mps2-an386)").
        controller_target => o.summary.controller_target.as_str(),
        /// Path of the MCAP log written, or None.
        mcap_path => o.mcap_string(),
        /// Number of agents `n`.
        n_agents => o.n,
        /// Team mass `m_C` (kg).
        mass => o.mass,
        /// Gravity `g` (m/s^2).
        gravity => o.scenario.physics.gravity,
        /// `atan(c_y(1, s))` (rad), the planned roll at which the planner saturates in hover.
        hover_roll_limit => o.hover_roll_limit,
        /// Controller ticks between the kept samples (1: every tick; see `max_samples`).
        sample_stride => o.sample_stride,
        /// (K,) time (s).
        t => o.scalar(py, |x| Some(x.t))?,
        /// (K, 3) `x` (m).
        position => o.vector(py, |x| Some(x.position))?,
        /// (K, 3) `x_dot` (m/s), world frame (`velocity_world`; kept for compatibility).
        velocity => o.vector(py, |x| Some(x.velocity))?,
        /// (K, 3) `x_dot` (m/s), world frame.
        velocity_world => o.vector(py, |x| Some(x.velocity))?,
        /// (K, 3) `v = R^T x_dot` (m/s), body frame (the velocity of `tvmd.State`).
        velocity_body => o.vector(py, |x| Some(x.velocity_body()))?,
        /// (K, 3) body rates `Omega` (rad/s), body frame.
        angular_velocity => o.vector(py, |x| Some(x.omega))?,
        /// (K, 3, 3) attitude `R` (body to world).
        rotation => o.column(py, &[3, 3], |x| x.rotation.concat())?,
        /// (K, 3) `x_r` (m).
        reference_position => o.vector(py, |x| Some(x.reference_position))?,
        /// (K, 3) roll, pitch, yaw of `R` (rad, ZYX).
        attitude_rpy => o.vector(py, |x| Some(x.roll_pitch_yaw))?,
        /// (K, 3) roll, pitch, yaw of `R_r` (rad).
        reference_rpy => o.vector(py, |x| Some(x.reference_roll_pitch_yaw))?,
        /// (K,) `phi_r` (rad).
        reference_roll => o.scalar(py, |x| Some(x.reference_roll))?,
        /// (K,) `phi_d` of the planned `R_d` (rad).
        planned_roll => o.scalar(py, |x| x.planned_roll)?,
        /// (K, 3) roll, pitch, yaw of `R_d` (rad).
        planned_rpy => o.vector(py, |x| x.planned_roll_pitch_yaw)?,
        /// (K,) angle between `R` and `R_d` (rad).
        attitude_error => o.scalar(py, |x| x.attitude_error)?,
        /// (K,) angle between `R` and `R_r` (rad).
        reference_attitude_error => o.scalar(py, |x| Some(x.reference_attitude_error))?,
        /// (K,) planner angle `theta*` (rad).
        theta => o.scalar(py, |x| x.theta)?,
        /// (K,) allocation error `e_f` (N).
        e_f => o.scalar(py, |x| x.e_f)?,
        /// (K,) moment error `e_tau` (N m).
        e_tau => o.scalar(py, |x| x.e_tau)?,
        /// (K,) thrust efficiency `||u_f|| / sum_i ||f_i||`.
        thrust_efficiency => o.scalar(py, |x| x.thrust_efficiency)?,
        /// (K,) int64: agents the allocator saturated (-1 if not reported).
        saturated_agents => o.column(py, &[], |x| [x.saturated_agents.map_or(-1, |c| i64::try_from(c).unwrap_or(i64::MAX))])?,
        /// (K,) Lyapunov candidate `V_x`.
        v_x as "V_x" => o.scalar(py, |x| x.v_x)?,
        /// (K,) Lyapunov candidate `V_R`.
        v_r as "V_R" => o.scalar(py, |x| x.v_r)?,
        /// (K,) bool: the controller skipped the cycle.
        cycle_error => o.column(py, &[], |x| [x.cycle_error])?,
        /// (K, n, 3) commanded `eta_x, eta_y, thrust`.
        commands => o.agents(py, |x| &x.commands)?,
        /// (K, n, 3) actual actuator outputs.
        actual => o.agents(py, |x| &x.actual)?,
        /// (K, n, 3) body-frame forces of the actual outputs (N), with the plant's actuation
        /// error.
        forces => o.forces(py)?,
        /// (K, n) commanded rotor speeds, normalized (1 at the largest thrust):
        /// `sqrt(thrust / max_thrust)`.
        rotor_speeds => o.rotor_speeds(py)?,
        /// (K, n) bool: true failure flags.
        failed => o.column(py, &[o.n], |x| (0..o.n).map(|i| x.failed.get(i).copied().unwrap_or(false)).collect::<Vec<_>>())?,
        /// Every field of tvmd-sim's `RunSummary` (a fresh dict per access).
        summary => record_to_py(py, &o.summary)?,
        /// tvmd-sim's `PaperMetrics` as a dict.
        paper_metrics => record_to_py(py, &o.paper)?,
        /// The scenario that ran (overrides applied), as TOML.
        scenario_toml => o.scenario.to_toml_string().map_err(value_error)?,
    }
    methods {
        fn __len__(&self) -> usize {
            self.inner.samples.len()
        }

        #[doc = include_str!("../docstrings/tvmd.sim.SimResult.to_columns.txt")]
        fn to_columns<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyAny>> {
            let py = slf.py();
            py.import("tvmd.sim")?.getattr("_columns")?.call1((slf,))
        }

        #[doc = include_str!("../docstrings/tvmd.sim.SimResult.to_pandas.txt")]
        fn to_pandas<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyAny>> {
            let py = slf.py();
            py.import("tvmd.sim")?.getattr("_to_pandas")?.call1((slf,))
        }

        /// Pickles as `tvmd.sim._sim_result_from_state(bytes)`: every sample and summary in
        /// CBOR (NaN kept), so an executor's worker can send its result back.
        fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<(Bound<'py, PyAny>, (Bound<'py, pyo3::types::PyBytes>,))> {
            let mut bytes = Vec::new();
            ciborium::into_writer(&self.inner, &mut bytes)
                .map_err(|e| PyRuntimeError::new_err(format!("cannot pickle a SimResult: {e}")))?;
            let rebuild = py.import("tvmd.sim")?.getattr("_sim_result_from_state")?;
            Ok((rebuild, (pyo3::types::PyBytes::new(py, &bytes),)))
        }
    }
}

/// Registers `SimResult` on the `sim` submodule.
pub(crate) fn register(sim: &Bound<'_, PyModule>) -> PyResult<()> {
    sim.add_class::<PySimResult>()
}
