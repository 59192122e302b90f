//! Semantic checks of a scenario ([`Scenario::validate`]): values that parse but make no sense,
//! each error naming the field by its dotted path.

use std::f64::consts::PI;

use super::{Scenario, ALLOCATOR_NAMES};
use crate::reference::ReferenceConfig;
use crate::SimError;

pub(super) fn invalid(field: impl Into<String>, reason: impl Into<String>) -> SimError {
    SimError::InvalidScenario {
        field: field.into(),
        reason: reason.into(),
    }
}

fn check_pos(field: &str, v: f64) -> Result<(), SimError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(invalid(field, format!("must be finite and > 0, got {v}")))
    }
}

fn check_nonneg(field: &str, v: &[f64]) -> Result<(), SimError> {
    match v.iter().find(|x| !(x.is_finite() && **x >= 0.0)) {
        None => Ok(()),
        Some(x) => Err(invalid(field, format!("must be finite and >= 0, got {x}"))),
    }
}

fn check_finite(field: &str, v: &[f64]) -> Result<(), SimError> {
    if v.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(invalid(field, "must be finite"))
    }
}

impl Scenario {
    /// Checks values that parse but make no sense; errors name the field.
    pub fn validate(&self) -> Result<(), SimError> {
        check_pos("duration", self.duration)?;
        check_pos("physics.dt", self.physics.dt)?;
        check_pos("controller_period", self.controller_period)?;
        self.steps_per_control()?;
        check_nonneg("physics.gravity", &[self.physics.gravity])?;
        check_nonneg("physics.friction", &[self.physics.friction])?;
        check_finite("initial_position", &self.initial_position)?;
        check_pos(
            "failure_response.landing_acceleration",
            self.failure_response.landing_acceleration,
        )?;
        if !(self.relaxation > 0.0 && self.relaxation <= 1.0) {
            return Err(invalid(
                "relaxation",
                format!("must be in (0, 1], got {}", self.relaxation),
            ));
        }
        for (f, v) in [
            ("limits.sigma_x", self.limits.sigma_x),
            ("limits.sigma_y", self.limits.sigma_y),
        ] {
            if !(v > 0.0 && v <= PI) {
                return Err(invalid(f, format!("must be in (0, pi], got {v}")));
            }
        }
        if let Some(t) = self.limits.max_thrust {
            check_pos("limits.max_thrust", t)?;
        }
        if !ALLOCATOR_NAMES.contains(&self.allocator.as_str())
            && self.allocator != tvmd_core::allocation::CLARABEL
        {
            return Err(invalid(
                "allocator",
                format!(
                    "unknown allocator `{}` (known: {})",
                    self.allocator,
                    ALLOCATOR_NAMES.join(", ")
                ),
            ));
        }
        if let Some([x, y]) = self.controller_rate_limits {
            check_pos("controller_rate_limits[0]", x)?;
            check_pos("controller_rate_limits[1]", y)?;
        }
        if let Some(n) = &self.null_space {
            n.validate()?;
        }
        check_nonneg("gains.k_x", &self.gains.k_x)?;
        check_nonneg("gains.k_r", &self.gains.k_r)?;
        check_nonneg("gains.k_xi", &self.gains.k_xi)?;
        let team = self.team_body()?;
        match &self.reference {
            ReferenceConfig::PaperTilt(p) => {
                check_finite("reference.ascent_height", &[p.ascent_height])?;
                check_finite("reference.roll_peak", &[p.roll_peak])?;
                for (f, w) in [
                    ("reference.ascent", p.ascent),
                    ("reference.tilt", p.tilt),
                    ("reference.descent", p.descent),
                ] {
                    check_finite(f, &w)?;
                    if w[1] < w[0] {
                        return Err(invalid(f, "end before start"));
                    }
                }
            }
            ReferenceConfig::Hover { position, roll } => {
                check_finite("reference.position", position)?;
                check_finite("reference.roll", &[*roll])?;
            }
        }
        if let Some(s) = &self.actuators.servo {
            check_pos("actuators.servo.natural_frequency", s.natural_frequency)?;
            check_nonneg("actuators.servo.damping_ratio", &[s.damping_ratio])?;
            check_pos("actuators.servo.rate_limit", s.rate_limit)?;
        }
        if let Some(l) = &self.actuators.rotor_lag {
            check_pos("actuators.rotor_lag.time_constant", l.time_constant)?;
        }
        if let Some(l) = &self.actuators.limits {
            check_pos("actuators.limits.sigma_x", l.sigma_x)?;
            check_pos("actuators.limits.sigma_y", l.sigma_y)?;
            check_pos("actuators.limits.max_thrust", l.max_thrust)?;
        }
        for (i, f) in self.failures.iter().enumerate() {
            if f.agent >= team.len() {
                return Err(invalid(
                    format!("failures[{i}].agent"),
                    format!(
                        "agent {} does not exist (the team has {})",
                        f.agent,
                        team.len()
                    ),
                ));
            }
            check_nonneg(&format!("failures[{i}].time"), &[f.time])?;
        }
        check_finite("disturbances.wind", &self.disturbances.wind)?;
        if let Some(w) = &self.disturbances.external_wrench {
            check_finite("disturbances.external_wrench.force", &w.force)?;
            check_finite("disturbances.external_wrench.torque", &w.torque)?;
            check_finite("disturbances.external_wrench.start", &[w.start])?;
            if let Some(e) = w.end {
                check_finite("disturbances.external_wrench.end", &[e])?;
            }
        }
        if let Some(n) = &self.disturbances.state_noise {
            check_nonneg(
                "disturbances.state_noise",
                &[n.position, n.velocity, n.attitude, n.angular_velocity],
            )?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bad_values_name_the_field() {
        let e = Scenario::from_toml_str("relaxation = 1.5\n").unwrap_err();
        assert!(
            matches!(&e, SimError::InvalidScenario { field, .. } if field == "relaxation"),
            "{e}"
        );
        let e = Scenario::from_toml_str("controller_period = 0.0125\n").unwrap_err();
        assert!(e.to_string().contains("controller_period"), "{e}");
        let e =
            Scenario::from_toml_str("[[failures]]\nagent = 7\ntime = 1.0\nkind = \"no-thrust\"\n")
                .unwrap_err();
        assert!(e.to_string().contains("failures[0].agent"), "{e}");
    }
}
