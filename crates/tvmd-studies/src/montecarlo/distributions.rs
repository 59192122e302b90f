//! The distributions a Monte Carlo study draws each flight's model error and initial
//! conditions from (`docs/method.md`, "Monte Carlo"), and one flight's draw.

use std::f64::consts::PI;

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use super::conditions::Conditions;
use crate::StudyError;
use tvmd_scenario::{PlantError, Scenario};

/// Uniform distributions of the model error and the initial conditions. Every model-error
/// half-width is multiplied by `model_error`, so one number sweeps the study from the nominal
/// plant (0) outwards.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Distributions {
    /// Multiplier of every model-error half-width below; 1.
    pub model_error: f64,
    /// Plant mass over the model's: `U[1 - e, 1 + e]`; e = 0.02.
    pub mass: f64,
    /// Plant inertia over the model's: `U[1 - e, 1 + e]`; e = 0.1.
    pub inertia: f64,
    /// Centre-of-mass offset, each axis `U[-e, e]` (m); e = 0.01.
    pub com_offset: f64,
    /// Each agent's thrust efficiency: `U[1 - e, 1]`; e = 0.02.
    pub thrust_efficiency: f64,
    /// Each agent's gimbal offsets, each axis `U[-e, e]` (rad); e = 0.01.
    pub gimbal_offset: f64,
    /// Initial horizontal position offset, each axis `U[-e, e]` (m); e = 0.1. Not scaled by
    /// `model_error`.
    pub initial_position: f64,
    /// Initial tilt: an angle `U[0, e]` about a horizontal axis of uniform direction (rad);
    /// e = 0 (a scenario that starts on the ground cannot start tilted). Not scaled by
    /// `model_error`.
    pub initial_tilt: f64,
    /// The flight conditions every flight meets ([`Conditions`]): servo dynamics, state
    /// noise and one period of latency by default.
    pub conditions: Conditions,
}

impl Default for Distributions {
    fn default() -> Self {
        Self {
            model_error: 1.0,
            mass: 0.02,
            inertia: 0.1,
            com_offset: 0.01,
            thrust_efficiency: 0.02,
            gimbal_offset: 0.01,
            initial_position: 0.1,
            initial_tilt: 0.0,
            conditions: Conditions::default(),
        }
    }
}

impl Distributions {
    /// Checks the half-widths: finite, non-negative, and small enough that every draw is a
    /// valid scenario (mass and inertia above zero, efficiency in `[0, 1]`, tilt at most
    /// 2.5 rad).
    pub fn validate(&self) -> Result<(), StudyError> {
        let bad = |name: &str, reason: String| StudyError::InvalidArgument {
            name: format!("distributions.{name}"),
            reason,
        };
        for (name, v) in [
            ("model_error", self.model_error),
            ("mass", self.mass),
            ("inertia", self.inertia),
            ("com_offset", self.com_offset),
            ("thrust_efficiency", self.thrust_efficiency),
            ("gimbal_offset", self.gimbal_offset),
            ("initial_position", self.initial_position),
            ("initial_tilt", self.initial_tilt),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(bad(name, format!("must be finite and >= 0, got {v}")));
            }
        }
        let k = self.model_error;
        for (name, width, limit) in [
            ("mass", self.mass * k, 0.9),
            ("inertia", self.inertia * k, 0.9),
            ("thrust_efficiency", self.thrust_efficiency * k, 1.0),
            ("com_offset", self.com_offset * k, 1.0),
            ("gimbal_offset", self.gimbal_offset * k, 0.5),
            ("initial_tilt", self.initial_tilt, 2.5),
        ] {
            if width > limit {
                return Err(bad(
                    name,
                    format!("half-width {width} (with model_error = {k}) above {limit}"),
                ));
            }
        }
        Ok(())
    }
}

/// What one flight drew.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Draw {
    /// The plant's model error.
    pub plant: PlantError,
    /// Initial horizontal offset (m).
    pub initial_offset: [f64; 2],
    /// Initial tilt angle (rad) and the heading of its axis (rad).
    pub initial_tilt: [f64; 2],
}

impl Draw {
    /// Flight `index` of the study seeded `seed` for a team of `n` agents: the same draw on
    /// any machine, in any order, and (up to the per-agent values) for every team, so teams
    /// and allocators meet the same errors. The scalars are drawn first, then per agent.
    pub fn new(d: &Distributions, seed: u64, index: u64, n: usize) -> Self {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        rng.set_stream(index);
        let k = d.model_error;
        let mut sym = |e: f64| {
            if e > 0.0 {
                rng.random_range(-e..=e)
            } else {
                0.0
            }
        };
        let mass_scale = 1.0 + sym(d.mass * k);
        let inertia_scale = 1.0 + sym(d.inertia * k);
        let com_offset = [
            sym(d.com_offset * k),
            sym(d.com_offset * k),
            sym(d.com_offset * k),
        ];
        let initial_offset = [sym(d.initial_position), sym(d.initial_position)];
        let tilt = sym(d.initial_tilt).abs();
        let heading = sym(PI);
        let mut agents = Vec::with_capacity(n);
        for _ in 0..n {
            let eff = 1.0 - sym(d.thrust_efficiency * k).abs();
            let gimbal = [sym(d.gimbal_offset * k), sym(d.gimbal_offset * k)];
            agents.push((eff, gimbal));
        }
        let (eff, gimbal): (Vec<f64>, Vec<[f64; 2]>) = agents.into_iter().unzip();
        let actuation = d.thrust_efficiency * k > 0.0 || d.gimbal_offset * k > 0.0;
        Self {
            plant: PlantError {
                mass_scale,
                inertia_scale,
                com_offset,
                thrust_efficiency: if actuation { eff } else { Vec::new() },
                gimbal_offsets: if actuation { gimbal } else { Vec::new() },
            },
            initial_offset,
            initial_tilt: [tilt, heading],
        }
    }

