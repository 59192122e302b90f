//! The summary of a run: [`RunSummary`] (extremes and final values) and [`PaperMetrics`] (the
//! paper's reproduction metrics, see `docs/method.md`). Pure functions of the samples (and, for
//! the final state and the counters, of the loop's [`RunTotals`]); nothing is hard-coded from
//! the paper.
//!
//! One rule picks the sample "at" a time: [`sample_at`], the nearest sample if it lies within
//! half a sample spacing.

use serde::Serialize;

use crate::math::roll_pitch_yaw;
use crate::physics::PlantState;
use crate::reference::ReferenceConfig;
use crate::scenario::{Precision, Scenario};
use crate::sim::sample::{arr, Sample};

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
    let best = samples
        .iter()
        .min_by(|a, b| (a.t - t).abs().total_cmp(&(b.t - t).abs()))?;
    let spacing = match (samples.first(), samples.last()) {
        (Some(first), Some(last)) if samples.len() > 1 => {
            (last.t - first.t) / (samples.len() - 1) as f64
        }
        _ => f64::INFINITY,
    };
    ((best.t - t).abs() <= 0.5 * spacing + 1e-9).then_some(best)
}

/// Horizontal error `||(x - x_r)_{x,y}||` at [`sample_at`]`(t)` (m).
pub fn horizontal_error_at(samples: &[Sample], t: f64) -> Option<f64> {
    sample_at(samples, t).map(Sample::horizontal_error)
}

/// Time after `start` from which `value` stays at or below `threshold` until `end`: the last
/// sample in `[start, end]` above the threshold, minus `start` (0 if none is above). `None` if
/// no sample in the window has a value.
pub fn settling_time(
    samples: &[Sample],
    start: f64,
    end: f64,
    threshold: f64,
    value: impl Fn(&Sample) -> Option<f64>,
) -> Option<f64> {
    let window: Vec<(f64, f64)> = samples
        .iter()
        .filter(|x| x.t >= start - 1e-9 && x.t <= end + 1e-9)
        .filter_map(|x| value(x).map(|v| (x.t, v)))
        .collect();
    if window.is_empty() {
        return None;
    }
    Some(
        window
            .iter()
            .filter(|(_, v)| *v > threshold)
            .map(|(t, _)| t - start)
            .fold(0.0, f64::max),
    )
}

/// The largest value, `None` for none.
fn max_of(values: impl Iterator<Item = f64>) -> Option<f64> {
    values.fold(None, |m: Option<f64>, v| Some(m.map_or(v, |m| m.max(v))))
}

/// The smallest value, `None` for none.
fn min_of(values: impl Iterator<Item = f64>) -> Option<f64> {
    values.fold(None, |m: Option<f64>, v| Some(m.map_or(v, |m| m.min(v))))
}

/// The largest `|phi_d|` reported (rad).
fn max_planned_roll(samples: &[Sample]) -> Option<f64> {
    max_of(samples.iter().filter_map(|x| x.planned_roll.map(f64::abs)))
}

/// The largest `e_f` reported and its time `(t, e_f)`; the first of equal maxima.
fn max_e_f(samples: &[Sample]) -> Option<(f64, f64)> {
    samples.iter().filter_map(|x| x.e_f.map(|e| (x.t, e))).fold(
        None,
        |m: Option<(f64, f64)>, (t, e)| match m {
            Some((_, me)) if me >= e => m,
            _ => Some((t, e)),
        },
    )
}

/// The largest `||x - x_r||` over the samples with `from <= t <= to` (m).
fn max_position_error(samples: &[Sample], from: f64, to: f64) -> Option<f64> {
    max_of(
        samples
            .iter()
            .filter(|x| x.t >= from - 1e-9 && x.t <= to + 1e-9)
            .map(Sample::position_error),
    )
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

/// One hover classification of a run: when the controller accepted a new failure mask.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct HoverClassification {
    /// Time (s) of the controller tick that accepted the mask.
    pub time: f64,
    /// Whether the working agents can hold hover with a margin.
    pub capable: bool,
    /// The certified margin (`<= 0`: none).
    pub margin: f64,
    /// Whether the scenario's `failure_response` started a landing on it.
    pub landing: bool,
}

