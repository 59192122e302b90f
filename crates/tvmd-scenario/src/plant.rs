//! `[plant]` and `[[payloads]]`: the team that flies differs from the controller's model of it.
//! The controller always gets the scenario's team (`[team]`, `[limits]`); the physics flies it
//! with these errors (`docs/method.md`, "Scenario families").

use serde::{Deserialize, Serialize};

use crate::checks::{check_magnitude, check_nonneg, check_range};
use crate::error::invalid;
use crate::ScenarioError;

/// Largest mass or inertia scale of the plant against the model.
pub const MAX_SCALE: f64 = 10.0;
/// Largest centre-of-mass or payload offset (m).
pub const MAX_OFFSET: f64 = 10.0;
/// Largest gimbal offset (rad).
pub const MAX_GIMBAL_OFFSET: f64 = 0.5;

/// Model error: how the flown team differs from the controller's model (`[plant]`). Every
/// default is the nominal plant.
///
/// ```toml
/// [plant]
/// mass_scale = 1.1                 # m_plant = 1.1 m_C
/// inertia_scale = 1.2              # J_plant = 1.2 J (about the plant's centre of mass)
/// com_offset = [0.02, -0.01, 0.0]  # body frame (m)
/// thrust_efficiency = [0.9, 1.0, 1.0, 1.0]  # per agent: the force is eff * T
/// gimbal_offsets = [[0.02, 0.0], [0.0, 0.0], [0.0, -0.02], [0.0, 0.0]]  # (eta_x, eta_y) rad
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PlantError {
    /// Plant mass over the model's `m_C`; 1. Every agent's and the navigator's mass scales
    /// alike, so the centre of mass stays where the model has it.
    pub mass_scale: f64,
    /// Plant inertia about its centre of mass over the model's `J`; 1.
    pub inertia_scale: f64,
    /// Centre of mass of the plant in the body frame (m), against the model's origin; zero.
    pub com_offset: [f64; 3],
    /// Per agent, the share of the commanded thrust it produces; empty: all 1.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub thrust_efficiency: Vec<f64>,
    /// Per agent, the gimbal's error `(d eta_x, d eta_y)` (rad) added to the angles it reaches;
    /// empty: none.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub gimbal_offsets: Vec<[f64; 2]>,
}

impl Default for PlantError {
    fn default() -> Self {
        Self::nominal()
    }
}

impl PlantError {
    /// The nominal plant: the controller's model is exact.
    pub fn nominal() -> Self {
        Self {
            mass_scale: 1.0,
            inertia_scale: 1.0,
            com_offset: [0.0; 3],
            thrust_efficiency: Vec::new(),
            gimbal_offsets: Vec::new(),
        }
    }

    /// True when the plant is the model (no error at all).
    pub fn is_nominal(&self) -> bool {
        self.mass_is_nominal() && self.actuation_is_nominal()
    }

    /// True when the mass, inertia and centre of mass are the model's.
    pub fn mass_is_nominal(&self) -> bool {
        self.mass_scale == 1.0 && self.inertia_scale == 1.0 && self.com_offset == [0.0; 3]
    }

    /// True when every agent produces the force it is commanded.
    pub fn actuation_is_nominal(&self) -> bool {
        self.thrust_efficiency.iter().all(|&e| e == 1.0)
            && self.gimbal_offsets.iter().all(|o| *o == [0.0; 2])
    }

    /// Agent `i`'s thrust efficiency (1 when not given).
    pub fn efficiency(&self, i: usize) -> f64 {
        self.thrust_efficiency.get(i).copied().unwrap_or(1.0)
    }

    /// Agent `i`'s gimbal offset (zero when not given).
    pub fn gimbal_offset(&self, i: usize) -> [f64; 2] {
        self.gimbal_offsets.get(i).copied().unwrap_or([0.0; 2])
    }

