//! The agents and the team body's mass properties (`m_C`, `J_C`).

use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};

use crate::math::{quarter_turn, skew};
use crate::PhysicsError;

/// One agent of the team, as the physics sees it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AgentBody {
    /// Position `p_i` of the agent's frame in the team frame {C} (m).
    pub position: [f64; 3],
    /// Agent mass `m_i` (kg), a point mass at `p_i`.
    pub mass: f64,
    /// Orientation `psi_i = m_i pi/2` as the integer number of quarter turns `m_i` about z.
    pub quarter_turns: i32,
}

impl From<&tvmd_core::AgentSpec<f64>> for AgentBody {
    /// The physics' view of a core agent (its position, mass and quarter turns).
    fn from(a: &tvmd_core::AgentSpec<f64>) -> Self {
        Self {
            position: a.position.into(),
            mass: a.mass,
            quarter_turns: a.quarter_turns,
        }
    }
}

impl AgentBody {
    /// The exact rotation `R_z(m_i pi/2)` from the agent frame to the team frame.
    pub fn rotation(&self) -> Matrix3<f64> {
        quarter_turn(self.quarter_turns)
    }

    /// `p_i` as a nalgebra vector.
    pub fn position_vector(&self) -> Vector3<f64> {
        Vector3::from(self.position)
    }
}

/// Mass model and collision geometry of a team.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TeamBody {
    /// The agents.
    pub agents: Vec<AgentBody>,
    /// Navigator mass `m_0` (kg) at the centre (may be zero).
    pub navigator_mass: f64,
    /// Navigator inertia `J_0` about the centre (kg m^2, row-major, symmetric).
    pub navigator_inertia: [[f64; 3]; 3],
    /// Radius of the agents' ball colliders (m).
    pub collider_radius: f64,
}

/// Default radius of the agents' ball colliders (m).
pub const DEFAULT_COLLIDER_RADIUS: f64 = 0.05;

impl TeamBody {
    /// Four agents of mass `mass` at `(+-a, +-a, 0)` with the given quarter turns.
    ///
    /// Agent order as in `tvmd_core::presets`:
    /// `(+a, +a), (+a, -a), (-a, -a), (-a, +a)`. Massless navigator, collider radius
    /// [`DEFAULT_COLLIDER_RADIUS`].
    pub fn a4(a: f64, mass: f64, quarter_turns: [i32; 4]) -> Self {
        let corners = [[a, a, 0.0], [a, -a, 0.0], [-a, -a, 0.0], [-a, a, 0.0]];
        Self {
            agents: corners
                .iter()
                .zip(quarter_turns)
                .map(|(p, m)| AgentBody {
                    position: *p,
                    mass,
                    quarter_turns: m,
                })
                .collect(),
            navigator_mass: 0.0,
            navigator_inertia: [[0.0; 3]; 3],
            collider_radius: DEFAULT_COLLIDER_RADIUS,
        }
    }

    /// `n` agents of mass `mass` evenly on a circle of `radius` in the `x-y` plane, agent `i`
    /// at angle `2 pi i / n`; every second agent turned a quarter turn when `inconsistent`
    /// (the layout of `tvmd_core::presets::ring`). Massless navigator.
    pub fn ring(n: usize, radius: f64, mass: f64, inconsistent: bool) -> Self {
        Self {
            agents: (0..n)
                .map(|i| {
                    let phase = std::f64::consts::TAU * i as f64 / n as f64;
                    AgentBody {
                        position: [radius * phase.cos(), radius * phase.sin(), 0.0],
                        mass,
                        quarter_turns: if inconsistent { (i % 2) as i32 } else { 0 },
                    }
                })
                .collect(),
            navigator_mass: 0.0,
            navigator_inertia: [[0.0; 3]; 3],
            collider_radius: DEFAULT_COLLIDER_RADIUS,
        }
    }

    /// A catalogue team (`tvmd_core::presets::Preset`) on a grid of `unit` metres with
    /// agents of `mass` kg, in the preset's agent order. Massless navigator, collider radius
    /// [`DEFAULT_COLLIDER_RADIUS`]. Errors when the core rejects the layout at that scale.
    pub fn preset(
        preset: tvmd_core::presets::Preset,
        unit: f64,
        mass: f64,
    ) -> Result<Self, tvmd_core::ConfigError> {
        let team: tvmd_core::TeamConfig<f64, 16> = preset.team_with(unit, mass)?;
        Ok(Self {
            agents: team.agents().iter().map(AgentBody::from).collect(),
            navigator_mass: 0.0,
            navigator_inertia: [[0.0; 3]; 3],
            collider_radius: DEFAULT_COLLIDER_RADIUS,
        })
    }