/// Summary of a run.
#[derive(Clone, Debug, PartialEq, Serialize)]
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
    /// `V_x` at the last sample, if reported.
    pub final_v_x: Option<f64>,
    /// `V_R` at the last sample, if reported.
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
    /// Number of controller calls.
    pub controller_calls: usize,
    /// Number of physics steps.
    pub physics_steps: usize,
    /// Wall-clock time spent in [`crate::sim::Simulation::run`] (s), logging included.
    pub wall_time: f64,
    /// Real-time factor: simulated time over wall time.
    pub real_time_factor: f64,
}

/// The null-space stage over a run: its smallest normalized margin to the admissible
/// boundary (`docs/method.md`, "Null-space stage") before and after it, over the samples where
/// it ran.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
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

impl NullSpaceSummary {
    /// `None` when the stage never ran.
    fn of(samples: &[Sample]) -> Option<Self> {
        let margins: Vec<[f64; 2]> = samples
            .iter()
            .filter_map(|x| x.null_space_margins)
            .collect();
        if margins.is_empty() {
            return None;
        }
        let n = margins.len() as f64;
        Some(Self {
            periods: margins.len(),
            raised_periods: margins.iter().filter(|[b, a]| a > b).count(),
            mean_margin_before: margins.iter().map(|m| m[0]).sum::<f64>() / n,
            mean_margin_after: margins.iter().map(|m| m[1]).sum::<f64>() / n,
            min_margin_before: margins.iter().map(|m| m[0]).fold(f64::INFINITY, f64::min),
            min_margin_after: margins.iter().map(|m| m[1]).fold(f64::INFINITY, f64::min),
        })
    }
}

impl RunSummary {
    /// The summary of a run of `scenario`: final state and counters from `totals`, extremes
    /// from the samples.
    pub fn new(scenario: &Scenario, samples: &[Sample], totals: &RunTotals) -> Self {
        let s = &totals.final_state;
        let tilt = |x: &Sample| {
            let [r, p, _] = x.roll_pitch_yaw;
            (r.cos() * p.cos()).clamp(-1.0, 1.0).acos()
        };
        let weight = totals.mass * scenario.physics.gravity;
        let e_f_max = max_e_f(samples);
        let working_thrusts = || {
            samples.iter().flat_map(|x| {
                x.commands
                    .iter()
                    .zip(&x.failed)
                    .filter(|(_, f)| !**f)
                    .map(|(c, _)| c.thrust)
            })
        };
        let commands = || samples.iter().flat_map(|x| x.commands.iter());
        let time = totals.time;
        Self {
            scenario: scenario.name.clone(),
            controller_precision: scenario.controller_precision,
            controller_target: crate::flight::HOST_TARGET.to_string(),
            time,
            interrupted: totals.interrupted,
            error: None,
            final_position: arr(&s.position),
            final_velocity: arr(&s.velocity),
            final_omega: arr(&s.omega),
            final_roll_pitch_yaw: roll_pitch_yaw(&s.rotation),
            max_position_error: samples
                .iter()
                .map(Sample::position_error)
                .fold(0.0, f64::max),
            max_position_error_after_4s: samples
                .iter()
                .filter(|x| x.t >= SETTLING_TIME - 1e-9)
                .map(Sample::position_error)
                .fold(0.0, f64::max),
            final_position_error: samples.last().map(Sample::position_error).unwrap_or(0.0),
            horizontal_error_at_4s: horizontal_error_at(samples, 4.0),
            horizontal_error_at_12s: horizontal_error_at(samples, 12.0),
            max_tilt: samples.iter().map(tilt).fold(0.0, f64::max),
            max_roll: samples
                .iter()
                .map(|x| x.roll_pitch_yaw[0].abs())
                .fold(0.0, f64::max),
            max_planned_roll: max_planned_roll(samples),
            max_e_f: e_f_max.map(|(_, e)| e),
            max_e_f_time: e_f_max.map(|(t, _)| t),
            max_e_f_over_weight: e_f_max.map(|(_, e)| e / weight),
            final_v_x: samples.last().and_then(|x| x.v_x),
            final_v_r: samples.last().and_then(|x| x.v_r),
            min_thrust: min_of(working_thrusts()),
            max_thrust: max_of(working_thrusts()),
            max_abs_eta_x: commands().map(|c| c.eta_x.abs()).fold(0.0, f64::max),
            max_abs_eta_y: commands().map(|c| c.eta_y.abs()).fold(0.0, f64::max),
            saturated_periods: samples
                .iter()
                .filter(|x| x.saturated_agents.is_some_and(|n| n > 0))
                .count(),
            cycle_errors: samples.iter().filter(|x| x.cycle_error).count(),
            null_space: NullSpaceSummary::of(samples),
            hover_classifications: samples
                .iter()
                .filter_map(|x| {
                    x.hover.as_ref().map(|h| HoverClassification {
                        time: x.t,
                        capable: h.capable,
                        margin: h.margin,
                        landing: h.landing,
                    })
                })
                .collect(),
            controller_calls: totals.controller_calls,
            physics_steps: totals.physics_steps,
            wall_time: totals.wall_time,
            real_time_factor: if totals.wall_time > 0.0 {
                time / totals.wall_time
            } else {
                f64::INFINITY
            },
        }
    }
}

