//! Offset-free tracking beyond the paper: an estimate of the unmodelled wrench
//! ([`DisturbanceObserver`]) or an integral of the tracking errors ([`IntegralAction`]), added
//! to the requested wrench before the planner and the force projection (eqs. 9-13), with
//! anti-windup and a landed hold (`docs/method.md#beyond-the-paper-offset-free-tracking`).

use nalgebra::{Vector3, Vector6};

use core::mem::align_of;
use core::ptr::addr_of;

use crate::foundation::real::Real;
use crate::foundation::stored::{bool_intact, tag_below};
use crate::law::anti_windup::Saturation;
use crate::law::disturbance::{DisturbanceObserver, ObserverState};
use crate::law::integral::{IntegralAction, IntegralState};
use crate::law::{Plant, RigidState};

/// Which offset-free action the controller runs (`None` in
/// [`crate::ControllerSettings::offset_free`]: the paper's law, no state). `repr(u8)`: the
/// tag first, checked raw by [`crate::Controller::storage_intact`].
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(u8)]
pub enum OffsetFree<T: Real> {
    /// The disturbance observer (the recommended one: `docs/method.md`).
    Observer(DisturbanceObserver<T>),
    /// Integral action on `e_x` and `e_R`.
    Integral(IntegralAction<T>),
}

/// The wrench the offset-free state adds to the request this period.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Compensation<T: Real> {
    /// Force (N) in `{I}`; the request adds `R^T force` to `u_fr`.
    pub force: Vector3<T>,
    /// Torque (N m) in `{C}`, added to `u_tau_r`.
    pub torque: Vector3<T>,
}

/// `repr(u8)`: the tag first, checked raw ([`OffsetFreeState::storage_intact`]).
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(u8)]
enum Kind<T: Real> {
    Off,
    Observer(ObserverState<T>),
    Integral(IntegralState<T>),
}

/// The offset-free state of a controller: the estimator or integral, the force bound (the
/// AFS's capacity `n sigma_Tf` of the working agents) and the landed hold.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OffsetFreeState<T: Real> {
    kind: Kind<T>,
    force_bound: T,
    landed: bool,
}

impl<T: Real> OffsetFreeState<T> {
    /// The state for `settings` (off for `None`), a control period `dt` (validated by the
    /// caller) and a force bound (N, finite and non-negative).
    pub fn new(settings: Option<&OffsetFree<T>>, period: T, force_bound: T) -> Self {
        let kind = match settings {
            None => Kind::Off,
            Some(OffsetFree::Observer(o)) => Kind::Observer(ObserverState::new(*o, period)),
            Some(OffsetFree::Integral(i)) => Kind::Integral(IntegralState::new(*i, period)),
        };
        Self {
            kind,
            force_bound,
            landed: false,
        }
    }

    /// Whether an offset-free action is configured.
    pub fn is_on(&self) -> bool {
        !matches!(self.kind, Kind::Off)
    }

    /// Whether the landed hold is on ([`Self::set_landed`]).
    pub fn landed(&self) -> bool {
        self.landed
    }

    /// The force bound (N).
    pub fn force_bound(&self) -> T {
        self.force_bound
    }

    /// The wrench to add to this period's request (zero when off or landed).
    pub fn compensation(&self) -> Compensation<T> {
        let (force, torque) = match &self.kind {
            _ if self.landed => (Vector3::zeros(), Vector3::zeros()),
            Kind::Off => (Vector3::zeros(), Vector3::zeros()),
            Kind::Observer(o) => o.compensation(),
            Kind::Integral(i) => i.compensation(),
        };
        Compensation { force, torque }
    }

    /// The disturbance observer's raw measurement of this period (`(d_f,meas, d_tau,meas)`,
    /// `{I}`, `{C}`; [`ObserverState::measurement`]): the wrench the team did not deliver as
    /// commanded, which the fault detector filters into its residual. `None` without an
    /// observer, when landed, or when this period measured nothing.
    pub fn observer_measurement(&self) -> Option<(Vector3<T>, Vector3<T>)> {
        match &self.kind {
            Kind::Observer(o) if !self.landed => o.measurement(),
            _ => None,
        }
    }

    /// The disturbance observer's filter gains `(gamma_f, gamma_tau)`
    /// ([`ObserverState::gains`]); `None` without an observer.
    pub fn observer_gains(&self) -> Option<(T, T)> {
        match &self.kind {
            Kind::Observer(o) => Some(o.gains()),
            _ => None,
        }
    }