    /// `base` with this draw applied: the plant error replaces the base's, the offset and the
    /// tilt add to its initial position and attitude; validated.
    pub fn apply(&self, base: &Scenario) -> Result<Scenario, StudyError> {
        let mut s = base.clone();
        s.plant = self.plant.clone();
        s.initial_position[0] += self.initial_offset[0];
        s.initial_position[1] += self.initial_offset[1];
        let [tilt, heading] = self.initial_tilt;
        if tilt > 0.0 {
            let axis = nalgebra::Vector3::new(heading.cos(), heading.sin(), 0.0);
            let r =
                nalgebra::Rotation3::from_axis_angle(&nalgebra::Unit::new_normalize(axis), tilt)
                    * nalgebra::Rotation3::from_matrix_unchecked(
                        tvmd_plant::math::from_roll_pitch_yaw(s.initial_attitude),
                    );
            s.initial_attitude = tvmd_plant::math::roll_pitch_yaw(r.matrix());
        }
        s.validate()?;
        Ok(s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn draws_are_reproducible_independent_and_inside_their_ranges() {
        let d = Distributions {
            initial_tilt: 1.0,
            ..Distributions::default()
        };
        let a = Draw::new(&d, 7, 3, 4);
        assert_eq!(a, Draw::new(&d, 7, 3, 4));
        assert_ne!(a, Draw::new(&d, 7, 4, 4));
        assert_ne!(a, Draw::new(&d, 8, 3, 4));
        // The scalars do not depend on the team's size.
        let six = Draw::new(&d, 7, 3, 6);
        assert_eq!(six.plant.mass_scale, a.plant.mass_scale);
        assert_eq!(six.initial_tilt, a.initial_tilt);
        for i in 0..200 {
            let x = Draw::new(&d, 1, i, 4);
            assert!((x.plant.mass_scale - 1.0).abs() <= 0.02);
            assert!((x.plant.inertia_scale - 1.0).abs() <= 0.1);
            assert!(x.plant.com_offset.iter().all(|c| c.abs() <= 0.01));
            assert!(x
                .plant
                .thrust_efficiency
                .iter()
                .all(|e| (0.98..=1.0).contains(e)));
            assert!(x
                .plant
                .gimbal_offsets
                .iter()
                .flatten()
                .all(|g| g.abs() <= 0.01));
            assert!(x.initial_tilt[0] <= 1.0 && x.initial_offset.iter().all(|o| o.abs() <= 0.1));
        }
        // model_error = 0: the nominal plant.
        let nominal = Draw::new(
            &Distributions {
                model_error: 0.0,
                ..d
            },
            1,
            0,
            4,
        );
        assert!(nominal.plant.is_nominal(), "{nominal:?}");
    }

    #[test]
    fn a_draw_applies_to_a_scenario_and_bad_widths_are_refused() {
        let base = Scenario::builtin("hover").unwrap();
        let d = Distributions {
            initial_tilt: 0.5,
            ..Distributions::default()
        };
        let x = Draw::new(&d, 2, 0, 4);
        let s = x.apply(&base).unwrap();
        assert_eq!(s.plant, x.plant);
        let r = tvmd_plant::math::from_roll_pitch_yaw(s.initial_attitude);
        assert!((tvmd_plant::math::tilt_angle(&r) - x.initial_tilt[0]).abs() < 1e-9);
        // A ground start cannot be tilted: the draw's scenario is refused, naming the field.
        let e = x
            .apply(&Scenario::builtin("paper-tilt").unwrap())
            .unwrap_err();
        assert!(e.to_string().contains("initial_attitude"), "{e}");
        for bad in [
            Distributions {
                mass: -0.1,
                ..Distributions::default()
            },
            Distributions {
                model_error: 100.0,
                ..Distributions::default()
            },
            Distributions {
                initial_tilt: 3.0,
                ..Distributions::default()
            },
            Distributions {
                gimbal_offset: f64::NAN,
                ..Distributions::default()
            },
        ] {
            assert!(bad.validate().is_err(), "{bad:?}");
        }
        Distributions::default().validate().unwrap();
    }
}
