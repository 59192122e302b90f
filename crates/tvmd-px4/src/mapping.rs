//! The 16 controls of PX4's HIL_ACTUATOR_CONTROLS onto the team's actuators, as data.
//!
//! PX4's `simulator_mavlink` sends `actuator_outputs_sim`: output `i` carries the function
//! `PWM_MAIN_FUNC(i+1)` of the airframe, motors in `[0, 1]`, servos in `[-1, 1]`, zero while
//! disarmed. A [`ControlMapping`] says, per output, which agent's rotor or gimbal axis it
//! drives. A rotor's thrust is linear in its control (`T = u * rotor_thrust`, PX4's thrust
//! model with `THR_MDL_FAC = 0`); the rotors of one agent add up (a coaxial pair). A gimbal
//! angle is the control times the axis's range (`eta = s * range`, the servo's `[-1, 1]`
//! spanning `[-range, range]`).

use serde::{Deserialize, Serialize};
use tvmd_plant::actuators::ActuatorCommand;

use crate::Px4Error;

/// Number of controls in HIL_ACTUATOR_CONTROLS.
pub const CONTROLS: usize = 16;

/// What one control drives.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Role {
    /// Nothing: the control is ignored.
    Unused,
    /// A rotor of agent `agent` (thrust along the agent's gimbal axis).
    Rotor(usize),
    /// The inner gimbal axis `eta_x` of an agent.
    EtaX(usize),
    /// The outer gimbal axis `eta_y` of an agent.
    EtaY(usize),
}

impl std::fmt::Display for Role {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Role::Unused => write!(f, "none"),
            Role::Rotor(a) => write!(f, "rotor:{a}"),
            Role::EtaX(a) => write!(f, "eta_x:{a}"),
            Role::EtaY(a) => write!(f, "eta_y:{a}"),
        }
    }
}

impl std::str::FromStr for Role {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        if s == "none" {
            return Ok(Role::Unused);
        }
        let (kind, agent) = s
            .split_once(':')
            .ok_or_else(|| format!("`{s}`: expected none, rotor:I, eta_x:I or eta_y:I"))?;
        let agent: usize = agent
            .parse()
            .map_err(|_| format!("`{s}`: the agent index must be a non-negative integer"))?;
        match kind {
            "rotor" => Ok(Role::Rotor(agent)),
            "eta_x" => Ok(Role::EtaX(agent)),
            "eta_y" => Ok(Role::EtaY(agent)),
            _ => Err(format!("`{s}`: expected none, rotor:I, eta_x:I or eta_y:I")),
        }
    }
}

/// The mapping as a flight file writes it (`[mapping]`): a layout's name or every control's
/// role, and the scales.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct MappingConfig {
    /// `"quad"` (controls 0-3: one rotor per agent, gimbals held at zero) or `"authors"` (the
    /// TVMD airframe's: controls 0-7 motors 101-108, two coaxial rotors per agent; controls
    /// 8-15 servos 201-208, `eta_x` then `eta_y` of each agent); ignored when `channels` is
    /// given.
    pub layout: Option<String>,
    /// Every control's role (`"none"`, `"rotor:I"`, `"eta_x:I"`, `"eta_y:I"`), at most 16.
    pub channels: Option<Vec<String>>,
    /// Thrust of one rotor at control 1 (N); default the agent's largest thrust `sigma_Tf`
    /// shared by its rotors.
    pub rotor_thrust: Option<f64>,
    /// Gimbal angle at control 1 `[eta_x, eta_y]` (rad); default the authors' servo ranges,
    /// 30 deg and 90 deg (`CA_SV_TL*_MAXA`).
    pub gimbal_range: Option<[f64; 2]>,
}

/// The resolved mapping: one role per control, checked against the team.
#[derive(Clone, Debug, PartialEq)]
pub struct ControlMapping {
    roles: [Role; CONTROLS],
    agents: usize,
    rotor_thrust: f64,
    gimbal_range: [f64; 2],
}