    /// As [`Self::reset`], with the observer's estimates then set to `(force, torque)` (`{I}`,
    /// `{C}`; [`ObserverState::reseed`]): what the caller knows the unmodelled wrench to be.
    pub fn reseed(&mut self, force: Vector3<T>, torque: Vector3<T>) {
        self.reset();
        if let Kind::Observer(o) = &mut self.kind {
            o.reseed(force, torque);
        }
    }

    /// Clears the state (zero estimate or integral, no observer sample); the landed flag,
    /// which is the caller's input, is kept.
    pub fn reset(&mut self) {
        match &mut self.kind {
            Kind::Off => {}
            Kind::Observer(o) => o.reset(),
            Kind::Integral(i) => i.reset(),
        }
    }

    /// The landed hold: while `true` the state is cleared and held at zero (ground contact is
    /// not a disturbance to compensate, and nothing integrates on the ground); on `false` it
    /// starts again from zero.
    pub fn set_landed(&mut self, landed: bool) {
        if landed {
            self.reset();
        }
        self.landed = landed;
    }

    /// Carries the landed flag and the estimate (or integral) of `old` into this state when
    /// both run the same kind of action (a reconfiguration while flying), clamped onto this
    /// state's bounds; another kind starts from zero.
    pub fn carry_over(&mut self, old: &Self) {
        self.landed = old.landed;
        match (&mut self.kind, &old.kind) {
            (Kind::Observer(new), Kind::Observer(old)) => new.carry_over(old),
            (Kind::Integral(new), Kind::Integral(old)) => new.carry_over(old),
            _ => {}
        }
        let bound = self.force_bound;
        self.set_force_bound(bound);
    }

    /// A new force bound (a failure changed the team's capacity): the force part is clamped
    /// onto it, the rest kept.
    pub fn set_force_bound(&mut self, force_bound: T) {
        self.force_bound = force_bound;
        match &mut self.kind {
            Kind::Off => {}
            Kind::Observer(o) => o.rebound(force_bound),
            Kind::Integral(i) => i.rebound(force_bound),
        }
    }

    /// Start of a period: the observer measures the last period (nothing for the integral, or
    /// when landed).
    pub fn begin(&mut self, plant: &Plant<T>, state: &RigidState<T>) {
        if self.landed {
            return;
        }
        if let Kind::Observer(o) = &mut self.kind {
            o.measure(plant, state, self.force_bound);
        }
    }

    /// End of a period whose commands were sent: the integral integrates `e_x`, `e_R`; the
    /// observer records the state and the allocated wrench. Nothing when landed.
    pub fn end(&mut self, plant: &Plant<T>, state: &RigidState<T>, cycle: &CycleRecord<T>) {
        if self.landed {
            return;
        }
        match &mut self.kind {
            Kind::Off => {}
            Kind::Observer(o) => o.record(plant, state, &cycle.wrench, cycle.saturation),
            Kind::Integral(i) => {
                i.update(&cycle.e_x, &cycle.e_r, cycle.saturation, self.force_bound)
            }
        }
    }
}

/// What [`OffsetFreeState::end`] needs of a period.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CycleRecord<T: Real> {
    /// `e_x` (m, `{I}`).
    pub e_x: Vector3<T>,
    /// `e_R` (rad, `{C}`).
    pub e_r: Vector3<T>,
    /// The allocated wrench `M f` (`{C}`).
    pub wrench: Vector6<T>,
    /// What the team could not deliver this period.
    pub saturation: Saturation,
}

impl<T: Real> OffsetFree<T> {
    /// Whether the action at `this` has one of the two tags (its values are numbers).
    ///
    /// # Safety
    /// `this` is aligned and points to `size_of::<Self>()` readable bytes.
    pub(crate) unsafe fn storage_intact(this: *const Self) -> bool {
        tag_below(this, 2)
    }
}

