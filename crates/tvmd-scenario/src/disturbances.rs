//! Optional disturbances: wind, an external wrench, state noise, feedback latency.

use serde::{Deserialize, Serialize};

use crate::Air;

/// A constant external wrench over a time window.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExternalWrenchSpec {
    /// Force through the centre of mass, world frame (N).
    #[serde(default)]
    pub force: [f64; 3],
    /// Torque, body frame (N m).
    #[serde(default)]
    pub torque: [f64; 3],
    /// Start time (s); 0.
    #[serde(default)]
    pub start: f64,
    /// End time (s); none = until the end.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub end: Option<f64>,
}

impl ExternalWrenchSpec {
    /// True if the wrench acts at time `t`.
    pub fn active(&self, t: f64) -> bool {
        t >= self.start && self.end.is_none_or(|e| t < e)
    }
}

/// Gaussian noise on the state fed back to the controller (standard deviations).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct StateNoise {
    /// Position noise per axis (m).
    pub position: f64,
    /// World-frame velocity noise per axis (m/s).
    pub velocity: f64,
    /// Attitude noise: rotation vector per axis (rad), applied as `R exp([n]x)`.
    pub attitude: f64,
    /// Body angular-velocity noise per axis (rad/s).
    pub angular_velocity: f64,
    /// Seed of the random generator (ChaCha8).
    pub seed: u64,
}

impl Default for StateNoise {
    fn default() -> Self {
        Self {
            position: 0.0,
            velocity: 0.0,
            attitude: 0.0,
            angular_velocity: 0.0,
            seed: 1,
        }
    }
}

/// Optional disturbances.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Disturbances {
    /// Constant force through the centre of mass, world frame (N): wind as a force, with no
    /// drag model (see `air` for wind as air velocity).
    pub wind: [f64; 3],
    /// Wind as air velocity (steady plus gusts) through the team's drag.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub air: Option<Air>,
    /// External wrench.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub external_wrench: Option<ExternalWrenchSpec>,
    /// Noise on the fed-back state.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub state_noise: Option<StateNoise>,
    /// Feedback latency in whole controller periods (0 to [`MAX_FEEDBACK_LATENCY`]): the
    /// controller's tick at `t` is given the (noisy) state of `t - latency * period` (the state
    /// at `t = 0` until then), as an estimator and a link that lag by that much would give it.
    #[serde(skip_serializing_if = "is_zero")]
    pub feedback_latency: u32,
}

/// The largest [`Disturbances::feedback_latency`] (controller periods).
pub const MAX_FEEDBACK_LATENCY: u32 = 1000;

fn is_zero(v: &u32) -> bool {
    *v == 0
}
