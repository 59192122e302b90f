//! The agents' own reports (`[reports]`): each agent measures its rotor speed (given as the
//! thrust that speed makes) and its gimbal angles at a rate, and sends them back over its link
//! with a latency, noise and losses, as PX4 reads ESC telemetry (`esc_status`) and servo
//! feedback.

use serde::{Deserialize, Serialize};

use crate::error::{invalid, ScenarioError};

/// What a dead ESC (a `no-thrust` failure) reports.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum DeadEsc {
    /// Nothing: the agent's reports stop (the default).
    #[default]
    Silent,
    /// Zero rotor speed, with the servos' angles.
    Zero,
}

/// The agents' reports.
///
/// A report measures at its sample time the agent's rotor speed, as the thrust `k omega^2` it
/// makes with an intact propeller, and its servos' angles, each with Gaussian noise; it arrives
/// `latency` later unless lost. What a faulty agent reports: a dead ESC as [`DeadEsc`] says, a
/// damaged propeller (`half-thrust`) the speed it spins at (its full commanded thrust: the
/// loss is invisible to the ESC), a stuck servo its stuck angle, a silent link (`link-loss`)
/// nothing. An agent listed in `lying` reports the command it received, whatever it does.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct AgentReports {
    /// Reports per second, in `(0, 1 / physics.dt]` (sampled at the physics steps).
    pub rate: f64,
    /// Delay from measurement to arrival (s), in `[0, 1]`.
    pub latency: f64,
    /// Standard deviation of the reported thrust (N).
    pub thrust_noise: f64,
    /// Standard deviation of each reported gimbal angle (rad).
    pub angle_noise: f64,
    /// Probability that a report is lost, in `[0, 1)`.
    pub loss: f64,
    /// What a dead ESC reports.
    pub dead_esc: DeadEsc,
    /// Agents whose reports lie: each says it does what it was commanded.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub lying: Vec<usize>,
    /// Seed of the reports' random generator (ChaCha8; a stream of its own).
    pub seed: u64,
}

impl Default for AgentReports {
    /// 100 reports a second, 20 ms late, 0.05 N and 5 mrad of noise, none lost.
    fn default() -> Self {
        Self {
            rate: 100.0,
            latency: 0.02,
            thrust_noise: 0.05,
            angle_noise: 0.005,
            loss: 0.0,
            dead_esc: DeadEsc::Silent,
            lying: Vec::new(),
            seed: 2,
        }
    }
}

impl AgentReports {
    /// Checks every field, naming it (`reports.<field>`), for a team of `agents` flown at the
    /// physics step `dt`.
    pub fn validate(&self, agents: usize, dt: f64) -> Result<(), ScenarioError> {
        let check = |field: &str, ok: bool, v: f64, what: &str| {
            if ok {
                Ok(())
            } else {
                Err(invalid(
                    format!("reports.{field}"),
                    format!("{what}, got {v}"),
                ))
            }
        };
        let r = self.rate;
        check(
            "rate",
            r.is_finite() && r > 0.0 && r * dt <= 1.0 + 1e-9,
            r,
            "must be positive and at most one report per physics step (Hz)",
        )?;
        let l = self.latency;
        check(
            "latency",
            l.is_finite() && (0.0..=1.0).contains(&l),
            l,
            "must be in [0, 1] s",
        )?;
        for (field, v) in [
            ("thrust_noise", self.thrust_noise),
            ("angle_noise", self.angle_noise),
        ] {
            check(
                field,
                v.is_finite() && v >= 0.0,
                v,
                "must be finite and at least 0",
            )?;
        }
        let p = self.loss;
        check(
            "loss",
            p.is_finite() && (0.0..1.0).contains(&p),
            p,
            "must be in [0, 1)",
        )?;
        if let Some(i) = self.lying.iter().find(|i| **i >= agents) {
            return Err(invalid(
                "reports.lying",
                format!("agent {i} is not in the team of {agents}"),
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use crate::Scenario;

    #[test]
    fn reports_parse_and_bad_values_name_the_field() {
        let s =
            Scenario::from_toml_str("[reports]\nrate = 50.0\nlying = [1]\ndead_esc = \"zero\"\n")
                .unwrap();
        let r = s.reports.unwrap();
        assert_eq!(
            (r.rate, r.latency, r.lying.as_slice()),
            (50.0, 0.02, &[1][..])
        );
        assert_eq!(r.dead_esc, super::DeadEsc::Zero);
        assert!(Scenario::default().reports.is_none());
        for (toml, field) in [
            ("rate = 0.0", "reports.rate"),
            ("rate = 5000.0", "reports.rate"),
            ("latency = -1.0", "reports.latency"),
            ("thrust_noise = nan", "reports.thrust_noise"),
            ("angle_noise = -0.1", "reports.angle_noise"),
            ("loss = 1.0", "reports.loss"),
            ("lying = [4]", "reports.lying"),
        ] {
            let e = Scenario::from_toml_str(&format!("[reports]\n{toml}\n")).unwrap_err();
            assert!(e.to_string().contains(field), "{toml}: {e}");
        }
    }
}
