//! One flight of a Monte Carlo study: its spec (what to fly, serialisable so that any
//! executor can ship it) and its row of the results table.

use std::sync::atomic::AtomicBool;

use serde::{Deserialize, Serialize};

use super::distributions::{Distributions, Draw};
use super::feasibility::Plant;
use crate::StudyError;
use tvmd_scenario::Scenario;
use tvmd_sim::runner::{fly, RunSpec};
use tvmd_sim::sim::SampleRetention;

/// One flight: the base scenario (as TOML, so the spec stands alone), the team and allocator,
/// and the draw's seed and index.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FlightSpec {
    /// The base scenario, TOML.
    pub scenario_toml: String,
    /// The catalogue team flown (`team.preset`), or `None` for the scenario's own.
    pub team: Option<String>,
    /// The allocator flown.
    pub allocator: String,
    /// The study's seed.
    pub seed: u64,
    /// The flight's index in its group (its random stream).
    pub index: u64,
    /// The distributions drawn from.
    pub distributions: Distributions,
}

impl FlightSpec {
    /// The spec as JSON (what crosses a process boundary).
    pub fn to_json(&self) -> Result<String, StudyError> {
        serde_json::to_string(self).map_err(|e| StudyError::Internal(e.to_string()))
    }

    /// A spec from [`FlightSpec::to_json`]'s text.
    pub fn from_json(text: &str) -> Result<Self, StudyError> {
        serde_json::from_str(text).map_err(|e| StudyError::InvalidArgument {
            name: "flight spec".into(),
            reason: e.to_string(),
        })
    }

    /// The scenario this flight flies: base, team, allocator, the draw, then the study's
    /// flight conditions.
    pub fn scenario(&self) -> Result<(Scenario, Draw), StudyError> {
        let mut base = Scenario::from_toml_str(&self.scenario_toml)?;
        if let Some(team) = &self.team {
            base.team.preset = Some(team.clone());
            base.team.agents = None;
        }
        base.allocator.clone_from(&self.allocator);
        base.validate()?;
        let n = base.team_body()?.len();
        let draw = Draw::new(&self.distributions, self.seed, self.index, n);
        let mut flown = draw.apply(&base)?;
        self.distributions
            .conditions
            .apply(&mut flown, self.seed, self.index);
        flown.validate()?;
        Ok((flown, draw))
    }
}

/// One flight's row: what it drew and how it flew. Every field is a number, a bool or a
/// string, so the table loads as it is in pandas or polars; a metric the run did not produce
/// is empty (`None`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FlightRow {
    /// Scenario name.
    pub scenario: String,
    /// Team (preset name, or `custom`).
    pub team: String,
    /// Allocator.
    pub allocator: String,
    /// The control law that flew: `"paper"`, `"offset-free"` or `"custom"`.
    pub law: String,
    /// The study's seed.
    pub seed: u64,
    /// The flight's index.
    pub index: u64,
    /// The distributions' `model_error` multiplier.
    pub model_error: f64,
    /// Drawn plant mass over the model's.
    pub mass_scale: f64,
    /// Drawn plant inertia over the model's.
    pub inertia_scale: f64,
    /// Drawn centre-of-mass offset, norm (m).
    pub com_offset: f64,
    /// Lowest drawn agent thrust efficiency.
    pub min_agent_efficiency: f64,
    /// Largest drawn gimbal offset magnitude (rad).
    pub max_gimbal_offset: f64,
    /// Drawn initial horizontal offset, norm (m).
    pub initial_offset: f64,
    /// Drawn initial tilt (rad).
    pub initial_tilt: f64,
    /// The verdict.
    pub success: bool,
    /// Whether any admissible command of the plant as built can hold the reference at the
    /// sampled instants: `"feasible"`, `"infeasible"` or `"undecided"`
    /// ([`super::feasibility`]). A failed flight that was infeasible is no fault of the
    /// controller.
    pub feasibility: String,
    /// The first sampled instant no admissible command could hold (s), if any.
    pub infeasible_at: Option<f64>,
    /// The bounds missed, `; `-separated (empty on success).
    pub failures: String,
    /// The error that ended the flight early, if any.
    pub error: Option<String>,
    /// Simulated time (s).
    pub time: f64,
    /// Position error: peak (m).
    pub position_peak: Option<f64>,
    /// Position error: 2% settling time (s).
    pub position_settling_time: Option<f64>,
    /// Position error: steady state (m).
    pub position_steady_state: Option<f64>,
    /// Position error: `int e dt` (m s).
    pub position_integral: Option<f64>,
    /// Position error: RMS (m).
    pub position_rms: Option<f64>,
    /// Attitude error to `R_r`: peak (rad).
    pub attitude_peak: Option<f64>,
    /// Attitude error to `R_d`: 2% settling time (s).
    pub planned_attitude_settling_time: Option<f64>,
    /// Attitude error to `R_d`: steady state (rad).
    pub planned_attitude_steady_state: Option<f64>,
    /// Attitude error to `R_d`: `int e dt` (rad s).
    pub planned_attitude_integral: Option<f64>,
    /// Largest force error `e_f` (N).
    pub max_force_error: Option<f64>,
    /// Largest moment error `e_tau` (N m).
    pub max_moment_error: Option<f64>,
    /// Mean thrust efficiency.
    pub mean_thrust_efficiency: Option<f64>,
    /// Lowest thrust efficiency.
    pub min_thrust_efficiency: Option<f64>,
    /// Time saturated (s).
    pub time_saturated: f64,
}

