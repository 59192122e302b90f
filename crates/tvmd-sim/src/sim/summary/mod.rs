//! The summary of a run: [`RunSummary`] (extremes and final values) and [`PaperMetrics`] (the
//! paper's reproduction metrics, see `docs/method.md`). Both are folds over the samples
//! ([`SummaryFold`], one sample at a time, so a run is summarised without keeping its samples)
//! plus, for the final state and the counters, the loop's [`RunTotals`]; nothing is hard-coded
//! from the paper.
//!
//! One rule picks the sample "at" a time: [`sample_at`], the nearest sample if it lies within
//! half a sample spacing ([`rules::Nearest`]).

mod fault;
mod fold;
pub mod metrics;
pub mod rules;
#[cfg(test)]
pub(crate) mod tests;
mod verdict;

use serde::{Deserialize, Serialize};

use crate::sim::sample::Sample;
use tvmd_plant::physics::PlantState;
use tvmd_scenario::{Precision, Scenario};

pub use fault::{FaultEvent, FaultSummary};
pub use fold::SummaryFold;
pub use metrics::{EfficiencyMetrics, ErrorMetrics, FlightMetrics, MagnitudeMetrics};
pub use rules::Rise as VxRise;
pub use verdict::Verdict;

/// Time after which [`RunSummary::max_position_error_after_4s`] is taken (s): the end of
/// the paper's ascent plus its hover (stage A).
pub const SETTLING_TIME: f64 = 4.0;

/// Attitude-error threshold of [`PaperMetrics::stage_b_attitude_settling`] (rad).
pub const ATTITUDE_SETTLED: f64 = 0.01;

/// `e_f` above this counts as an unfulfilled force (N): the paper's experimental bound.
pub const E_F_VISIBLE: f64 = 1e-6;

/// The `e_f` threshold of [`PaperMetrics::e_f_onset`] for a controller in `precision` and a
/// team of weight `weight = m_C g` (N): [`E_F_VISIBLE`], or `16 eps m_C g` of the controller's
/// float type if that is larger. Round-off alone must not count as a lost force: in f32 it
/// leaves a few uN on forces of ~10 N (3.8e-6 N on `paper-tilt`), above the paper's 1e-6 N, so
/// the threshold becomes 5.2e-5 N (`1.9e-6 m_C g`) for the paper's team; in f64 it stays 1e-6 N.
pub fn e_f_visible(precision: Precision, weight: f64) -> f64 {
    let eps = match precision {
        Precision::F64 => f64::EPSILON,
        Precision::F32 => f64::from(f32::EPSILON),
    };
    E_F_VISIBLE.max(16.0 * eps * weight)
}

/// The sample nearest to `t`, if one lies within half a sample spacing (or the only one).
pub fn sample_at(samples: &[Sample], t: f64) -> Option<&Sample> {
    let mut spacing = rules::Spacing::default();
    let mut nearest = rules::Nearest::new(t);
    for (k, x) in samples.iter().enumerate() {
        spacing.push(x.t);
        nearest.push(x.t, k);
    }
    nearest.get(&spacing).map(|(_, k)| &samples[k])
}

/// What the loop knows at the end of a run besides the samples.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RunTotals {
    /// Simulated time reached (s).
    pub time: f64,
    /// The true state at that time.
    pub final_state: PlantState,
    /// Team mass `m_C` (kg).
    pub mass: f64,
    /// Number of controller calls.
    pub controller_calls: usize,
    /// Number of physics steps.
    pub physics_steps: usize,
    /// Wall-clock time spent in the loop (s), logging included.
    pub wall_time: f64,
    /// Whether the run was stopped before the scenario's end (a signal or the caller's flag).
    pub interrupted: bool,
}

