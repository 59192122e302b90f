//! The team of a scenario: a preset or explicit agents, and its limits.

use std::f64::consts::PI;

use serde::{Deserialize, Serialize};
use tvmd_core::presets::Preset;
use tvmd_plant::{AgentBody, TeamBody, DEFAULT_COLLIDER_RADIUS};

use crate::ScenarioError;

/// The team: a preset or explicit agents.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct TeamSpec {
    /// A catalogue team (`tvmd_core::presets::Preset::name`: `"a3-con"` .. `"t10-inc"`,
    /// `"a4-inc"` the paper's); used when `agents` is absent (default `"a4-inc"`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub preset: Option<String>,
    /// Explicit agents (positions relative to the team centre of mass); excludes `preset`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub agents: Option<Vec<AgentBody>>,
    /// Agent mass for presets (kg); 0.7.
    pub agent_mass: f64,
    /// Grid unit of the presets (m): the half side `a` of the A4 square, `0.5 sqrt(2)/2` by
    /// default (the authors' `GRID_SIZE`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub arm: Option<f64>,
    /// Navigator mass (kg); 0.
    pub navigator_mass: f64,
    /// Navigator inertia (kg m^2, row-major); 0.
    pub navigator_inertia: [[f64; 3]; 3],
    /// Collider radius (m); 0.05.
    pub collider_radius: f64,
}

impl Default for TeamSpec {
    fn default() -> Self {
        Self {
            preset: None,
            agents: None,
            agent_mass: 0.7,
            arm: None,
            navigator_mass: 0.0,
            navigator_inertia: [[0.0; 3]; 3],
            collider_radius: DEFAULT_COLLIDER_RADIUS,
        }
    }
}

impl TeamSpec {
    /// Resolves the preset or the explicit agents into a validated [`TeamBody`].
    pub fn team_body(&self) -> Result<TeamBody, ScenarioError> {
        let invalid = |field: &str, reason: String| ScenarioError::InvalidScenario {
            field: field.into(),
            reason,
        };
        let mut body = match (&self.preset, &self.agents) {
            (Some(_), Some(_)) => {
                return Err(invalid(
                    "team.agents",
                    "give either `team.preset` or `team.agents`, not both".into(),
                ))
            }
            (None, Some(agents)) => TeamBody {
                agents: agents.clone(),
                navigator_mass: 0.0,
                navigator_inertia: [[0.0; 3]; 3],
                collider_radius: DEFAULT_COLLIDER_RADIUS,
            },
            (preset, None) => {
                let name = preset.as_deref().unwrap_or("a4-inc");
                let Some(preset) = Preset::from_name(name) else {
                    let known: Vec<&str> = Preset::ALL.iter().map(|p| p.name()).collect();
                    return Err(invalid(
                        "team.preset",
                        format!("unknown preset `{name}` (known: {})", known.join(", ")),
                    ));
                };
                let unit = self.arm.unwrap_or_else(TeamBody::paper_arm);
                TeamBody::preset(preset, unit, self.agent_mass)
                    .map_err(|e| invalid("team", e.to_string()))?
            }
        };
        body.navigator_mass = self.navigator_mass;
        body.navigator_inertia = self.navigator_inertia;
        body.collider_radius = self.collider_radius;
        body.validate()
            .map_err(|e| invalid("team", e.to_string()))?;
        Ok(body)
    }
}

/// Gimbal and thrust limits (eq. 6).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct LimitsConfig {
    /// `sigma_x` (rad); `pi/6`.
    pub sigma_x: f64,
    /// `sigma_y` (rad); `pi/4`.
    pub sigma_y: f64,
    /// `sigma_Tf`, maximum thrust of one agent (N); default `2 m_i g` of the heaviest agent.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_thrust: Option<f64>,
}

impl Default for LimitsConfig {
    fn default() -> Self {
        Self {
            sigma_x: PI / 6.0,
            sigma_y: PI / 4.0,
            max_thrust: None,
        }
    }
}
