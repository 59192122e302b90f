//! Agent commands, thrust direction (eq. 1), actuator models and failures.
//!
//! Each agent has two gimbal angles `eta_x`, `eta_y` and a thrust `T`. Its force in the team
//! (body) frame is `T R_z(m_i pi/2) a_hat(eta_x, eta_y)` with the exact quarter-turn matrix.
//!
//! Models (per agent, stepped at the physics rate):
//! - ideal (default): the command passes through unchanged;
//! - servo: each gimbal angle follows its command as a second-order system
//!   `eta_dd = w_n^2 (eta_cmd - eta) - 2 zeta w_n eta_d` with `|eta_d| <= rate_limit`;
//! - rotor lag: first order `T_d = (T_cmd - T) / tau`;
//! - optional saturation of the *commands* to the gimbal and thrust limits.
//!
//! Failures take effect from a given time: the thrust drops to zero at once and/or the gimbal
//! sticks at the angles it has at that moment.

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

use crate::math::quarter_turn;

/// Command (or actual state) of one agent.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ActuatorCommand {
    /// Gimbal angle about the agent's x axis (rad).
    pub eta_x: f64,
    /// Gimbal angle about the agent's y axis (rad).
    pub eta_y: f64,
    /// Thrust magnitude (N).
    pub thrust: f64,
}

impl ActuatorCommand {
    /// True if every field is finite.
    pub fn is_finite(&self) -> bool {
        self.eta_x.is_finite() && self.eta_y.is_finite() && self.thrust.is_finite()
    }
}

/// `a_hat(eta_x, eta_y)` of eq. (1): the plant uses the core's gimbal model.
pub use tvmd_core::gimbal::thrust_direction;

/// The agent's force in the team (body) frame: `T R_z(m_i pi/2) a_hat(eta_x, eta_y)`.
pub fn agent_force_body(cmd: &ActuatorCommand, quarter_turns: i32) -> Vector3<f64> {
    quarter_turn(quarter_turns) * (cmd.thrust * thrust_direction(cmd.eta_x, cmd.eta_y))
}

/// Second-order, rate-limited gimbal servo.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ServoModel {
    /// Natural frequency `w_n` (rad/s).
    pub natural_frequency: f64,
    /// Damping ratio `zeta`.
    pub damping_ratio: f64,
    /// Maximum gimbal rate (rad/s).
    pub rate_limit: f64,
}

/// First-order rotor (thrust) lag.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RotorLag {
    /// Time constant `tau` (s).
    pub time_constant: f64,
}

/// Per-agent command limits used when saturation is enabled.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SaturationLimits {
    /// `|eta_x| <= sigma_x` (rad).
    pub sigma_x: f64,
    /// `|eta_y| <= sigma_y` (rad).
    pub sigma_y: f64,
    /// `0 <= T <= max_thrust` (N).
    pub max_thrust: f64,
}

impl SaturationLimits {
    /// `cmd` with each gimbal angle clamped to its limit and the thrust to `[0, max_thrust]`
    /// (a rotor pushes only up its axis); a non-finite value stays non-finite.
    pub fn saturate(&self, cmd: &ActuatorCommand) -> ActuatorCommand {
        ActuatorCommand {
            eta_x: cmd.eta_x.clamp(-self.sigma_x, self.sigma_x),
            eta_y: cmd.eta_y.clamp(-self.sigma_y, self.sigma_y),
            thrust: cmd.thrust.clamp(0.0, self.max_thrust),
        }
    }
}

/// Actuator model of every agent. The default is ideal (commands pass through).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ActuatorModel {
    /// Gimbal servo model; `None` = ideal gimbal.
    pub servo: Option<ServoModel>,
    /// Rotor lag; `None` = ideal thrust.
    pub rotor_lag: Option<RotorLag>,
    /// Saturate commands to these limits before the models; `None` = no saturation.
    pub limits: Option<SaturationLimits>,
}

impl ActuatorModel {
    /// True if commands pass through unchanged.
    pub fn is_ideal(&self) -> bool {
        self.servo.is_none() && self.rotor_lag.is_none() && self.limits.is_none()
    }

    /// True if the outputs depend on the held commands and the failures alone (no servo, no
    /// rotor lag; saturation allowed): they change only when either does.
    pub fn is_memoryless(&self) -> bool {
        self.servo.is_none() && self.rotor_lag.is_none()
    }
}

/// What fails in an agent.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum FailureKind {
    /// The rotor stops: thrust zero from the failure time on.
    NoThrust,
    /// The gimbal sticks at its angles at the failure time; thrust keeps following commands.
    StuckGimbal,
    /// Both.
    NoThrustStuckGimbal,
    /// The rotor delivers half of its commanded thrust from the failure time on (a partial
    /// loss: a damaged propeller, a browning-out ESC).
    HalfThrust,
    /// The agent's command link falls silent: its actuators keep working on the last command
    /// it received, then it fails safe as its link says (the simulator's `[links]`).
    LinkLoss,
}

