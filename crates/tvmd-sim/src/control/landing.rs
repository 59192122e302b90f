//! The landing reference flown after a hover-capability loss when the scenario asks for it
//! (`failure_response.on_hover_loss = "land"`): level, at the `x`, `y` where the loss was
//! classified, falling with a constant downward acceleration `a` to the rest height `z = 0`
//! (the team resting on the ground, see `tvmd_plant::physics`); once the reference is down and
//! the team is within [`TOUCHDOWN_HEIGHT`] of it, the rotors go idle (disarmed, as PX4's land
//! detector does). [`Touchdown`] disarms every commanded landing so, the scenario's own descent
//! to the ground included.
//!
//! Why an accelerating descent and not a constant rate: a team classified not hover-capable
//! has no margin at the hover wrench (A4-Inc minus one: two agents at `sigma_Tf`, one at zero),
//! and a constant-rate descent needs that same wrench, with nothing left to correct a tilt.
//! Falling at `a` asks for `m_C (g - a)` only, which leaves the working agents a margin of
//! about `a / g` to hold the attitude; the price is a touchdown at `sqrt(2 a z_0)` (no
//! deceleration, which would need more than the weight).

use nalgebra::{Matrix3, Vector3};

use tvmd_plant::reference::ReferenceSample;

/// Height (m) above the rest height under which a landed team is disarmed.
pub const TOUCHDOWN_HEIGHT: f64 = 0.05;

/// Height (m) of the fed-back centre of mass above the rest height (`z = 0`, the team resting
/// on the ground) at or under which the controller is told the team is on the ground
/// ([`tvmd_core::Controller::set_landed`]): before take-off and after touchdown. A land
/// detector on the controller's own state estimate, as a flight controller's would be; 2 cm
/// is well above the ground contact's jitter and the state noise of the scenarios.
pub const LANDED_HEIGHT: f64 = 0.02;

/// The simulated flight stack's disarm on touchdown: once the team has flown (its centre of
/// mass above [`TOUCHDOWN_HEIGHT`]), a reference that asks to be on the ground (at or under
/// [`LANDED_HEIGHT`]) and a team on the ground (at or under [`LANDED_HEIGHT`] too) disarm it
/// for the rest of the flight: the rotors idle, as PX4's land detector does.
///
/// Why: a team that reaches the ground a little ahead of its reference (any tracking lag below
/// it) would push the descent's final deceleration, more than its weight, against the ground
/// and be thrown up again; a flight stack cuts the rotors at contact.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Touchdown {
    airborne: bool,
    disarmed: bool,
}

impl Touchdown {
    /// Updates the detector with the fed-back centre of mass `position` and this tick's
    /// `reference`; returns whether the team is disarmed.
    pub fn update(&mut self, position: &Vector3<f64>, reference: &ReferenceSample) -> bool {
        self.airborne |= position.z > TOUCHDOWN_HEIGHT;
        self.disarmed |=
            self.airborne && reference.position.z <= LANDED_HEIGHT && position.z <= LANDED_HEIGHT;
        self.disarmed
    }

    /// Whether the team has been disarmed.
    pub fn disarmed(&self) -> bool {
        self.disarmed
    }
}

/// A landing started at time `start` from `from`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Landing {
    /// Time (s) the landing started.
    pub start: f64,
    /// Position (m) the landing started from.
    pub from: Vector3<f64>,
    /// Downward acceleration of the reference (m/s^2), `> 0`.
    pub acceleration: f64,
}

impl Landing {
    /// A landing from `position` at time `t`.
    pub fn start(t: f64, position: &Vector3<f64>, acceleration: f64) -> Self {
        Self {
            start: t,
            from: *position,
            acceleration,
        }
    }

    /// Time (s) the reference reaches `z = 0`: `start + sqrt(2 z_0 / a)`.
    pub fn touchdown_time(&self) -> f64 {
        self.start + (2.0 * self.from.z.max(0.0) / self.acceleration).sqrt()
    }

    /// The reference's speed at touchdown (m/s), `sqrt(2 a z_0)`.
    pub fn touchdown_speed(&self) -> f64 {
        (2.0 * self.acceleration * self.from.z.max(0.0)).sqrt()
    }

    /// The reference at time `t`: level, at the start's `x`, `y`, with
    /// `z = z_0 - a tau^2 / 2` (`tau = t - start`) and its velocity and acceleration as
    /// feed-forward until `z = 0`; then at rest at `z = 0`.
    pub fn reference(&self, t: f64) -> ReferenceSample {
        let tau = (t - self.start).max(0.0);
        let falling = t < self.touchdown_time();
        let a = self.acceleration;
        let (z, vz, az) = if falling {
            (self.from.z - 0.5 * a * tau * tau, -a * tau, -a)
        } else {
            (0.0, 0.0, 0.0)
        };
        ReferenceSample {
            t,
            position: Vector3::new(self.from.x, self.from.y, z),
            velocity: Vector3::new(0.0, 0.0, vz),
            acceleration: Vector3::new(0.0, 0.0, az),
            rotation: Matrix3::identity(),
            omega: Vector3::zeros(),
            omega_dot: Vector3::zeros(),
            roll: 0.0,
            roll_rate: 0.0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn falls_level_to_rest_height_and_holds() {
        let l = Landing::start(5.0, &Vector3::new(0.1, -0.2, 2.0), 1.0);
        assert_eq!(l.touchdown_time(), 7.0);
        assert_eq!(l.touchdown_speed(), 2.0);
        let mid = l.reference(6.0);
        assert_eq!(mid.position, Vector3::new(0.1, -0.2, 1.5));
        assert_eq!((mid.velocity.z, mid.acceleration.z), (-1.0, -1.0));
        assert_eq!(mid.rotation, Matrix3::identity());
        let after = l.reference(8.0);
        assert_eq!(after.position.z, 0.0);
        assert_eq!(after.velocity, Vector3::zeros());
        let mut detector = Touchdown::default();
        let ground = Vector3::new(0.0, 0.0, 0.01);
        assert!(!detector.update(&ground, &after), "not flown yet");
        assert!(!detector.update(&Vector3::new(0.0, 0.0, 1.0), &mid));
        assert!(
            !detector.update(&ground, &l.reference(6.9)),
            "reference still 0.2 m high"
        );
        assert!(
            !detector.update(&Vector3::new(0.0, 0.0, 0.03), &after),
            "not down yet"
        );
        assert!(detector.update(&ground, &after));
        assert!(
            detector.update(&Vector3::new(0.0, 0.0, 0.3), &mid),
            "disarmed for good"
        );
    }
}
