//! The fault study's "first effect on a report" (`fault_reports.rs`): the first report of a
//! failed agent that differs from the one it would have sent had it not failed
//! (`Simulation::healthy_reports`: its actuators' healthy twin given the same commands, measured
//! with the same noise draws, so the difference is the failure's effect alone) by more than the
//! report's noise can explain, or that the failure stopped.

use tvmd_scenario::AgentReports;
use tvmd_sim::AgentReport;

/// The thresholds (noise standard deviations of the report) past which a report differs from
/// the one the agent would have sent had it not failed: the first is the table's "first effect",
/// the others show how much that choice moves the delays.
pub const EFFECT_SIGMAS: [f64; 3] = [3.0, 1.0, 10.0];

/// The failed agent's first reports that the failure changed ([`EffectWatch`]).
#[derive(Clone, Copy, Debug, Default)]
pub struct FirstEffect {
    /// Per [`EFFECT_SIGMAS`], when the first report that differs by more was measured (s).
    pub at: [Option<f64>; 3],
    /// The largest effect on a reported angle (rad) over the reports measured within 50 ms of
    /// the first effect: what a check had to see to name the agent in time.
    pub largest: Option<f64>,
    /// The share of the reports measured within 0.5 s of the first effect whose two angles lay
    /// within the commands sent 20 ms either side of their measurement (where a check that
    /// admits any angle between the commands cannot see the failure, whatever its tolerance).
    pub inside: Option<f64>,
    /// The largest error (rad) of the report check's own servo model (a first-order lag of 50
    /// ms turning at most at 6 rad/s, `ReportCheck::recommended`, stepped on the commands sent
    /// from 0.1 s before the fault) against the reports the agent would have sent healthy,
    /// and against the stuck ones, within 0.5 s of the first effect: how well a check that
    /// tracked its model, rather than an envelope, could tell them apart.
    pub model: Option<[f64; 2]>,
    /// When a check of the reports against that model at their measurement, tolerance
    /// [`MODEL_TOLERANCE`] and two reports in a row, would have named the stuck gimbal (s after
    /// the first effect, the 20 ms latency included; within 0.5 s of it).
    pub model_named: Option<f64>,
}

/// The tolerance (rad) of the hypothetical check against the model ([`FirstEffect::model_named`]).
pub const MODEL_TOLERANCE: f64 = 0.1;

/// Watches one agent's reports against the ones it would have sent had it not failed
/// (`Simulation::healthy_reports`: the same noise, so the difference is the failure's effect).
/// A report that the failure stops (a silent ESC, a lost link) is an effect of any size,
/// measured when the missing report would have been.
pub struct EffectWatch {
    t_f: f64,
    spec: AgentReports,
    last: Option<f64>,
    effect: FirstEffect,
    /// `(measured, the angles' effect (rad), eta_x, eta_y)` of the reports after the fault.
    angles: Vec<(f64, f64, f64, f64)>,
    /// `(t, eta_x, eta_y)` of the commands sent from 0.1 s before the fault on.
    commands: Vec<(f64, f64, f64)>,
    /// `(measured, eta_x, eta_y)` of the healthy reports from 0.1 s before the fault on.
    healthy: Vec<(f64, f64, f64)>,
}

impl EffectWatch {
    /// Watches an agent failed at `t_f` whose reports are `spec`.
    pub fn new(t_f: f64, spec: AgentReports) -> Self {
        Self {
            t_f,
            spec,
            last: None,
            effect: FirstEffect::default(),
            angles: Vec::new(),
            commands: Vec::new(),
            healthy: Vec::new(),
        }
    }

    /// The command sent at the tick `t`.
    pub fn command(&mut self, t: f64, eta_x: f64, eta_y: f64) {
        if t >= self.t_f - 0.1 {
            self.commands.push((t, eta_x, eta_y));
        }
    }