impl FailureKind {
    /// True if the thrust is lost.
    pub fn loses_thrust(self) -> bool {
        matches!(self, Self::NoThrust | Self::NoThrustStuckGimbal)
    }

    /// True if the thrust is halved.
    pub fn halves_thrust(self) -> bool {
        matches!(self, Self::HalfThrust)
    }

    /// True if the agent's command link falls silent.
    pub fn silences_link(self) -> bool {
        matches!(self, Self::LinkLoss)
    }

    /// True if the gimbal sticks.
    pub fn sticks_gimbal(self) -> bool {
        matches!(self, Self::StuckGimbal | Self::NoThrustStuckGimbal)
    }
}

/// State of one agent's actuators.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct AgentActuator {
    /// Actual gimbal angles and thrust.
    pub actual: ActuatorCommand,
    /// Gimbal rates (rad/s) `[eta_x_dot, eta_y_dot]` (servo model only).
    pub rates: [f64; 2],
    /// The thrust is lost.
    pub thrust_failed: bool,
    /// The gimbal is stuck at `actual`'s angles.
    pub gimbal_stuck: bool,
    /// The rotor delivers half its commanded thrust ([`FailureKind::HalfThrust`]).
    pub thrust_halved: bool,
}

fn servo_axis(angle: &mut f64, rate: &mut f64, cmd: f64, m: &ServoModel, dt: f64) {
    let wn = m.natural_frequency;
    let acc = wn * wn * (cmd - *angle) - 2.0 * m.damping_ratio * wn * *rate;
    // Semi-implicit Euler: the rate first (then limited), the angle with the new rate.
    *rate = (*rate + dt * acc).clamp(-m.rate_limit, m.rate_limit);
    *angle += dt * *rate;
}

impl AgentActuator {
    /// Advances this agent's actuators by `dt` towards `cmd` and returns the actual output.
    pub fn step(
        &mut self,
        cmd: &ActuatorCommand,
        model: &ActuatorModel,
        dt: f64,
    ) -> ActuatorCommand {
        let c = model.limits.map_or(*cmd, |l| l.saturate(cmd));
        if !self.gimbal_stuck {
            match &model.servo {
                None => {
                    self.actual.eta_x = c.eta_x;
                    self.actual.eta_y = c.eta_y;
                }
                Some(m) => {
                    let [rx, ry] = &mut self.rates;
                    servo_axis(&mut self.actual.eta_x, rx, c.eta_x, m, dt);
                    servo_axis(&mut self.actual.eta_y, ry, c.eta_y, m, dt);
                }
            }
        }
        if self.thrust_failed {
            self.actual.thrust = 0.0;
        } else {
            let wanted = if self.thrust_halved {
                0.5 * c.thrust
            } else {
                c.thrust
            };
            match &model.rotor_lag {
                None => self.actual.thrust = wanted,
                Some(l) => {
                    // Exact discretisation of the first-order lag over dt.
                    let a = (-dt / l.time_constant).exp();
                    self.actual.thrust = a * self.actual.thrust + (1.0 - a) * wanted;
                }
            }
        }
        self.actual
    }

    /// Applies a failure now.
    pub fn fail(&mut self, kind: FailureKind) {
        if kind.loses_thrust() {
            self.thrust_failed = true;
            self.actual.thrust = 0.0;
        }
        if kind.sticks_gimbal() {
            self.gimbal_stuck = true;
            self.rates = [0.0; 2];
        }
        if kind.halves_thrust() {
            self.thrust_halved = true;
            self.actual.thrust *= 0.5;
        }
    }

    /// True if any failure is active.
    pub fn failed(&self) -> bool {
        self.thrust_failed || self.gimbal_stuck || self.thrust_halved
    }
}

/// The actuators of all agents.
#[derive(Clone, Debug, PartialEq)]
pub struct ActuatorBank {
    /// The model shared by all agents.
    pub model: ActuatorModel,
    /// Per-agent state.
    pub agents: Vec<AgentActuator>,
}

impl ActuatorBank {
    /// `n` agents at rest (zero angles, zero thrust).
    pub fn new(model: ActuatorModel, n: usize) -> Self {
        Self {
            model,
            agents: vec![AgentActuator::default(); n],
        }
    }

    /// Advances all agents by `dt`; `commands.len()` must equal the number of agents
    /// (extra commands are ignored, missing ones count as zero). Read the outputs with
    /// [`ActuatorBank::outputs`]; nothing is allocated, as this runs every physics step.
    pub fn step(&mut self, commands: &[ActuatorCommand], dt: f64) {
        for (i, a) in self.agents.iter_mut().enumerate() {
            let c = commands.get(i).copied().unwrap_or_default();
            a.step(&c, &self.model, dt);
        }
    }