    /// Checks the values against a team of `n` agents.
    pub fn validate(&self, n: usize) -> Result<(), ScenarioError> {
        // A plant lighter than a tenth of the model or heavier than ten times is no longer
        // the same team.
        check_range("plant.mass_scale", self.mass_scale, 0.1, MAX_SCALE)?;
        check_range("plant.inertia_scale", self.inertia_scale, 0.1, MAX_SCALE)?;
        check_magnitude("plant.com_offset", &self.com_offset, MAX_OFFSET)?;
        for (field, len) in [
            ("plant.thrust_efficiency", self.thrust_efficiency.len()),
            ("plant.gimbal_offsets", self.gimbal_offsets.len()),
        ] {
            if len != 0 && len != n {
                return Err(invalid(
                    field,
                    format!("gives {len} agents for a team of {n} (give one per agent or none)"),
                ));
            }
        }
        for (i, &e) in self.thrust_efficiency.iter().enumerate() {
            check_range(&format!("plant.thrust_efficiency[{i}]"), e, 0.0, 2.0)?;
        }
        for (i, o) in self.gimbal_offsets.iter().enumerate() {
            check_magnitude(&format!("plant.gimbal_offsets[{i}]"), o, MAX_GIMBAL_OFFSET)?;
        }
        Ok(())
    }
}

/// A payload that attaches rigidly to the team at a time (`[[payloads]]`), moving with it
/// from then on; the controller is not told.
///
/// ```toml
/// [[payloads]]
/// mass = 0.5                # kg
/// offset = [0.1, 0.0, -0.1] # its centre of mass in the body frame (m)
/// time = 4.0                # s
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Payload {
    /// Mass (kg), a point mass.
    pub mass: f64,
    /// Where it attaches, in the body frame (m); the model's centre of mass by default.
    #[serde(default)]
    pub offset: [f64; 3],
    /// When it attaches (s); 0.
    #[serde(default)]
    pub time: f64,
}

impl Payload {
    /// Checks the values; `field` is the payload's dotted path.
    pub fn validate(&self, field: &str) -> Result<(), ScenarioError> {
        check_range(&format!("{field}.mass"), self.mass, 1e-6, 1e4)?;
        check_magnitude(&format!("{field}.offset"), &self.offset, MAX_OFFSET)?;
        check_nonneg(&format!("{field}.time"), &[self.time])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_nominal_and_bad_values_name_the_field() {
        let p: PlantError = toml::from_str("").unwrap();
        assert_eq!(p, PlantError::nominal());
        assert!(p.mass_is_nominal() && p.actuation_is_nominal());
        p.validate(4).unwrap();
        let p: PlantError = toml::from_str("thrust_efficiency = [1.0, 0.9]").unwrap();
        assert!(!p.actuation_is_nominal() && p.mass_is_nominal());
        assert_eq!((p.efficiency(1), p.efficiency(3)), (0.9, 1.0));
        let e = p.validate(4).unwrap_err().to_string();
        assert!(
            e.contains("plant.thrust_efficiency") && e.contains("2 agents"),
            "{e}"
        );
        for (text, field) in [
            ("mass_scale = 0.0", "plant.mass_scale"),
            ("inertia_scale = nan", "plant.inertia_scale"),
            ("com_offset = [0.0, inf, 0.0]", "plant.com_offset"),
            (
                "gimbal_offsets = [[0.0, 0.0], [0.9, 0.0]]",
                "plant.gimbal_offsets[1]",
            ),
        ] {
            let p: PlantError = toml::from_str(text).unwrap();
            let e = p.validate(2).unwrap_err().to_string();
            assert!(e.contains(field), "{text}: {e}");
        }
        let bad = Payload {
            mass: -1.0,
            offset: [0.0; 3],
            time: 0.0,
        };
        assert!(bad
            .validate("payloads[0]")
            .unwrap_err()
            .to_string()
            .contains("payloads[0].mass"));
    }
}