    /// One tick at `t`: the agent's newest report and the one it would have sent healthy.
    pub fn see(&mut self, t: f64, report: Option<AgentReport>, healthy: Option<AgentReport>) {
        let period = 1.0 / self.spec.rate;
        let mark = |at: &mut [Option<f64>; 3], m: f64, sigmas: f64| {
            for (slot, k) in at.iter_mut().zip(EFFECT_SIGMAS) {
                if slot.is_none() && sigmas > k {
                    *slot = Some(m);
                }
            }
        };
        let missing = self.last.map(|m| m + period);
        if t >= self.t_f && missing.is_some_and(|m| t - m > self.spec.latency + 0.5 * period) {
            mark(&mut self.effect.at, missing.unwrap_or(t), f64::INFINITY);
        }
        let (Some(r), Some(h)) = (report, healthy) else {
            return;
        };
        let m = t - r.age;
        if self.last.is_some_and(|l| m <= l + 1e-9) {
            return;
        }
        self.last = Some(m);
        let angle = (r.eta_x - h.eta_x).abs().max((r.eta_y - h.eta_y).abs());
        let sigmas = ((r.thrust - h.thrust).abs() / self.spec.thrust_noise)
            .max(angle / self.spec.angle_noise);
        if m >= self.t_f - 0.1 {
            self.healthy.push((m, h.eta_x, h.eta_y));
        }
        if m >= self.t_f - 1e-9 {
            mark(&mut self.effect.at, m, sigmas);
            self.angles.push((m, angle, r.eta_x, r.eta_y));
        }
    }

    /// The first effects seen.
    pub fn finish(mut self) -> FirstEffect {
        let Some(first) = self.effect.at[0] else {
            return self.effect;
        };
        let within = |a: &&(f64, f64, f64, f64), span: f64| {
            a.0 >= first - 1e-9 && a.0 <= first + span + 1e-9
        };
        self.effect.largest = self
            .angles
            .iter()
            .filter(|a| within(a, 0.05))
            .map(|a| a.1)
            .reduce(f64::max);
        let late: Vec<_> = self.angles.iter().filter(|a| within(a, 0.5)).collect();
        let inside = late.iter().filter(|a| {
            let sent: Vec<_> = self
                .commands
                .iter()
                .filter(|c| (c.0 - a.0).abs() <= 0.02 + 1e-9)
                .collect();
            let spans = |v: f64, axis: fn(&&(f64, f64, f64)) -> f64| {
                let lo = sent.iter().map(axis).fold(f64::INFINITY, f64::min);
                let hi = sent.iter().map(axis).fold(f64::NEG_INFINITY, f64::max);
                lo <= v && v <= hi
            };
            spans(a.2, |c| c.1) && spans(a.3, |c| c.2)
        });
        if !late.is_empty() {
            self.effect.inside = Some(inside.count() as f64 / late.len() as f64);
        }
        self.effect.model = self.model_errors(first);
        self.effect
    }

    /// The model's predictions `(t, [eta_x, eta_y])` from the first healthy report on.
    fn predictions(&self) -> Vec<(f64, [f64; 2])> {
        let period = 0.01;
        let (gain, step) = (1.0 - (-period / 0.05_f64).exp(), 6.0 * period);
        let Some(&(m0, x0, y0)) = self.healthy.first() else {
            return Vec::new();
        };
        let mut model = [x0, y0];
        let mut predicted = Vec::new();
        for &(t, x, y) in self.commands.iter().filter(|c| c.0 >= m0 - 1e-9) {
            for (m, c) in model.iter_mut().zip([x, y]) {
                *m += ((c - *m) * gain).clamp(-step, step);
            }
            predicted.push((t + period, model));
        }
        predicted
    }

    /// [`FirstEffect::model`] and [`FirstEffect::model_named`].
    fn model_errors(&mut self, first: f64) -> Option<[f64; 2]> {
        let predicted = self.predictions();
        let error = |m: f64, x: f64, y: f64| {
            let p = predicted.iter().find(|p| (p.0 - m).abs() < 1e-6)?.1;
            Some((x - p[0]).abs().max((y - p[1]).abs()))
        };
        let within = |m: f64| m >= first - 1e-9 && m <= first + 0.5 + 1e-9;
        let healthy = self
            .healthy
            .iter()
            .filter(|h| within(h.0))
            .filter_map(|h| error(h.0, h.1, h.2))
            .reduce(f64::max)?;
        let stuck: Vec<(f64, f64)> = self
            .angles
            .iter()
            .filter(|a| within(a.0))
            .filter_map(|a| Some((a.0, error(a.0, a.2, a.3)?)))
            .collect();
        self.effect.model_named = stuck
            .windows(2)
            .find(|w| w.iter().all(|e| e.1 > MODEL_TOLERANCE))
            .map(|w| w[1].0 + self.spec.latency - first);
        let stuck = stuck.iter().map(|e| e.1).reduce(f64::max)?;
        Some([healthy, stuck])
    }
}
