//! Agent failures and the response to a hover-capability loss.

use serde::{Deserialize, Serialize};
use tvmd_plant::actuators::FailureKind;

/// An agent failure.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Failure {
    /// Agent index (0-based).
    pub agent: usize,
    /// Failure time (s).
    pub time: f64,
    /// What fails.
    pub kind: FailureKind,
    /// Whether the controller is told (through the `failed` flags); default true.
    #[serde(default = "default_true")]
    pub controller_informed: bool,
    /// How long after the failure an informed controller is told (s, at least 0; default 0):
    /// the latency of whatever reports it (an agent's own telemetry over the team's network,
    /// a detector). Until then the controller flies the failed agent as working.
    #[serde(default)]
    pub informed_after: f64,
}

fn default_true() -> bool {
    true
}

/// What the controller does when an accepted failure mask leaves a team that cannot hold hover
/// with a margin ([`tvmd_core::Controller::set_failures`]'s classification).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum OnHoverLoss {
    /// Keep flying the scenario's reference (the default; the classification is only logged).
    #[default]
    Continue,
    /// Replace the reference by a level descent at the current `x`, `y` to the rest height
    /// `z = 0` at the downward acceleration `landing_acceleration`, then idle the rotors.
    Land,
}

/// The scenario's response to a hover-capability loss (`[failure_response]`).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct FailureResponse {
    /// `"continue"` (default) or `"land"`.
    pub on_hover_loss: OnHoverLoss,
    /// Downward acceleration of the landing reference (m/s^2); 1.0. The reference falls from
    /// where the loss was classified to `z = 0` (asking the agents for `m_C (g - a)`, which
    /// leaves a margin of about `a / g` for the attitude), touching down at `sqrt(2 a z_0)`
    /// (1.7 m/s from 1.5 m). Measured on `agent-failure` (A4-Inc minus one), largest tilt
    /// after the failure in f64 / f32: 0.5 m/s^2: 0.000 / 0.000 rad; 1.0: 0.000 / 0.017;
    /// 1.5: 0.001 / 0.027; 2.5: 0.000 / 0.001.
    pub landing_acceleration: f64,
}

impl Default for FailureResponse {
    fn default() -> Self {
        Self {
            on_hover_loss: OnHoverLoss::Continue,
            landing_acceleration: 1.0,
        }
    }
}
