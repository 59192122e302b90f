//! The plant's saturation: the hardware's range applied to every command the plant holds.
//!
//! A gimbal turns no further than its limit and a rotor spins between rest and its largest
//! speed, so its thrust lies in `[0, sigma_Tf]` and never points down its axis. Whatever a
//! step is given (the tvmd controller's commands, a user's own, a PIL target's), the plant
//! holds each command clamped to `|eta_x| <= sigma_x`, `|eta_y| <= sigma_y`,
//! `0 <= T <= sigma_Tf` (the scenario's `[limits]`) and reports by how much it clamped it.
//! The tvmd controller's commands are inside this set: for them nothing changes.

use tvmd_plant::actuators::{ActuatorCommand, SaturationLimits};
use tvmd_scenario::Scenario;

use crate::SimError;

/// The hardware's command range and what it took off the last step's commands.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct PlantSaturation {
    limits: SaturationLimits,
    /// Per agent, the last held command minus its saturated value (zero: inside the range).
    clamped: Vec<ActuatorCommand>,
}

/// `x` or its f32 rounding, whichever is larger: an f32 controller commands its own rounding
/// of a limit, which is the same hardware limit (never clamped by the f64 plant).
fn with_f32_rounding(x: f64) -> f64 {
    x.max(f64::from(x as f32))
}

impl PlantSaturation {
    /// The range of `scenario`'s agents (its `[limits]`), nothing clamped yet.
    pub(super) fn new(scenario: &Scenario, agents: usize) -> Result<Self, SimError> {
        let l = scenario.actuator_limits()?;
        Ok(Self {
            limits: SaturationLimits {
                sigma_x: with_f32_rounding(l.sigma_x),
                sigma_y: with_f32_rounding(l.sigma_y),
                max_thrust: with_f32_rounding(l.max_thrust),
            },
            clamped: vec![ActuatorCommand::default(); agents],
        })
    }

    /// Writes `commands`, saturated, over `held` and records what was clamped.
    pub(super) fn apply(&mut self, commands: &[ActuatorCommand], held: &mut Vec<ActuatorCommand>) {
        held.clear();
        self.clamped.clear();
        for c in commands {
            let s = self.limits.saturate(c);
            held.push(s);
            self.clamped.push(ActuatorCommand {
                eta_x: c.eta_x - s.eta_x,
                eta_y: c.eta_y - s.eta_y,
                thrust: c.thrust - s.thrust,
            });
        }
    }

    /// Per agent, the last step's command minus what the plant held (rad, rad, N).
    pub(super) fn clamped(&self) -> &[ActuatorCommand] {
        &self.clamped
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn commands_outside_the_range_are_clamped_and_reported() {
        let scenario = Scenario::builtin("hover").expect("hover");
        let mut s = PlantSaturation::new(&scenario, 2).expect("limits");
        let max = scenario.max_thrust().expect("max thrust");
        let inside = ActuatorCommand {
            eta_x: 0.1,
            eta_y: -0.2,
            thrust: 0.5 * max,
        };
        let outside = ActuatorCommand {
            eta_x: 2.0,
            eta_y: -2.0,
            thrust: -5.0,
        };
        let mut held = Vec::new();
        s.apply(&[inside, outside], &mut held);
        assert_eq!(held[0], inside);
        assert_eq!(s.clamped()[0], ActuatorCommand::default());
        assert_eq!(
            held[1].eta_x,
            scenario
                .limits
                .sigma_x
                .max(f64::from(scenario.limits.sigma_x as f32))
        );
        assert!(held[1].eta_y < 0.0 && held[1].eta_y >= -0.8);
        assert_eq!(held[1].thrust, 0.0);
        assert_eq!(s.clamped()[1].thrust, -5.0);
        s.apply(
            &[
                outside,
                ActuatorCommand {
                    thrust: 3.0 * max,
                    ..inside
                },
            ],
            &mut held,
        );
        assert!((held[1].thrust - max).abs() <= 1e-6 * max);
        assert!((s.clamped()[1].thrust - 2.0 * max).abs() <= 1e-6 * max);
    }
}