    /// Actual outputs of the agents, in agent order.
    pub fn outputs(&self) -> impl Iterator<Item = &ActuatorCommand> + '_ {
        self.agents.iter().map(|a| &a.actual)
    }

    /// Actual outputs of all agents, collected.
    pub fn actual(&self) -> Vec<ActuatorCommand> {
        self.outputs().copied().collect()
    }

    /// Applies a failure to agent `i` (ignored if out of range).
    pub fn fail(&mut self, i: usize, kind: FailureKind) {
        if let Some(a) = self.agents.get_mut(i) {
            a.fail(kind);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::FRAC_PI_2;

    #[test]
    fn direction_is_unit_and_matches_eq1() {
        let d = thrust_direction(0.3f64, -0.7);
        assert!((d.norm() - 1.0).abs() < 1e-15);
        assert!(
            (d - Vector3::new(
                0.3f64.cos() * (-0.7f64).sin(),
                -(0.3f64.sin()),
                0.3f64.cos() * 0.7f64.cos()
            ))
            .norm()
                < 1e-15
        );
        assert_eq!(thrust_direction(0.0, 0.0), Vector3::z());
    }

    #[test]
    fn quarter_turn_rotates_the_force() {
        let c = ActuatorCommand {
            eta_x: 0.0,
            eta_y: FRAC_PI_2,
            thrust: 2.0,
        };
        // a_hat = +x in the agent frame; one quarter turn maps it to +y.
        let f = agent_force_body(&c, 1);
        assert!((f - Vector3::new(0.0, 2.0, 0.0)).norm() < 1e-15);
    }

    #[test]
    fn servo_converges_and_respects_rate_limit() {
        let model = ActuatorModel {
            servo: Some(ServoModel {
                natural_frequency: 30.0,
                damping_ratio: 0.8,
                rate_limit: 2.0,
            }),
            ..Default::default()
        };
        let mut a = AgentActuator::default();
        let cmd = ActuatorCommand {
            eta_x: 0.5,
            eta_y: -0.2,
            thrust: 5.0,
        };
        let mut prev = a.actual;
        for _ in 0..2000 {
            let out = a.step(&cmd, &model, 1e-3);
            assert!((out.eta_x - prev.eta_x).abs() <= 2.0 * 1e-3 + 1e-15);
            prev = out;
        }
        assert!((a.actual.eta_x - 0.5).abs() < 1e-6 && (a.actual.eta_y + 0.2).abs() < 1e-6);
        assert_eq!(a.actual.thrust, 5.0);
    }

    #[test]
    fn rotor_lag_is_first_order() {
        let model = ActuatorModel {
            rotor_lag: Some(RotorLag {
                time_constant: 0.05,
            }),
            ..Default::default()
        };
        let mut a = AgentActuator::default();
        let cmd = ActuatorCommand {
            thrust: 10.0,
            ..Default::default()
        };
        for _ in 0..50 {
            a.step(&cmd, &model, 1e-3);
        }
        // After one time constant: 1 - 1/e of the step.
        assert!((a.actual.thrust - 10.0 * (1.0 - (-1.0f64).exp())).abs() < 1e-9);
    }

    #[test]
    fn failures_stop_thrust_and_freeze_gimbal() {
        let model = ActuatorModel::default();
        let mut bank = ActuatorBank::new(model, 2);
        let cmd = [ActuatorCommand {
            eta_x: 0.1,
            eta_y: 0.2,
            thrust: 3.0,
        }; 2];
        bank.step(&cmd, 1e-3);
        bank.fail(0, FailureKind::NoThrust);
        bank.fail(1, FailureKind::StuckGimbal);
        bank.step(
            &[ActuatorCommand {
                eta_x: -0.3,
                eta_y: 0.0,
                thrust: 4.0,
            }; 2],
            1e-3,
        );
        let out = bank.actual();
        assert_eq!(
            out[0],
            ActuatorCommand {
                eta_x: -0.3,
                eta_y: 0.0,
                thrust: 0.0
            }
        );
        assert_eq!(
            out[1],
            ActuatorCommand {
                eta_x: 0.1,
                eta_y: 0.2,
                thrust: 4.0
            }
        );
        // A halved rotor delivers half of every later command, its gimbal still moving.
        let mut half = ActuatorBank::new(model, 1);
        half.fail(0, FailureKind::HalfThrust);
        half.step(&cmd[..1], 1e-3);
        assert_eq!(
            half.actual()[0],
            ActuatorCommand {
                thrust: 1.5,
                ..cmd[0]
            }
        );
        assert!(half.agents[0].failed());
    }

    #[test]
    fn limits_saturate_commands() {
        let model = ActuatorModel {
            limits: Some(SaturationLimits {
                sigma_x: 0.5,
                sigma_y: 0.6,
                max_thrust: 10.0,
            }),
            ..Default::default()
        };
        let mut a = AgentActuator::default();
        let out = a.step(
            &ActuatorCommand {
                eta_x: 1.0,
                eta_y: -1.0,
                thrust: 20.0,
            },
            &model,
            1e-3,
        );
        assert_eq!(
            out,
            ActuatorCommand {
                eta_x: 0.5,
                eta_y: -0.6,
                thrust: 10.0
            }
        );
    }
}