    /// Half side of the paper's A4 square: `a = 0.5 sqrt(2)/2` m.
    pub fn paper_arm() -> f64 {
        0.5 * std::f64::consts::SQRT_2 / 2.0
    }

    /// The paper's A4-Inc team: `psi = [pi/2, pi/2, 0, 0]`, `m_i = 0.7` kg, massless navigator.
    pub fn a4_inc() -> Self {
        Self::a4(Self::paper_arm(), 0.7, [1, 1, 0, 0])
    }

    /// The consistent variant A4-Con: all `psi_i = 0`, otherwise as [`TeamBody::a4_inc`].
    pub fn a4_con() -> Self {
        Self::a4(Self::paper_arm(), 0.7, [0, 0, 0, 0])
    }

    /// Number of agents.
    pub fn len(&self) -> usize {
        self.agents.len()
    }

    /// True if the team has no agent.
    pub fn is_empty(&self) -> bool {
        self.agents.is_empty()
    }

    /// Team mass `m_C = m_0 + sum m_i`.
    pub fn mass(&self) -> f64 {
        self.navigator_mass + self.agents.iter().map(|a| a.mass).sum::<f64>()
    }

    /// Team inertia about the origin, `J_C = J_0 - sum m_i [p_i]x [p_i]x` (point-mass agents).
    pub fn inertia(&self) -> Matrix3<f64> {
        let mut j = crate::math::from_rows(&self.navigator_inertia);
        for a in &self.agents {
            let s = skew(&a.position_vector());
            j -= a.mass * s * s;
        }
        j
    }

    /// Height of the centre of mass above the ground when the team rests level on it:
    /// `collider_radius - min(0, min_i p_i.z)`.
    pub fn rest_height(&self) -> f64 {
        let lowest = self
            .agents
            .iter()
            .map(|a| a.position[2])
            .fold(0.0_f64, f64::min);
        self.collider_radius - lowest
    }

    /// Checks that the team is physically usable.
    ///
    /// Requires at least one agent, finite positive masses, a non-negative navigator mass, a
    /// symmetric positive-semidefinite navigator inertia, a positive collider radius, and the
    /// centre of mass at the origin (`|sum m_i p_i| / m_C <= 1e-9 (1 + max |p_i|)`).
    pub fn validate(&self) -> Result<(), PhysicsError> {
        let bad = |m: String| Err(PhysicsError::InvalidTeam(m));
        if self.agents.is_empty() {
            return bad("the team has no agent".into());
        }
        for (i, a) in self.agents.iter().enumerate() {
            if !(a.mass.is_finite() && a.mass > 0.0) {
                return bad(format!(
                    "agent {i}: mass must be finite and > 0, got {}",
                    a.mass
                ));
            }
            if a.position.iter().any(|c| !c.is_finite()) {
                return bad(format!("agent {i}: position is not finite"));
            }
        }
        if !(self.navigator_mass.is_finite() && self.navigator_mass >= 0.0) {
            return bad(format!(
                "navigator mass must be finite and >= 0, got {}",
                self.navigator_mass
            ));
        }
        let j0 = crate::math::from_rows(&self.navigator_inertia);
        if j0.iter().any(|c| !c.is_finite()) || (j0 - j0.transpose()).abs().max() > 1e-12 {
            return bad("navigator inertia must be finite and symmetric".into());
        }
        if j0.symmetric_eigenvalues().min() < -1e-12 {
            return bad("navigator inertia must be positive semidefinite".into());
        }
        if !(self.collider_radius.is_finite() && self.collider_radius > 0.0) {
            return bad(format!(
                "collider radius must be finite and > 0, got {}",
                self.collider_radius
            ));
        }
        let first_moment: Vector3<f64> = self
            .agents
            .iter()
            .map(|a| a.mass * a.position_vector())
            .sum();
        let scale = 1.0
            + self
                .agents
                .iter()
                .map(|a| a.position_vector().norm())
                .fold(0.0, f64::max);
        let com = first_moment / self.mass();
        if com.norm() > 1e-9 * scale {
            return bad(format!(
                "the centre of mass is at [{:.3e}, {:.3e}, {:.3e}], not at the origin: agent \
                 positions must be given relative to the team centre of mass",
                com.x, com.y, com.z
            ));
        }
        Ok(())
    }
}