/// Flies `spec` and returns its row; `Err` only when the flight cannot start (a bad scenario
/// or draw). A flight that fails in the air is a row with `error` set and `success` false.
pub fn fly_flight(spec: &FlightSpec) -> Result<FlightRow, StudyError> {
    fly_flight_until(spec, None)?.ok_or_else(|| StudyError::Internal("a flight stopped".into()))
}

/// [`fly_flight`], stopping at the next controller tick once `cancel` is set: `None` then (a
/// flight cut short is no sample of the study).
pub fn fly_flight_until(
    spec: &FlightSpec,
    cancel: Option<&AtomicBool>,
) -> Result<Option<FlightRow>, StudyError> {
    let (scenario, draw) = spec.scenario()?;
    let run = RunSpec {
        scenario: scenario.clone(),
        log: None,
        pil: None,
        samples: SampleRetention::None,
    };
    let flight = fly(&run, None, cancel)?;
    let feasibility = Plant::new(&scenario)?.verdict(&scenario);
    if flight.result.summary.interrupted {
        return Ok(None);
    }
    let s = &flight.result.summary;
    let m = &s.metrics;
    let p = m.position.as_ref();
    let att = m.attitude.as_ref();
    let planned = m.planned_attitude.as_ref();
    let plant = &draw.plant;
    Ok(Some(FlightRow {
        scenario: scenario.name.clone(),
        team: spec
            .team
            .clone()
            .or_else(|| scenario.team.preset.clone())
            .unwrap_or_else(|| {
                if scenario.team.agents.is_some() {
                    "custom".into()
                } else {
                    "a4-inc".into()
                }
            }),
        allocator: scenario.allocator.clone(),
        law: scenario.law.name().into(),
        seed: spec.seed,
        index: spec.index,
        model_error: spec.distributions.model_error,
        mass_scale: plant.mass_scale,
        inertia_scale: plant.inertia_scale,
        com_offset: plant.com_offset.iter().map(|c| c * c).sum::<f64>().sqrt(),
        min_agent_efficiency: plant.thrust_efficiency.iter().copied().fold(1.0, f64::min),
        max_gimbal_offset: plant
            .gimbal_offsets
            .iter()
            .map(|[x, y]| x.hypot(*y))
            .fold(0.0, f64::max),
        initial_offset: draw.initial_offset[0].hypot(draw.initial_offset[1]),
        initial_tilt: draw.initial_tilt[0],
        success: s.verdict.success,
        feasibility: feasibility.feasibility.name().into(),
        infeasible_at: feasibility.first_infeasible,
        failures: s.verdict.failures.join("; "),
        error: s.error.clone(),
        time: s.time,
        position_peak: p.map(|e| e.peak),
        position_settling_time: p.and_then(|e| e.settling_time),
        position_steady_state: p.and_then(|e| e.steady_state),
        position_integral: p.map(|e| e.integral),
        position_rms: p.map(|e| e.rms),
        attitude_peak: att.map(|e| e.peak),
        planned_attitude_settling_time: planned.and_then(|e| e.settling_time),
        planned_attitude_steady_state: planned.and_then(|e| e.steady_state),
        planned_attitude_integral: planned.map(|e| e.integral),
        max_force_error: m.force_error.map(|e| e.max),
        max_moment_error: m.moment_error.map(|e| e.max),
        mean_thrust_efficiency: m.thrust_efficiency.map(|e| e.mean),
        min_thrust_efficiency: m.thrust_efficiency.map(|e| e.min),
        time_saturated: m.time_saturated,
    }))
}
