//! `[success]`: the bounds a flight must meet to count as a success, and the [`Verdict`] of a
//! run against them (`docs/method.md`, "Flight metrics").

use serde::{Deserialize, Serialize};

use crate::sim::RunSummary;

/// The bounds of a successful flight; the verdict fails on any bound missed.
///
/// ```toml
/// [success]
/// steady_state_window = 1.0
/// max_steady_state_position_error = 0.05
/// max_steady_state_attitude_error = 0.05
/// max_position_error = 1.0
/// # max_settling_time = 6.0
/// max_cycle_errors = 0
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SuccessBounds {
    /// The final part of the flight over which steady-state errors are averaged (s); 1. A
    /// window longer than the flight averages the whole flight.
    pub steady_state_window: f64,
    /// Largest steady-state position error `||x - x_r||` (m); 0.05.
    pub max_steady_state_position_error: f64,
    /// Largest steady-state error to the planned attitude `angle(R, R_d)` (rad); 0.05. The
    /// planned attitude, not `R_r`: an infeasible reference is given up on purpose.
    pub max_steady_state_attitude_error: f64,
    /// Largest position error at any time (m); 1: the team stayed near its reference.
    pub max_position_error: f64,
    /// Largest 2% settling time of the position error (s); none by default (a tracking
    /// reference need not settle, a step does).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_settling_time: Option<f64>,
    /// Largest number of controller periods the controller skipped; 0.
    pub max_cycle_errors: usize,
}

impl Default for SuccessBounds {
    fn default() -> Self {
        Self {
            steady_state_window: 1.0,
            max_steady_state_position_error: 0.05,
            max_steady_state_attitude_error: 0.05,
            max_position_error: 1.0,
            max_settling_time: None,
            max_cycle_errors: 0,
        }
    }
}

/// The verdict of a run against its scenario's [`SuccessBounds`].
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Verdict {
    /// Every bound met and the flight reached the scenario's end.
    pub success: bool,
    /// One line per bound missed (empty on success).
    pub failures: Vec<String>,
}

impl Verdict {
    /// Judges `summary` (its flight metrics, counters and end) against `bounds`.
    pub fn judge(summary: &RunSummary, bounds: &SuccessBounds) -> Self {
        let mut failures = Vec::new();
        if let Some(e) = &summary.error {
            failures.push(format!("the flight ended early: {e}"));
        }
        if summary.interrupted {
            failures.push(format!("interrupted at {} s", summary.time));
        }
        let m = &summary.metrics;
        let mut within = |what: &str, value: Option<f64>, bound: f64, unit: &str| match value {
            Some(v) if v.is_nan() || v > bound => {
                failures.push(format!("{what} {v:.4} {unit} above {bound} {unit}"));
            }
            Some(_) => {}
            None => failures.push(format!("no {what} (the run has no samples for it)")),
        };
        let position = m.position.as_ref();
        within(
            "steady-state position error",
            position.and_then(|p| p.steady_state),
            bounds.max_steady_state_position_error,
            "m",
        );
        within(
            "steady-state attitude error",
            m.planned_attitude
                .or(m.attitude)
                .and_then(|a| a.steady_state),
            bounds.max_steady_state_attitude_error,
            "rad",
        );
        within(
            "peak position error",
            position.map(|p| p.peak),
            bounds.max_position_error,
            "m",
        );
        if let Some(bound) = bounds.max_settling_time {
            match position.map(|p| p.settling_time) {
                Some(None) => failures.push("the position error did not settle".into()),
                settling => within("position settling time", settling.flatten(), bound, "s"),
            }
        }
        if summary.cycle_errors > bounds.max_cycle_errors {
            failures.push(format!(
                "{} skipped controller periods, above {}",
                summary.cycle_errors, bounds.max_cycle_errors
            ));
        }
        Self {
            success: failures.is_empty(),
            failures,
        }
    }
}