impl<T: Real> OffsetFreeState<T> {
    /// Whether the state at `this` holds valid tags: the kind's, the observer's inside
    /// ([`ObserverState::storage_intact`]) and the landed flag. Reads only.
    ///
    /// # Safety
    /// `this` is aligned and points to `size_of::<Self>()` readable bytes.
    pub(crate) unsafe fn storage_intact(this: *const Self) -> bool {
        let kind = addr_of!((*this).kind);
        let intact = match kind.cast::<u8>().read() {
            0 | 2 => true,
            // `repr(u8)`: the variant is a `repr(C)` struct of the tag and the state.
            1 => ObserverState::storage_intact(
                kind.cast::<u8>()
                    .add(align_of::<ObserverState<T>>())
                    .cast::<ObserverState<T>>(),
            ),
            _ => false,
        };
        intact && bool_intact(addr_of!((*this).landed))
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use nalgebra::Matrix3;

    fn record(e: f64) -> CycleRecord<f64> {
        CycleRecord {
            e_x: Vector3::new(e, 0.0, 0.0),
            e_r: Vector3::new(0.0, e, 0.0),
            wrench: Vector6::zeros(),
            saturation: Saturation::NONE,
        }
    }

    #[test]
    fn off_is_inert_and_landed_holds_zero() {
        let plant = Plant::new(2.0, Matrix3::identity(), 9.81).unwrap();
        let state = RigidState::at_rest(Vector3::zeros());
        let mut off = OffsetFreeState::<f64>::new(None, 0.01, 50.0);
        off.begin(&plant, &state);
        off.end(&plant, &state, &record(1.0));
        assert!(!off.is_on());
        assert_eq!(off.compensation(), Compensation::default());

        let action = IntegralAction::new([1.0; 3], [1.0; 3], 1.0).unwrap();
        let mut s = OffsetFreeState::new(Some(&OffsetFree::Integral(action)), 0.01, 50.0);
        s.end(&plant, &state, &record(1.0));
        assert!(s.compensation().force.x < 0.0);
        s.set_landed(true);
        assert_eq!(s.compensation(), Compensation::default());
        for _ in 0..100 {
            s.begin(&plant, &state);
            s.end(&plant, &state, &record(1.0));
        }
        s.set_landed(false);
        assert_eq!(s.compensation(), Compensation::default());
        s.end(&plant, &state, &record(1.0));
        assert!((s.compensation().force.x + 0.01).abs() < 1e-15);
        // A smaller capacity clamps the kept state.
        for _ in 0..10_000 {
            s.end(&plant, &state, &record(1.0));
        }
        assert!((s.compensation().force.norm() - 50.0).abs() < 1e-9);
        s.set_force_bound(10.0);
        assert!(s.compensation().force.norm() <= 10.0 * (1.0 + 1e-12));
        s.reset();
        assert_eq!(s.compensation(), Compensation::default());
    }
}

#[cfg(test)]
mod storage_tests {
    #![allow(clippy::unwrap_used, clippy::unreachable)]
    use super::*;
    use crate::foundation::stored::{accepts, refuses};
    use core::ptr::addr_of_mut;

    #[test]
    fn an_invalid_kind_observer_or_landed_flag_is_refused() {
        let observer = DisturbanceObserver::new(10.0_f32, 10.0, 5.0).unwrap();
        let check = OffsetFreeState::<f32>::storage_intact;
        let off = OffsetFreeState::<f32>::new(None, 0.01, 10.0);
        let on = OffsetFreeState::new(Some(&OffsetFree::Observer(observer)), 0.01, 10.0);
        let integral = IntegralAction::new([1.0; 3], [1.0; 3], 5.0).unwrap();
        let integral = OffsetFreeState::new(Some(&OffsetFree::Integral(integral)), 0.01, 10.0);
        for s in [&off, &on, &integral] {
            assert!(accepts(s, check));
            assert!(refuses(
                s,
                3,
                |p| unsafe { addr_of_mut!((*p).kind).cast() },
                check
            ));
            assert!(refuses(
                s,
                2,
                |p| unsafe { addr_of_mut!((*p).landed).cast() },
                check
            ));
        }
        // The observer's own tags, reached through the kind's payload (`repr(u8)` layout).
        let Kind::Observer(o) = &on.kind else {
            unreachable!()
        };
        let at = o as *const ObserverState<f32> as usize - &on as *const _ as usize;
        assert_eq!(at, core::mem::offset_of!(OffsetFreeState<f32>, kind) + 4);
        let mut s = on;
        s.set_landed(true);
        assert!(accepts(&s, check));
        let first = |p: *mut OffsetFreeState<f32>| unsafe { p.cast::<u8>().add(at) };
        let tags = (0..core::mem::size_of::<ObserverState<f32>>())
            .filter(|&k| refuses(&on, 2, |p| unsafe { first(p).add(k) }, check))
            .count();
        // `last`, `momenta`, `measured` and the two saturation flags.
        assert_eq!(tags, 5);
        let off = OffsetFree::Observer(observer);
        let check = OffsetFree::<f32>::storage_intact;
        assert!(accepts(&off, check) && refuses(&off, 2, |p| p.cast(), check));
    }
}
