//! The verdict of a run against its scenario's `[success]` bounds (`docs/method.md`, "Flight
//! metrics").

use serde::{Deserialize, Serialize};
use tvmd_scenario::SuccessBounds;

use super::RunSummary;

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
            // To the planned attitude while the controller ran in the window; to the reference
            // when it did not (disarmed on the ground).
            m.planned_attitude
                .and_then(|a| a.steady_state)
                .or(m.attitude.and_then(|a| a.steady_state)),
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
