//! `[success]`: the bounds a flight must meet to count as a success (the verdict of a run
//! against them is `tvmd_sim::Verdict`) (`docs/method.md`, "Flight metrics").

use serde::{Deserialize, Serialize};

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
