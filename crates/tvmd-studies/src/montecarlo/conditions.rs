//! What every flight of a Monte Carlo study meets besides its draw: servo dynamics, noise on
//! the fed-back state and a feedback latency (`docs/method.md`, "Monte Carlo"), on by default
//! so that a study's success rate is not that of a noise-free, delay-free, ideal-servo plant;
//! and, when asked for, turbulence, a discrete gust and the agents' command links, each seeded
//! per flight.

use serde::{Deserialize, Serialize};

use tvmd_plant::actuators::ServoModel;
use tvmd_plant::turbulence::Turbulence;
use tvmd_scenario::{Air, CommandLinks, Gust, Scenario, StateNoise};

/// A `1 - cos` gust every flight meets, of a stated peak speed and length, horizontal, its
/// heading and start drawn per flight (the start in the middle half of the flight).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GustCondition {
    /// Peak air speed of the gust (m/s).
    pub speed: f64,
    /// Length of the gust (s).
    pub duration: f64,
}

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
    /// Dryden turbulence ([`Turbulence`]; its seed is replaced by one per flight); none by
    /// default. A scenario with no air gets the standard's mean wind at the turbulence's
    /// altitude, along a heading drawn per flight; a scenario's own air keeps its wind.
    #[serde(default)]
    pub turbulence: Option<Turbulence>,
    /// A discrete gust per flight; none by default.
    #[serde(default)]
    pub gust: Option<GustCondition>,
    /// Every agent's command link ([`CommandLinks`]; its seed is replaced by one per flight);
    /// none by default. A scenario's own `[links]` stay.
    #[serde(default)]
    pub links: Option<CommandLinks>,
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
            turbulence: None,
            gust: None,
            links: None,
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
            turbulence: None,
            gust: None,
            links: None,
        }
    }

    /// Fills in what `scenario` leaves unset; the noise, turbulence and gust of flight `index`
    /// of the study seeded `seed` get draws of their own.
    pub fn apply(&self, scenario: &mut Scenario, seed: u64, index: u64) {
        let flight_seed = |stream: u64| {
            // splitmix64's increment: distinct, well-spread seeds per (seed, index, stream).
            seed.wrapping_mul(0x9E37_79B9_7F4A_7C15)
                .wrapping_add(index)
                .rotate_left(17)
                .wrapping_add(stream.wrapping_mul(0xD1B5_4A32_D192_ED03))
        };
        // A uniform number in [0, 1) from a seed (splitmix64's finalizer).
        let unit = |z: u64| {
            let z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            let z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
        };
        if let Some(t) = self.turbulence {
            let t = Turbulence {
                seed: flight_seed(1),
                ..t
            };
            let air = scenario.disturbances.air.get_or_insert_with(|| {
                let heading = std::f64::consts::TAU * unit(flight_seed(2));
                let u = t.mean_wind_speed();
                Air {
                    velocity: [u * heading.cos(), u * heading.sin(), 0.0],
                    ..Air::default()
                }
            });
            if air.turbulence.is_none() {
                air.turbulence = Some(t);
            }
        }
        if let Some(g) = self.gust {
            let heading = std::f64::consts::TAU * unit(flight_seed(3));
            let start = scenario.duration * (0.25 + 0.5 * unit(flight_seed(4)));
            let air = scenario.disturbances.air.get_or_insert_with(Air::default);
            air.gusts.push(Gust {
                start,
                duration: g.duration,
                velocity: [g.speed * heading.cos(), g.speed * heading.sin(), 0.0],
            });
        }
        if scenario.actuators.servo.is_none() {
            scenario.actuators.servo = self.servo;
        }
        if scenario.disturbances.state_noise.is_none() {
            scenario.disturbances.state_noise = self.state_noise.map(|n| StateNoise {
                seed: flight_seed(0),
                ..n
            });
        }
        if scenario.disturbances.feedback_latency == 0 {
            scenario.disturbances.feedback_latency = self.feedback_latency;
        }
        if scenario.links.is_none() {
            scenario.links = self.links.map(|l| CommandLinks {
                seed: flight_seed(5),
                ..l
            });
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

    #[test]
    fn turbulence_and_gusts_are_drawn_per_flight() {
        let weather = Conditions {
            turbulence: Some(Turbulence::standard(8.0, 1.5)),
            gust: Some(GustCondition {
                speed: 3.0,
                duration: 2.0,
            }),
            ..Conditions::none()
        };
        let flown = |index| {
            let mut s = Scenario::builtin("hover").unwrap();
            weather.apply(&mut s, 3, index);
            s.validate().unwrap();
            s.disturbances.air.unwrap()
        };
        let (a, b) = (flown(0), flown(1));
        let (ta, tb) = (a.turbulence.unwrap(), b.turbulence.unwrap());
        assert_ne!(ta.seed, tb.seed);
        // The standard's mean wind, along a heading of each flight's own.
        let speed = |v: [f64; 3]| v[0].hypot(v[1]);
        assert!((speed(a.velocity) - ta.mean_wind_speed()).abs() < 1e-12);
        assert_ne!(a.velocity, b.velocity);
        let (ga, gb) = (a.gusts[0], b.gusts[0]);
        assert!((speed(ga.velocity) - 3.0).abs() < 1e-12 && ga.duration == 2.0);
        assert!(ga.start >= 3.0 && ga.start <= 9.0 && ga.start != gb.start);
        // A scenario's own wind stays; the turbulence rides on it.
        let mut wind = Scenario::builtin("wind").unwrap();
        weather.apply(&mut wind, 3, 0);
        let air = wind.disturbances.air.unwrap();
        assert_eq!(air.velocity, [1.0, 0.0, 0.0]);
        assert!(air.turbulence.is_some() && air.gusts.len() == 2);
    }

    #[test]
    fn links_are_drawn_per_flight_and_a_scenarios_own_stay() {
        let lossy = Conditions {
            links: Some(CommandLinks {
                latency: 0.02,
                loss: 0.1,
                ..CommandLinks::default()
            }),
            ..Conditions::none()
        };
        let flown = |index| {
            let mut s = Scenario::builtin("hover").unwrap();
            lossy.apply(&mut s, 3, index);
            s.validate().unwrap();
            s.links.unwrap()
        };
        let (a, b) = (flown(0), flown(1));
        assert_eq!((a.latency, a.loss), (0.02, 0.1));
        assert_ne!(a.seed, b.seed);
        let mut own = Scenario::builtin("hover").unwrap();
        own.links = Some(CommandLinks::default());
        lossy.apply(&mut own, 3, 0);
        assert_eq!(own.links, Some(CommandLinks::default()));
    }
}
