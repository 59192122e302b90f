//! [`SummaryFold`]: the summary and the paper metrics of a run, folded over its samples one at
//! a time, so that a run is summarised in constant memory whatever its length (the loop folds
//! every tick whether or not it keeps the samples).

use super::metrics::MetricsFold;
use super::rules::{ArgMax, Max, MaxRise, Min, Nearest, Settling, Spacing};
use super::{
    e_f_visible, FaultSummary, HoverClassification, NullSpaceSummary, PaperMetrics, RunSummary,
    RunTotals, ATTITUDE_SETTLED, SETTLING_TIME,
};
use tvmd_plant::math::roll_pitch_yaw;
use tvmd_plant::reference::ReferenceConfig;
use tvmd_scenario::Scenario;

use super::Verdict;
use crate::sim::sample::{arr, Sample};

/// The times at which [`PaperMetrics::v_x_at`] reads `V_x` (before the final sample) (s).
const V_X_TIMES: [f64; 6] = [0.0, 2.0, 4.0, 8.0, 12.0, 14.0];
/// Index of 4 s and 12 s in [`V_X_TIMES`] (the horizontal errors' times).
const AT_4S: usize = 2;
const AT_12S: usize = 4;

/// What [`Nearest`] keeps of a sample: its horizontal error and `V_x`.
type AtTime = Nearest<(f64, Option<f64>)>;

/// What the summary reads from the last sample.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Last {
    t: f64,
    position_error: f64,
    /// `(t, V_x)` of the law's last period.
    v_x: Option<(f64, f64)>,
    v_r: Option<f64>,
}

/// The null-space stage's margins so far.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Margins {
    periods: usize,
    raised: usize,
    sum: [f64; 2],
    min: [f64; 2],
}

impl Margins {
    fn push(&mut self, [before, after]: [f64; 2]) {
        if self.periods == 0 {
            self.min = [f64::INFINITY; 2];
        }
        self.periods += 1;
        self.raised += usize::from(after > before);
        self.sum[0] += before;
        self.sum[1] += after;
        self.min = [self.min[0].min(before), self.min[1].min(after)];
    }

    fn get(&self) -> Option<NullSpaceSummary> {
        let n = self.periods as f64;
        (self.periods > 0).then(|| NullSpaceSummary {
            periods: self.periods,
            raised_periods: self.raised,
            mean_margin_before: self.sum[0] / n,
            mean_margin_after: self.sum[1] / n,
            min_margin_before: self.min[0],
            min_margin_after: self.min[1],
        })
    }
}

/// The running summary of a run of one scenario: [`SummaryFold::push`] each sample in time
/// order, then read [`SummaryFold::summary`] and [`SummaryFold::paper`] at any point.
#[derive(Clone, Debug)]
pub struct SummaryFold {
    /// Tilt window `[b0, b1]` of a paper-tilt reference with a roll.
    tilt: Option<[f64; 2]>,
    duration: f64,
    e_f_visible: f64,
    spacing: Spacing,
    at: [AtTime; V_X_TIMES.len()],
    last: Option<Last>,
    max_position_error: Max,
    max_position_error_after_4s: Max,
    max_position_error_6_to_12s: Max,
    max_tilt: Max,
    max_roll: Max,
    max_planned_roll: Max,
    max_e_f: ArgMax,
    e_f_onset: Option<f64>,
    min_thrust: Min,
    max_thrust: Max,
    max_abs_eta: [Max; 2],
    saturated_periods: usize,
    cycle_errors: usize,
    margins: Margins,
    hover: Vec<HoverClassification>,
    fault: Option<FaultSummary>,
    stage_b_settling: Option<Settling>,
    stage_b_max_attitude_error: Max,
    max_v_x_after_4s: Max,
    max_v_x_rise: MaxRise,
    metrics: MetricsFold,
}

