//! Per-agent command links (`[links]`): each agent receives its commands over a link of its own
//! (in the paper's experiment WiFi to each agent's ESP32; in the authors' PX4 fork I2C to each
//! module's controller) that delays, jitters and drops them, and an agent whose link falls
//! silent holds its last command for a while, then fails safe.

use serde::{Deserialize, Serialize};

use crate::error::{invalid, ScenarioError};

/// What an agent does once its link has been silent for [`CommandLinks::hold`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum LinkFailsafe {
    /// Rotor stopped, gimbal level (an ESC's and a servo's usual failsafe; the default).
    #[default]
    Idle,
    /// Keeps its last command for as long as the link is silent.
    Hold,
}

/// The largest [`CommandLinks::latency`] and [`CommandLinks::jitter`] (s).
pub const MAX_LINK_DELAY: f64 = 1.0;

/// Every agent's command link; each agent draws its own delays and losses.
///
/// A command sent at a controller tick `t` arrives at `t + latency + U(0, jitter)` unless it is
/// lost: each command independently with probability `loss`, and in bursts (Gilbert's model: a
/// burst begins before a command with probability `burst_start` and drops a geometric number of
/// commands of mean `burst_length`). An agent applies an arriving command unless it has applied
/// a newer one (a late packet overtaken by the next is dropped). After `hold` seconds without
/// an arrival it fails safe ([`LinkFailsafe`]); the next arrival ends that.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct CommandLinks {
    /// Fixed delay of every command (s), in `[0, MAX_LINK_DELAY]`.
    pub latency: f64,
    /// Extra delay, uniform in `[0, jitter]` (s), in `[0, MAX_LINK_DELAY]`.
    pub jitter: f64,
    /// Probability that a command is lost on its own, in `[0, 1)`.
    pub loss: f64,
    /// Probability that a burst of losses begins before a command, in `[0, 1)`.
    pub burst_start: f64,
    /// Mean commands a burst drops (at least 1).
    pub burst_length: f64,
    /// How long an agent holds its last command without an arrival before it fails safe (s,
    /// positive).
    pub hold: f64,
    /// What it does then.
    pub failsafe: LinkFailsafe,
    /// Seed of the links' random generator (ChaCha8; its own stream: the state noise's draws
    /// are the same with links or without).
    pub seed: u64,
}

impl Default for CommandLinks {
    /// An ideal link (every command applied at the physics step it is sent) whose agent holds
    /// for 0.1 s, then idles: what a `link-loss` failure uses when `[links]` is absent.
    fn default() -> Self {
        Self {
            latency: 0.0,
            jitter: 0.0,
            loss: 0.0,
            burst_start: 0.0,
            burst_length: 1.0,
            hold: 0.1,
            failsafe: LinkFailsafe::Idle,
            seed: 1,
        }
    }
}

impl CommandLinks {
    /// Checks every field, naming it (`links.<field>`).
    pub fn validate(&self) -> Result<(), ScenarioError> {
        let in_range = |field: &str, v: f64, lo: f64, hi: f64, closed: bool| {
            let ok = v.is_finite() && v >= lo && if closed { v <= hi } else { v < hi };
            if ok {
                Ok(())
            } else {
                let upper = if closed { "]" } else { ")" };
                Err(invalid(
                    format!("links.{field}"),
                    format!("must be in [{lo}, {hi}{upper}, got {v}"),
                ))
            }
        };
        in_range("latency", self.latency, 0.0, MAX_LINK_DELAY, true)?;
        in_range("jitter", self.jitter, 0.0, MAX_LINK_DELAY, true)?;
        in_range("loss", self.loss, 0.0, 1.0, false)?;
        in_range("burst_start", self.burst_start, 0.0, 1.0, false)?;
        if !(self.burst_length.is_finite() && self.burst_length >= 1.0) {
            return Err(invalid(
                "links.burst_length",
                format!("must be at least 1 command, got {}", self.burst_length),
            ));
        }
        if !(self.hold.is_finite() && self.hold > 0.0) {
            return Err(invalid(
                "links.hold",
                format!("must be positive and finite (s), got {}", self.hold),
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use crate::Scenario;

    #[test]
    fn links_parse_and_bad_values_name_the_field() {
        let s = Scenario::from_toml_str(
            "[links]\nlatency = 0.02\njitter = 0.005\nloss = 0.1\nfailsafe = \"hold\"\n",
        )
        .unwrap();
        let l = s.links.unwrap();
        assert_eq!((l.latency, l.jitter, l.loss), (0.02, 0.005, 0.1));
        assert_eq!(l.failsafe, super::LinkFailsafe::Hold);
        assert_eq!(l.hold, 0.1);
        assert!(Scenario::default().links.is_none());
        for (toml, field) in [
            ("latency = -0.01", "links.latency"),
            ("latency = 2.0", "links.latency"),
            ("jitter = nan", "links.jitter"),
            ("loss = 1.0", "links.loss"),
            ("burst_start = -0.5", "links.burst_start"),
            ("burst_length = 0.5", "links.burst_length"),
            ("hold = 0.0", "links.hold"),
            ("hold = inf", "links.hold"),
        ] {
            let e = Scenario::from_toml_str(&format!("[links]\n{toml}\n")).unwrap_err();
            assert!(e.to_string().contains(field), "{toml}: {e}");
        }
        assert!(Scenario::from_toml_str("[links]\nfailsafe = \"explode\"\n").is_err());
        assert!(Scenario::from_toml_str("[links]\nlatencyy = 0.1\n").is_err());
    }

    #[test]
    fn a_link_loss_is_a_failure_kind() {
        let s = Scenario::from_toml_str(
            "[[failures]]\nagent = 1\ntime = 2.0\nkind = \"link-loss\"\ncontroller_informed = false\n",
        )
        .unwrap();
        assert_eq!(
            s.failures[0].kind,
            tvmd_plant::actuators::FailureKind::LinkLoss
        );
    }
}