impl ControlMapping {
    /// The mapping of `config` for a team of `agents` agents whose largest agent thrust is
    /// `max_thrust` (N). Errors name what is wrong: an unknown layout, a role for an agent the
    /// team does not have, an agent without a rotor, a non-positive scale.
    pub fn new(config: &MappingConfig, agents: usize, max_thrust: f64) -> Result<Self, Px4Error> {
        let bad = |reason: String| Px4Error::Config {
            field: "mapping".into(),
            reason,
        };
        let mut roles = [Role::Unused; CONTROLS];
        match (&config.channels, config.layout.as_deref()) {
            (Some(channels), _) => {
                if channels.len() > CONTROLS {
                    return Err(bad(format!(
                        "{} channels, at most {CONTROLS}",
                        channels.len()
                    )));
                }
                for (role, text) in roles.iter_mut().zip(channels) {
                    *role = text.parse().map_err(bad)?;
                }
            }
            (None, Some("quad") | None) => {
                for (i, role) in roles.iter_mut().enumerate().take(agents.min(CONTROLS)) {
                    *role = Role::Rotor(i);
                }
            }
            (None, Some("authors")) => {
                for a in 0..agents.min(4) {
                    roles[2 * a] = Role::Rotor(a);
                    roles[2 * a + 1] = Role::Rotor(a);
                    roles[8 + 2 * a] = Role::EtaX(a);
                    roles[8 + 2 * a + 1] = Role::EtaY(a);
                }
            }
            (None, Some(other)) => {
                return Err(bad(format!(
                    "unknown layout `{other}` (known: quad, authors; or give `channels`)"
                )))
            }
        }
        let mut rotors = vec![0usize; agents];
        for role in roles {
            match role {
                Role::Unused => {}
                Role::Rotor(a) | Role::EtaX(a) | Role::EtaY(a) if a >= agents => {
                    return Err(bad(format!(
                        "`{role}` names agent {a}, the team has {agents} (0 to {})",
                        agents.saturating_sub(1)
                    )))
                }
                Role::Rotor(a) => rotors[a] += 1,
                _ => {}
            }
        }
        if let Some(a) = rotors.iter().position(|&n| n == 0) {
            return Err(bad(format!(
                "agent {a} has no rotor control: a team of {agents} agents needs one or more \
                 `rotor:I` per agent (the authors' layout covers 4 agents; give `channels` for \
                 other teams)"
            )));
        }
        let per_agent = rotors.iter().copied().max().unwrap_or(1) as f64;
        let rotor_thrust = config.rotor_thrust.unwrap_or(max_thrust / per_agent);
        let gimbal_range = config
            .gimbal_range
            .unwrap_or([30f64.to_radians(), 90f64.to_radians()]);
        if !(rotor_thrust.is_finite() && rotor_thrust > 0.0) {
            return Err(bad(format!(
                "rotor_thrust must be > 0 N, got {rotor_thrust}"
            )));
        }
        if !gimbal_range.iter().all(|r| r.is_finite() && *r > 0.0) {
            return Err(bad(format!(
                "gimbal_range must be > 0 rad, got {gimbal_range:?}"
            )));
        }
        Ok(Self {
            roles,
            agents,
            rotor_thrust,
            gimbal_range,
        })
    }

    /// The role of every control.
    pub fn roles(&self) -> &[Role; CONTROLS] {
        &self.roles
    }