impl SummaryFold {
    /// An empty fold for runs of `scenario` (its tilt window, duration and `e_f` threshold).
    pub fn new(scenario: &Scenario) -> Self {
        let tilt = match &scenario.reference {
            ReferenceConfig::PaperTilt(p) if p.tilt[1] > p.tilt[0] && p.roll_peak != 0.0 => {
                Some(p.tilt)
            }
            _ => None,
        };
        let weight = scenario
            .team_body()
            .map_or(0.0, |b| b.mass() * scenario.physics.gravity);
        Self {
            tilt,
            duration: scenario.duration,
            e_f_visible: e_f_visible(scenario.controller_precision, weight),
            spacing: Spacing::default(),
            at: V_X_TIMES.map(Nearest::new),
            last: None,
            max_position_error: Max::default(),
            max_position_error_after_4s: Max::default(),
            max_position_error_6_to_12s: Max::default(),
            max_tilt: Max::default(),
            max_roll: Max::default(),
            max_planned_roll: Max::default(),
            max_e_f: ArgMax::default(),
            e_f_onset: None,
            min_thrust: Min::default(),
            max_thrust: Max::default(),
            max_abs_eta: [Max::default(); 2],
            saturated_periods: 0,
            cycle_errors: 0,
            margins: Margins::default(),
            hover: Vec::new(),
            fault: None,
            stage_b_settling: tilt
                .map(|[b0, b1]| Settling::new(b0, b0 + 0.75 * (b1 - b0), ATTITUDE_SETTLED)),
            stage_b_max_attitude_error: Max::default(),
            max_v_x_after_4s: Max::default(),
            max_v_x_rise: MaxRise::default(),
            metrics: MetricsFold::new(
                scenario.controller_period,
                scenario.duration - scenario.success.steady_state_window,
            ),
        }
    }

    /// The fold of `samples` (in time order).
    pub fn over(scenario: &Scenario, samples: &[Sample]) -> Self {
        let mut fold = Self::new(scenario);
        samples.iter().for_each(|x| fold.push(x));
        fold
    }

    /// Adds the next sample.
    pub fn push(&mut self, x: &Sample) {
        let t = x.t;
        let error = x.position_error();
        self.metrics.push(x);
        self.spacing.push(t);
        let at = (x.horizontal_error(), x.v_x);
        self.at.iter_mut().for_each(|n| n.push(t, at));
        self.max_position_error.push(error);
        if t >= SETTLING_TIME - 1e-9 {
            self.max_position_error_after_4s.push(error);
            self.max_v_x_after_4s.push_some(x.v_x);
        }
        if (6.0 - 1e-9..=12.0 + 1e-9).contains(&t) {
            self.max_position_error_6_to_12s.push(error);
        }
        let [roll, pitch, _] = x.roll_pitch_yaw;
        self.max_tilt
            .push((roll.cos() * pitch.cos()).clamp(-1.0, 1.0).acos());
        self.max_roll.push(roll.abs());
        self.max_planned_roll
            .push_some(x.planned_roll.map(f64::abs));
        if let Some(e) = x.e_f {
            self.max_e_f.push(t, e);
            if e > self.e_f_visible && self.e_f_onset.is_none() {
                self.e_f_onset = Some(t);
            }
        }
        for (c, failed) in x.commands.iter().zip(&x.failed) {
            if !failed {
                self.min_thrust.push(c.thrust);
                self.max_thrust.push(c.thrust);
            }
        }
        for c in &x.commands {
            self.max_abs_eta[0].push(c.eta_x.abs());
            self.max_abs_eta[1].push(c.eta_y.abs());
        }
        self.saturated_periods += usize::from(x.saturated_agents.is_some_and(|n| n > 0));
        self.cycle_errors += usize::from(x.cycle_error);
        if let Some(m) = x.null_space_margins {
            self.margins.push(m);
        }
        if let Some(h) = &x.hover {
            self.hover.push(HoverClassification {
                time: t,
                capable: h.capable,
                margin: h.margin,
                landing: h.landing,
                refused: h.refused.clone(),
            });
        }
        if let Some(f) = &x.fault {
            self.fault
                .get_or_insert_with(FaultSummary::default)
                .push(t, f);
        }
        if let Some([b0, b1]) = self.tilt {
            if t >= b0 && t <= b1 {
                self.stage_b_max_attitude_error.push_some(x.attitude_error);
            }
        }
        if let Some(s) = self.stage_b_settling.as_mut() {
            s.push(t, x.attitude_error);
        }
        if let Some(v) = x.v_x {
            self.max_v_x_rise.push(t, v);
        }
        // The Lyapunov values of the law's last period: a disarmed team (on the ground after a
        // landing) reports none, and keeps the last ones with their time.
        let (v_x, v_r) = match (x.v_x, x.v_r, self.last) {
            (None, None, Some(previous)) => (previous.v_x, previous.v_r),
            (v_x, v_r, _) => (v_x.map(|v| (t, v)), v_r),
        };
        self.last = Some(Last {
            t,
            position_error: error,
            v_x,
            v_r,
        });
    }