/// One hover classification of a run: when the controller accepted, or refused, a new failure
/// mask.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct HoverClassification {
    /// Time (s) of the controller tick that accepted the mask.
    pub time: f64,
    /// Whether the working agents can hold hover with a margin.
    pub capable: bool,
    /// The certified margin (`<= 0`: none).
    pub margin: f64,
    /// Whether the scenario's `failure_response` started a landing on it.
    pub landing: bool,
    /// The controller refused the mask (it keeps the previous one): why. Then `capable` is
    /// false and `margin` 0.
    #[serde(default)]
    pub refused: Option<String>,
}

/// Summary of a run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RunSummary {
    /// Scenario name.
    pub scenario: String,
    /// The float type the controller flew in (`"f64"` or `"f32"`).
    pub controller_precision: Precision,
    /// Where the controller ran: `"host"`, or the emulated target of a processor-in-the-loop
    /// flight (e.g. `"cortex-m4 (qemu mps2-an386)"`).
    pub controller_target: String,
    /// Simulated time reached (s).
    pub time: f64,
    /// Whether the run was stopped before the scenario's end (SIGINT, SIGTERM, Ctrl-C in
    /// Python): the summary then covers `time` seconds only.
    pub interrupted: bool,
    /// The error that ended the flight early (then the summary covers `time` seconds only), or
    /// `None`.
    pub error: Option<String>,
    /// Final position (m).
    pub final_position: [f64; 3],
    /// Final world velocity (m/s).
    pub final_velocity: [f64; 3],
    /// Final body angular velocity (rad/s).
    pub final_omega: [f64; 3],
    /// Final roll, pitch, yaw (rad).
    pub final_roll_pitch_yaw: [f64; 3],
    /// Largest `||x - x_r||` over the samples (m).
    pub max_position_error: f64,
    /// Largest `||x - x_r||` over the samples at `t >= SETTLING_TIME` (4 s) (m).
    pub max_position_error_after_4s: f64,
    /// `||x - x_r||` at the last sample (m).
    pub final_position_error: f64,
    /// Horizontal error `||(x - x_r)_{x,y}||` at the sample at `t = 4 s` ([`sample_at`]) (m).
    pub horizontal_error_at_4s: Option<f64>,
    /// Horizontal error at the sample at `t = 12 s` ([`sample_at`]) (m).
    pub horizontal_error_at_12s: Option<f64>,
    /// Largest tilt angle (angle between body z and world z) over the samples (rad).
    pub max_tilt: f64,
    /// Largest actual roll `|phi|` (rad).
    pub max_roll: f64,
    /// Largest planned roll `|phi_d|`, if reported (rad).
    pub max_planned_roll: Option<f64>,
    /// Largest allocation error `e_f`, if reported (N).
    pub max_e_f: Option<f64>,
    /// Time of the largest `e_f` (s).
    pub max_e_f_time: Option<f64>,
    /// Largest `e_f / (m_C g)`, if reported.
    pub max_e_f_over_weight: Option<f64>,
    /// `V_x` of the last sample that reports it (the law's last period: a team disarmed on the
    /// ground reports none after its touchdown).
    pub final_v_x: Option<f64>,
    /// `V_R` of the last sample that reports it.
    pub final_v_r: Option<f64>,
    /// Smallest commanded thrust of a working agent (N).
    pub min_thrust: Option<f64>,
    /// Largest commanded thrust (N).
    pub max_thrust: Option<f64>,
    /// Largest commanded `|eta_x|` (rad).
    pub max_abs_eta_x: f64,
    /// Largest commanded `|eta_y|` (rad).
    pub max_abs_eta_y: f64,
    /// Controller periods in which the allocator saturated at least one agent.
    pub saturated_periods: usize,
    /// Controller periods the controller skipped (held commands).
    pub cycle_errors: usize,
    /// The null-space stage's margins, when the scenario runs one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub null_space: Option<NullSpaceSummary>,
    /// The hover classifications, one per accepted change of the failure mask.
    pub hover_classifications: Vec<HoverClassification>,
    /// What the fault detector reported, when the controller runs one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fault: Option<FaultSummary>,
    /// Number of controller calls.
    pub controller_calls: usize,
    /// Number of physics steps.
    pub physics_steps: usize,
    /// Wall-clock time spent in [`crate::sim::Simulation::run`] (s), logging included.
    pub wall_time: f64,
    /// Real-time factor: simulated time over wall time.
    pub real_time_factor: f64,
    /// The flight metrics (`docs/method.md`, "Flight metrics").
    pub metrics: FlightMetrics,
    /// The verdict against the scenario's `[success]` bounds.
    pub verdict: Verdict,
}