/// Metrics of a paper-tilt-like run.
#[derive(Clone, Debug, PartialEq, Serialize)]
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

/// A rise of `V_x` between two times.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct VxRise {
    /// `V_x(to) - V_x(from)`.
    pub rise: f64,
    /// Time of the preceding minimum (s).
    pub from: f64,
    /// `V_x` at `from`.
    pub from_value: f64,
    /// Time of the peak (s).
    pub to: f64,
    /// `V_x` at `to`.
    pub to_value: f64,
}

fn max_rise(samples: &[Sample]) -> Option<VxRise> {
    let mut best: Option<VxRise> = None;
    let mut low: Option<(f64, f64)> = None;
    for (t, v) in samples.iter().filter_map(|x| x.v_x.map(|v| (x.t, v))) {
        let (lt, lv) = match low {
            Some((lt, lv)) if lv <= v => (lt, lv),
            _ => {
                low = Some((t, v));
                (t, v)
            }
        };
        if best.is_none_or(|b| v - lv > b.rise) {
            best = Some(VxRise {
                rise: v - lv,
                from: lt,
                from_value: lv,
                to: t,
                to_value: v,
            });
        }
    }
    best
}

impl PaperMetrics {
    /// Computes the metrics of a run of `scenario` (the tilt window comes from its reference).
    pub fn new(scenario: &Scenario, samples: &[Sample]) -> Self {
        let tilt = match &scenario.reference {
            ReferenceConfig::PaperTilt(p) if p.tilt[1] > p.tilt[0] && p.roll_peak != 0.0 => {
                Some(p.tilt)
            }
            _ => None,
        };
        let (settling, max_err) = match tilt {
            Some([b0, b1]) => {
                let end = b0 + 0.75 * (b1 - b0);
                let max = max_of(
                    samples
                        .iter()
                        .filter(|x| x.t >= b0 && x.t <= b1)
                        .filter_map(|x| x.attitude_error),
                );
                (
                    settling_time(samples, b0, end, ATTITUDE_SETTLED, |x| x.attitude_error),
                    max,
                )
            }
            None => (None, None),
        };
        let mut v_x_at: Vec<(f64, f64)> = [0.0, 2.0, 4.0, 8.0, 12.0, 14.0]
            .iter()
            .filter(|&&t| t < scenario.duration)
            .filter_map(|&t| sample_at(samples, t).and_then(|x| x.v_x.map(|v| (x.t, v))))
            .collect();
        if let Some((t, v)) = samples.last().and_then(|x| x.v_x.map(|v| (x.t, v))) {
            v_x_at.push((t, v));
        }
        let weight = scenario
            .team_body()
            .map_or(0.0, |b| b.mass() * scenario.physics.gravity);
        let visible = e_f_visible(scenario.controller_precision, weight);
        Self {
            horizontal_error_at_4s: horizontal_error_at(samples, 4.0),
            horizontal_error_at_12s: horizontal_error_at(samples, 12.0),
            max_planned_roll: max_planned_roll(samples),
            stage_b_attitude_settling: settling,
            stage_b_max_attitude_error: max_err,
            max_e_f: max_e_f(samples).map(|(t, e)| (e, t)),
            e_f_onset: samples
                .iter()
                .find(|x| x.e_f.is_some_and(|e| e > visible))
                .map(|x| x.t),
            e_f_visible: visible,
            max_position_error_6_to_12s: max_position_error(samples, 6.0, 12.0),
            v_x_at,
            max_v_x_after_4s: max_of(
                samples
                    .iter()
                    .filter(|x| x.t >= 4.0 - 1e-9)
                    .filter_map(|x| x.v_x),
            ),
            max_v_x_rise: max_rise(samples),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;

    fn sample(t: f64, x: f64, e_f: Option<f64>) -> Sample {
        Sample {
            t,
            position: [x, 0.0, 1.0],
            velocity: [0.0; 3],
            reference_position: [0.0, 0.0, 1.0],
            roll_pitch_yaw: [0.0; 3],
            reference_roll_pitch_yaw: [0.0; 3],
            reference_roll: 0.0,
            planned_roll: Some(-x),
            planned_roll_pitch_yaw: None,
            attitude_error: None,
            theta: None,
            e_f,
            saturated_agents: None,
            null_space_margins: None,
            v_x: Some(x),
            v_r: None,
            cycle_error: false,
            hover: None,
            commands: Vec::new(),
            actual: Vec::new(),
            failed: Vec::new(),
        }
    }

    #[test]
    fn sample_at_is_the_nearest_within_half_a_spacing() {
        let samples: Vec<Sample> = (0..5)
            .map(|k| sample(k as f64 * 0.01, k as f64, None))
            .collect();
        assert_eq!(sample_at(&samples, 0.021).map(|s| s.t), Some(0.02));
        assert_eq!(sample_at(&samples, 0.025 - 1e-6).map(|s| s.t), Some(0.02));
        assert_eq!(sample_at(&samples, 0.0449).map(|s| s.t), Some(0.04));
        assert!(sample_at(&samples, 0.0451).is_none());
        assert!(sample_at(&[], 0.0).is_none());
        assert_eq!(horizontal_error_at(&samples, 0.03), Some(3.0));
    }

    #[test]
    fn summary_and_paper_metrics_share_the_rules() {
        let samples = vec![
            sample(0.0, 0.5, Some(0.0)),
            sample(4.0, 0.2, Some(2e-6)),
            sample(8.0, 0.1, Some(3e-6)),
            sample(12.0, 0.3, Some(3e-6)),
        ];
        let scenario = Scenario {
            duration: 16.0,
            ..Scenario::default()
        };
        let totals = RunTotals {
            time: 16.0,
            final_state: PlantState::at_rest(Vector3::new(0.3, 0.0, 1.0)),
            mass: 2.0,
            controller_calls: 4,
            physics_steps: 16,
            wall_time: 0.0,
            interrupted: false,
        };
        let summary = RunSummary::new(&scenario, &samples, &totals);
        let paper = PaperMetrics::new(&scenario, &samples);
        assert_eq!(summary.horizontal_error_at_4s, Some(0.2));
        assert_eq!(summary.horizontal_error_at_12s, Some(0.3));
        assert_eq!(paper.horizontal_error_at_4s, summary.horizontal_error_at_4s);
        assert_eq!(
            paper.horizontal_error_at_12s,
            summary.horizontal_error_at_12s
        );
        assert_eq!(summary.max_planned_roll, Some(0.5));
        assert_eq!(paper.max_planned_roll, summary.max_planned_roll);
        // The first of equal maxima.
        assert_eq!(
            (summary.max_e_f, summary.max_e_f_time),
            (Some(3e-6), Some(8.0))
        );
        assert_eq!(paper.max_e_f, Some((3e-6, 8.0)));
        assert_eq!(paper.e_f_onset, Some(4.0));
        assert_eq!(paper.e_f_visible, E_F_VISIBLE);
        // In f32 a few uN are round-off, not a lost force.
        let f32_scenario = Scenario {
            controller_precision: Precision::F32,
            ..scenario.clone()
        };
        let f32_paper = PaperMetrics::new(&f32_scenario, &samples);
        let weight = 2.8 * crate::GRAVITY;
        assert_eq!(f32_paper.e_f_visible, e_f_visible(Precision::F32, weight));
        assert!((f32_paper.e_f_visible - 16.0 * 1.1920929e-7 * weight).abs() < 1e-12);
        assert_eq!(f32_paper.e_f_onset, None);
        assert_eq!(e_f_visible(Precision::F64, weight), E_F_VISIBLE);
        assert_eq!(summary.max_position_error_after_4s, 0.3);
        assert_eq!(paper.max_position_error_6_to_12s, Some(0.3));
        assert_eq!(summary.real_time_factor, f64::INFINITY);
        let rise = paper.max_v_x_rise.unwrap();
        assert_eq!((rise.from, rise.to, rise.rise), (8.0, 12.0, 0.3 - 0.1));
    }
}