    /// The team's commands of PX4's 16 controls: rotor controls clamped to `[0, 1]` and servo
    /// controls to `[-1, 1]` (the ranges PX4 sends; a non-finite control counts as 0, PX4's
    /// disarmed value).
    pub fn commands(&self, controls: &[f32; CONTROLS]) -> Vec<ActuatorCommand> {
        let mut out = vec![ActuatorCommand::default(); self.agents];
        for (role, &u) in self.roles.iter().zip(controls) {
            let u = if u.is_finite() { f64::from(u) } else { 0.0 };
            match *role {
                Role::Unused => {}
                Role::Rotor(a) => out[a].thrust += u.clamp(0.0, 1.0) * self.rotor_thrust,
                Role::EtaX(a) => out[a].eta_x = u.clamp(-1.0, 1.0) * self.gimbal_range[0],
                Role::EtaY(a) => out[a].eta_y = u.clamp(-1.0, 1.0) * self.gimbal_range[1],
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn layout(name: &str) -> MappingConfig {
        MappingConfig {
            layout: Some(name.into()),
            ..Default::default()
        }
    }

    #[test]
    fn quad_layout_drives_one_rotor_per_agent_and_holds_the_gimbals() {
        let m = ControlMapping::new(&layout("quad"), 4, 10.0).unwrap();
        let mut u = [0f32; CONTROLS];
        u[..4].copy_from_slice(&[0.5, 1.0, 0.0, 0.25]);
        u[8] = 1.0; // a servo output the quad does not use
        let c = m.commands(&u);
        let thrust: Vec<f64> = c.iter().map(|c| c.thrust).collect();
        assert_eq!(thrust, vec![5.0, 10.0, 0.0, 2.5]);
        assert!(c.iter().all(|c| c.eta_x == 0.0 && c.eta_y == 0.0));
    }

    #[test]
    fn authors_layout_adds_the_coaxial_pair_and_scales_the_servos() {
        let m = ControlMapping::new(&layout("authors"), 4, 12.0).unwrap();
        let mut u = [0f32; CONTROLS];
        u[2] = 1.0; // agent 1, upper rotor
        u[3] = 0.5; // agent 1, lower rotor
        u[10] = -1.0; // agent 1 eta_x
        u[11] = 0.5; // agent 1 eta_y
        let c = m.commands(&u);
        assert!((c[1].thrust - 9.0).abs() < 1e-12, "{}", c[1].thrust);
        assert!((c[1].eta_x + 30f64.to_radians()).abs() < 1e-12);
        assert!((c[1].eta_y - 45f64.to_radians()).abs() < 1e-12);
        assert_eq!(c[0], ActuatorCommand::default());
    }

    #[test]
    fn authors_layout_drives_a_three_agent_team_from_the_first_six_of_each() {
        // Airframes 4091 and 4092 (A3): motors 1-6 and servos 1-6; outputs 7, 8, 15, 16 unused.
        let m = ControlMapping::new(&layout("authors"), 3, 12.0).unwrap();
        for (i, role) in m.roles().iter().enumerate() {
            let expected = match i {
                0..=5 => Role::Rotor(i / 2),
                8..=13 if i % 2 == 0 => Role::EtaX((i - 8) / 2),
                8..=13 => Role::EtaY((i - 8) / 2),
                _ => Role::Unused,
            };
            assert_eq!(*role, expected, "control {i}");
        }
        // What PX4 sends on the unused outputs (NaN, disarmed) drives nothing.
        let mut u = [0.5f32; CONTROLS];
        for i in [6, 7, 14, 15] {
            u[i] = f32::NAN;
        }
        let c = m.commands(&u);
        assert_eq!(c.len(), 3);
        assert!(c.iter().all(|c| (c.thrust - 6.0).abs() < 1e-12), "{c:?}");
    }

    #[test]
    fn out_of_range_and_nan_controls_are_bounded() {
        let m = ControlMapping::new(&layout("quad"), 4, 10.0).unwrap();
        let mut u = [0f32; CONTROLS];
        u[0] = 2.0;
        u[1] = -1.0;
        u[2] = f32::NAN;
        let c = m.commands(&u);
        assert_eq!((c[0].thrust, c[1].thrust, c[2].thrust), (10.0, 0.0, 0.0));
    }

    #[test]
    fn bad_mappings_are_refused_with_the_reason() {
        let err = |c: &MappingConfig, n| ControlMapping::new(c, n, 10.0).unwrap_err().to_string();
        assert!(err(&layout("hexa"), 4).contains("unknown layout `hexa`"));
        // The authors' layout covers four agents: a six-agent team lacks rotors.
        assert!(err(&layout("authors"), 6).contains("agent 4 has no rotor"));
        let explicit = MappingConfig {
            channels: Some(vec!["rotor:0".into(), "rotor:5".into()]),
            ..Default::default()
        };
        assert!(err(&explicit, 2).contains("names agent 5"));
        let typo = MappingConfig {
            channels: Some(vec!["motor:0".into()]),
            ..Default::default()
        };
        assert!(err(&typo, 1).contains("expected none, rotor:I"));
    }
}