/// The null-space stage over a run: its smallest normalized margin to the admissible
/// boundary (`docs/method.md`, "Null-space stage") before and after it, over the samples where
/// it ran.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct NullSpaceSummary {
    /// Samples where the stage ran.
    pub periods: usize,
    /// Samples where it raised the smallest margin.
    pub raised_periods: usize,
    /// Mean smallest margin at the allocator's forces.
    pub mean_margin_before: f64,
    /// Mean smallest margin after the stage.
    pub mean_margin_after: f64,
    /// Lowest smallest margin at the allocator's forces.
    pub min_margin_before: f64,
    /// Lowest smallest margin after the stage.
    pub min_margin_after: f64,
}

impl RunSummary {
    /// The summary of a run of `scenario`: final state and counters from `totals`, extremes
    /// from the samples (the fold of [`SummaryFold::over`]).
    pub fn new(scenario: &Scenario, samples: &[Sample], totals: &RunTotals) -> Self {
        SummaryFold::over(scenario, samples).summary(scenario, totals)
    }
}

/// Metrics of a paper-tilt-like run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PaperMetrics {
    /// Horizontal error at `t = 4 s` (m) (calibration: 0.23 m).
    pub horizontal_error_at_4s: Option<f64>,
    /// Horizontal error at `t = 12 s` (m) (calibration: 0.11 m).
    pub horizontal_error_at_12s: Option<f64>,
    /// Largest planned roll `|phi_d|` (rad).
    pub max_planned_roll: Option<f64>,
    /// Time from the start of stage B until the angle between `R` and the planned `R_d` stays
    /// below [`ATTITUDE_SETTLED`] over the first three quarters of stage B (s); `None` without a
    /// tilt stage or planner output.
    pub stage_b_attitude_settling: Option<f64>,
    /// Largest angle between `R` and `R_d` during stage B (rad).
    pub stage_b_max_attitude_error: Option<f64>,
    /// Largest `e_f` and its time (N, s).
    pub max_e_f: Option<(f64, f64)>,
    /// First time `e_f` exceeds [`PaperMetrics::e_f_visible`] (s), if it does.
    pub e_f_onset: Option<f64>,
    /// The threshold of `e_f_onset` (N): [`e_f_visible`] of the run's controller precision
    /// and team weight (1e-6 N in f64).
    pub e_f_visible: f64,
    /// Largest `||x - x_r||` over `6 s <= t <= 12 s` (m): the tilt after the horizontal error's
    /// first minimum (where the paper sees "slight drifting" at `s = 1`).
    pub max_position_error_6_to_12s: Option<f64>,
    /// `V_x` at a few times `(t, V_x)`, the last one at the final sample.
    pub v_x_at: Vec<(f64, f64)>,
    /// Largest `V_x` after stage A (`t >= 4 s`).
    pub max_v_x_after_4s: Option<f64>,
    /// Largest rise of `V_x` over the run, `max_t (V_x(t) - min_{t' <= t} V_x(t'))`, with the
    /// times of the minimum and of the peak: 0 if `V_x` never increases.
    pub max_v_x_rise: Option<VxRise>,
}

impl PaperMetrics {
    /// Computes the metrics of a run of `scenario` (the tilt window comes from its reference)
    /// from its samples (the fold of [`SummaryFold::over`]).
    pub fn new(scenario: &Scenario, samples: &[Sample]) -> Self {
        SummaryFold::over(scenario, samples).paper()
    }
}
