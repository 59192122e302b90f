//! What every flight of a Monte Carlo study meets besides its draw: servo dynamics, noise on
//! the fed-back state and a feedback latency (`docs/method.md`, "Monte Carlo"). On by default,
//! so that a study's success rate is not that of a noise-free, delay-free, ideal-servo plant.

use serde::{Deserialize, Serialize};

use tvmd_plant::actuators::ServoModel;
use tvmd_scenario::{Scenario, StateNoise};

/// The flight conditions of a study. Each fills in only what the base scenario leaves unset
/// (no servo model, no state noise, zero latency), so a scenario's own stay as they are.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Conditions {
    /// Gimbal servo dynamics; 40 rad/s, damping 0.8, 6 rad/s rate limit.
    pub servo: Option<ServoModel>,
    /// Noise on the fed-back state (standard deviations; the seed is replaced by one drawn
    /// from the study's seed and the flight's index); 1 mm, 1 cm/s, 2 mrad, 0.01 rad/s.
    pub state_noise: Option<StateNoise>,
    /// Feedback latency (controller periods); 1.
    pub feedback_latency: u32,
}

impl Default for Conditions {
    fn default() -> Self {
        Self {
            servo: Some(ServoModel {
                natural_frequency: 40.0,
                damping_ratio: 0.8,
                rate_limit: 6.0,
            }),
            state_noise: Some(StateNoise {
                position: 0.001,
                velocity: 0.01,
                attitude: 0.002,
                angular_velocity: 0.01,
                seed: 0,
            }),
            feedback_latency: 1,
        }
    }
}

impl Conditions {
    /// No servo model, no noise, no latency: the scenario as it is.
    pub fn none() -> Self {
        Self {
            servo: None,
            state_noise: None,
            feedback_latency: 0,
        }
    }

    /// Fills in what `scenario` leaves unset; the noise of flight `index` of the study seeded
    /// `seed` gets a seed of its own.
    pub fn apply(&self, scenario: &mut Scenario, seed: u64, index: u64) {
        if scenario.actuators.servo.is_none() {
            scenario.actuators.servo = self.servo;
        }
        if scenario.disturbances.state_noise.is_none() {
            scenario.disturbances.state_noise = self.state_noise.map(|n| StateNoise {
                // splitmix64's increment: distinct, well-spread seeds per (seed, index).
                seed: seed
                    .wrapping_mul(0x9E37_79B9_7F4A_7C15)
                    .wrapping_add(index)
                    .rotate_left(17),
                ..n
            });
        }
        if scenario.disturbances.feedback_latency == 0 {
            scenario.disturbances.feedback_latency = self.feedback_latency;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fills_in_only_what_the_scenario_leaves_unset() {
        let mut s = Scenario::builtin("hover").unwrap();
        Conditions::default().apply(&mut s, 3, 0);
        assert!(s.actuators.servo.is_some());
        assert_eq!(s.disturbances.feedback_latency, 1);
        let a = s.disturbances.state_noise.unwrap();
        let mut t = Scenario::builtin("hover").unwrap();
        Conditions::default().apply(&mut t, 3, 1);
        assert_ne!(a.seed, t.disturbances.state_noise.unwrap().seed);
        // A scenario's own latency stays.
        let mut own = Scenario::builtin("paper-experiment").unwrap();
        own.disturbances.feedback_latency = 3;
        Conditions::default().apply(&mut own, 3, 0);
        assert_eq!(own.disturbances.feedback_latency, 3);
        let mut bare = Scenario::builtin("hover").unwrap();
        Conditions::none().apply(&mut bare, 3, 0);
        assert_eq!(bare, Scenario::builtin("hover").unwrap());
    }
}
