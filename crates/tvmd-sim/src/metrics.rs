//! The paper's reproduction metrics, computed from the samples of a run (SPEC "Reproduction
//! targets"). Pure functions of the samples; nothing here is hard-coded from the paper.

use serde::Serialize;

use crate::reference::ReferenceConfig;
use crate::scenario::Scenario;
use crate::sim::Sample;

/// Attitude-error threshold of [`PaperMetrics::stage_b_attitude_settling`] (rad).
pub const ATTITUDE_SETTLED: f64 = 0.01;

/// `e_f` above this counts as an unfulfilled force (N): the paper's experimental bound.
pub const E_F_VISIBLE: f64 = 1e-6;

/// Metrics of a paper-tilt-like run.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PaperMetrics {
    /// Horizontal error at `t = 4 s` (m) (SPEC calibration: 0.23 m).
    pub horizontal_error_at_4s: Option<f64>,
    /// Horizontal error at `t = 12 s` (m) (SPEC calibration: 0.11 m).
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
    /// First time `e_f` exceeds [`E_F_VISIBLE`] (s), if it does.
    pub e_f_onset: Option<f64>,
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

/// The sample nearest to `t`, if one lies within half a sample spacing (or the only one).
pub fn sample_at(samples: &[Sample], t: f64) -> Option<&Sample> {
    let best = samples
        .iter()
        .min_by(|a, b| (a.t - t).abs().total_cmp(&(b.t - t).abs()))?;
    let spacing = if samples.len() > 1 {
        (samples[samples.len() - 1].t - samples[0].t) / (samples.len() - 1) as f64
    } else {
        f64::INFINITY
    };
    ((best.t - t).abs() <= 0.5 * spacing + 1e-9).then_some(best)
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

impl PaperMetrics {
    /// Computes the metrics of a run of `scenario` (the tilt window comes from its reference).
    pub fn new(scenario: &Scenario, samples: &[Sample]) -> Self {
        let tilt = match &scenario.reference {
            ReferenceConfig::PaperTilt(p) if p.tilt[1] > p.tilt[0] && p.roll_peak != 0.0 => {
                Some(p.tilt)
            }
            _ => None,
        };
        let horizontal = |t: f64| sample_at(samples, t).map(Sample::horizontal_error);
        let (settling, max_err) = match tilt {
            Some([b0, b1]) => {
                let end = b0 + 0.75 * (b1 - b0);
                let max = samples
                    .iter()
                    .filter(|x| x.t >= b0 && x.t <= b1)
                    .filter_map(|x| x.attitude_error)
                    .fold(None, |m: Option<f64>, v| Some(m.map_or(v, |m| m.max(v))));
                (
                    settling_time(samples, b0, end, ATTITUDE_SETTLED, |x| x.attitude_error),
                    max,
                )
            }
            None => (None, None),
        };
        let max_e_f = samples.iter().filter_map(|x| x.e_f.map(|e| (e, x.t))).fold(
            None,
            |m: Option<(f64, f64)>, (e, t)| match m {
                Some((me, _)) if me >= e => m,
                _ => Some((e, t)),
            },
        );
        let mut v_x_at: Vec<(f64, f64)> = [0.0, 2.0, 4.0, 8.0, 12.0, 14.0]
            .iter()
            .filter(|&&t| t < scenario.duration)
            .filter_map(|&t| sample_at(samples, t).and_then(|x| x.v_x.map(|v| (x.t, v))))
            .collect();
        if let Some((t, v)) = samples.last().and_then(|x| x.v_x.map(|v| (x.t, v))) {
            v_x_at.push((t, v));
        }
        Self {
            horizontal_error_at_4s: horizontal(4.0),
            horizontal_error_at_12s: horizontal(12.0),
            max_planned_roll: samples
                .iter()
                .filter_map(|x| x.planned_roll.map(f64::abs))
                .fold(None, |m: Option<f64>, v| Some(m.map_or(v, |m| m.max(v)))),
            stage_b_attitude_settling: settling,
            stage_b_max_attitude_error: max_err,
            max_e_f,
            e_f_onset: samples
                .iter()
                .find(|x| x.e_f.is_some_and(|e| e > E_F_VISIBLE))
                .map(|x| x.t),
            max_position_error_6_to_12s: samples
                .iter()
                .filter(|x| x.t >= 6.0 - 1e-9 && x.t <= 12.0 + 1e-9)
                .map(Sample::position_error)
                .fold(None, |m: Option<f64>, v| Some(m.map_or(v, |m| m.max(v)))),
            v_x_at,
            max_v_x_after_4s: samples
                .iter()
                .filter(|x| x.t >= 4.0 - 1e-9)
                .filter_map(|x| x.v_x)
                .fold(None, |m: Option<f64>, v| Some(m.map_or(v, |m| m.max(v)))),
            max_v_x_rise: max_rise(samples),
        }
    }
}
