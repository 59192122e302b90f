//! Integral action on the position and attitude tracking errors of eq. (12), one of the two
//! offset-free options ([`crate::OffsetFree::Integral`];
//! `docs/method.md#beyond-the-paper-offset-free-tracking`).
//!
//! The state is the integral term itself, a force in `{I}` and a torque in `{C}`:
//! `c_f <- c_f - dt K_Ix e_x`, `c_tau <- c_tau - dt K_IR e_R`, each updated through the
//! anti-windup rule ([`crate::law::anti_windup`]) and added to the requested wrench before the
//! planner and the projection. At an equilibrium of the closed loop the state is constant, so
//! `e_x = 0` and `e_R = 0` there: a constant disturbance leaves no steady error.

use nalgebra::Vector3;

use crate::foundation::error::{positive, ConfigError, ConfigField};
use crate::foundation::real::Real;
use crate::law::anti_windup::{guarded, Saturation};

/// Integral gains `K_Ix` (N/(m s), per axis of `{I}`) and `K_IR` (N m/(rad s), per axis of
/// `{C}`) and the bound on the integral torque (N m). Validated: each finite and positive.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IntegralAction<T: Real> {
    k_x: Vector3<T>,
    k_r: Vector3<T>,
    max_torque: T,
}

impl<T: Real> IntegralAction<T> {
    /// Errors: [`ConfigError::NonFinite`] or [`ConfigError::Parameter`] naming
    /// [`ConfigField::IntegralGain`] or [`ConfigField::OffsetFreeTorqueBound`].
    pub fn new(k_x: [T; 3], k_r: [T; 3], max_torque: T) -> Result<Self, ConfigError> {
        let check = |v: [T; 3]| -> Result<Vector3<T>, ConfigError> {
            let [a, b, c] = v;
            let f = ConfigField::IntegralGain;
            Ok(Vector3::new(
                positive(a, f)?,
                positive(b, f)?,
                positive(c, f)?,
            ))
        };
        Ok(Self {
            k_x: check(k_x)?,
            k_r: check(k_r)?,
            max_torque: positive(max_torque, ConfigField::OffsetFreeTorqueBound)?,
        })
    }

    /// `K_Ix` (N/(m s)).
    pub fn k_x(&self) -> Vector3<T> {
        self.k_x
    }

    /// `K_IR` (N m/(rad s)).
    pub fn k_r(&self) -> Vector3<T> {
        self.k_r
    }

    /// The bound on `||c_tau||` (N m).
    pub fn max_torque(&self) -> T {
        self.max_torque
    }
}

/// The integral terms `c_f` (N, `{I}`) and `c_tau` (N m, `{C}`), bounded by
/// `||c_f|| <= force_bound` and `||c_tau|| <= max_torque`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IntegralState<T: Real> {
    action: IntegralAction<T>,
    period: T,
    force: Vector3<T>,
    torque: Vector3<T>,
}

impl<T: Real> IntegralState<T> {
    /// Zero integral terms for a control period `dt` (validated by the caller).
    pub fn new(action: IntegralAction<T>, period: T) -> Self {
        Self {
            action,
            period,
            force: Vector3::zeros(),
            torque: Vector3::zeros(),
        }
    }

    /// The force (`{I}`) and torque (`{C}`) the integral adds to the requested wrench.
    pub fn compensation(&self) -> (Vector3<T>, Vector3<T>) {
        (self.force, self.torque)
    }

    /// Back to zero.
    pub fn reset(&mut self) {
        self.force = Vector3::zeros();
        self.torque = Vector3::zeros();
    }

    /// The integral terms of `old` (another integral's, e.g. before a reconfiguration), the
    /// torque clamped onto this action's bound.
    pub fn carry_over(&mut self, old: &Self) {
        self.force = old.force;
        self.torque = guarded(&old.torque, &old.torque, false, self.action.max_torque);
    }

    /// Clamps the force term onto a new bound (e.g. a smaller team after a failure).
    pub fn rebound(&mut self, force_bound: T) {
        self.force = guarded(&self.force, &self.force, false, force_bound);
    }

    /// One period: integrates `e_x` (m, `{I}`) and `e_R` (rad, `{C}`) of this period, under
    /// the anti-windup rule with this period's `saturation`.
    pub fn update(
        &mut self,
        e_x: &Vector3<T>,
        e_r: &Vector3<T>,
        saturation: Saturation,
        force_bound: T,
    ) {
        let dt = self.period;
        let force = self.force - self.action.k_x.component_mul(e_x) * dt;
        let torque = self.torque - self.action.k_r.component_mul(e_r) * dt;
        self.force = guarded(&self.force, &force, saturation.force, force_bound);
        self.torque = guarded(
            &self.torque,
            &torque,
            saturation.torque,
            self.action.max_torque,
        );
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    #[test]
    fn validates_gains() {
        assert_eq!(
            IntegralAction::new([1.0f64, 0.0, 1.0], [1.0; 3], 1.0),
            Err(ConfigError::Parameter {
                field: ConfigField::IntegralGain
            })
        );
        assert_eq!(
            IntegralAction::new([1.0f64; 3], [1.0; 3], f64::NAN),
            Err(ConfigError::NonFinite {
                field: ConfigField::OffsetFreeTorqueBound
            })
        );
    }

    #[test]
    fn integrates_with_the_sign_that_opposes_the_error_and_respects_bounds() {
        let action = IntegralAction::new([2.0f64; 3], [3.0; 3], 0.5).unwrap();
        let mut s = IntegralState::new(action, 0.01);
        let e_x = Vector3::new(0.1, 0.0, -0.2);
        let e_r = Vector3::new(0.0, 0.05, 0.0);
        s.update(&e_x, &e_r, Saturation::NONE, 100.0);
        let (f, t) = s.compensation();
        assert!((f - Vector3::new(-0.002, 0.0, 0.004)).norm() < 1e-15);
        assert!((t - Vector3::new(0.0, -0.0015, 0.0)).norm() < 1e-15);
        // Saturated: no growth; an error of the other sign still shrinks the state.
        let saturated = Saturation {
            force: true,
            torque: true,
        };
        s.update(&e_x, &e_r, saturated, 100.0);
        assert_eq!(s.compensation(), (f, t));
        s.update(&(-e_x), &(-e_r), saturated, 100.0);
        assert!(s.compensation().0.norm() < 1e-15);
        // Bounded by the force bound and the torque bound however long the error persists.
        for _ in 0..100_000 {
            s.update(&(e_x * 100.0), &(e_r * 100.0), Saturation::NONE, 3.0);
        }
        let (f, t) = s.compensation();
        assert!(f.norm() <= 3.0 * (1.0 + 1e-12) && t.norm() <= 0.5 * (1.0 + 1e-12));
        s.rebound(1.0);
        assert!(s.compensation().0.norm() <= 1.0 + 1e-12);
        s.reset();
        assert_eq!(s.compensation(), (Vector3::zeros(), Vector3::zeros()));
    }
}