    /// Horizontal error at the sample at [`V_X_TIMES`]`[k]`.
    fn horizontal_error_at(&self, k: usize) -> Option<f64> {
        self.at[k].get(&self.spacing).map(|(_, (h, _))| h)
    }

    /// The summary of the samples so far, with the final state and counters of `totals`.
    pub fn summary(&self, scenario: &Scenario, totals: &RunTotals) -> RunSummary {
        let s = &totals.final_state;
        let weight = totals.mass * scenario.physics.gravity;
        let e_f = self.max_e_f.get();
        let last = self.last;
        let mut summary = RunSummary {
            scenario: scenario.name.clone(),
            controller_precision: scenario.controller_precision,
            controller_target: crate::flight::HOST_TARGET.to_string(),
            time: totals.time,
            interrupted: totals.interrupted,
            error: None,
            final_position: arr(&s.position),
            final_velocity: arr(&s.velocity),
            final_omega: arr(&s.omega),
            final_roll_pitch_yaw: roll_pitch_yaw(&s.rotation),
            max_position_error: self.max_position_error.or_zero(),
            max_position_error_after_4s: self.max_position_error_after_4s.or_zero(),
            final_position_error: last.map_or(0.0, |x| x.position_error),
            horizontal_error_at_4s: self.horizontal_error_at(AT_4S),
            horizontal_error_at_12s: self.horizontal_error_at(AT_12S),
            max_tilt: self.max_tilt.or_zero(),
            max_roll: self.max_roll.or_zero(),
            max_planned_roll: self.max_planned_roll.get(),
            max_e_f: e_f.map(|(_, e)| e),
            max_e_f_time: e_f.map(|(t, _)| t),
            max_e_f_over_weight: e_f.map(|(_, e)| e / weight),
            final_v_x: last.and_then(|x| x.v_x).map(|(_, v)| v),
            final_v_r: last.and_then(|x| x.v_r),
            min_thrust: self.min_thrust.get(),
            max_thrust: self.max_thrust.get(),
            max_abs_eta_x: self.max_abs_eta[0].or_zero(),
            max_abs_eta_y: self.max_abs_eta[1].or_zero(),
            saturated_periods: self.saturated_periods,
            cycle_errors: self.cycle_errors,
            null_space: self.margins.get(),
            hover_classifications: self.hover.clone(),
            fault: self.fault,
            controller_calls: totals.controller_calls,
            physics_steps: totals.physics_steps,
            wall_time: totals.wall_time,
            real_time_factor: if totals.wall_time > 0.0 {
                totals.time / totals.wall_time
            } else {
                f64::INFINITY
            },
            metrics: self.metrics.get(),
            verdict: Verdict::default(),
        };
        summary.verdict = Verdict::judge(&summary, &scenario.success);
        summary
    }

    /// The paper's metrics of the samples so far.
    pub fn paper(&self) -> PaperMetrics {
        let mut v_x_at: Vec<(f64, f64)> = V_X_TIMES
            .iter()
            .zip(&self.at)
            .filter(|(&t, _)| t < self.duration)
            .filter_map(|(_, n)| {
                let (t, (_, v)) = n.get(&self.spacing)?;
                v.map(|v| (t, v))
            })
            .collect();
        if let Some((t, v)) = self.last.and_then(|x| x.v_x) {
            v_x_at.push((t, v));
        }
        PaperMetrics {
            horizontal_error_at_4s: self.horizontal_error_at(AT_4S),
            horizontal_error_at_12s: self.horizontal_error_at(AT_12S),
            max_planned_roll: self.max_planned_roll.get(),
            stage_b_attitude_settling: self.stage_b_settling.and_then(|s| s.get()),
            stage_b_max_attitude_error: self.stage_b_max_attitude_error.get(),
            max_e_f: self.max_e_f.get().map(|(t, e)| (e, t)),
            e_f_onset: self.e_f_onset,
            e_f_visible: self.e_f_visible,
            max_position_error_6_to_12s: self.max_position_error_6_to_12s.get(),
            v_x_at,
            max_v_x_after_4s: self.max_v_x_after_4s.get(),
            max_v_x_rise: self.max_v_x_rise.get(),
        }
    }
}
