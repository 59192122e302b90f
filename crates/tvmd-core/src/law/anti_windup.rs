//! Anti-windup of the offset-free state ([`crate::OffsetFree`]): which parts of the requested
//! wrench the team could not deliver this period, and the one rule that keeps the state from
//! growing then and bounds it by what the team can produce
//! (`docs/method.md#beyond-the-paper-offset-free-tracking`).

use nalgebra::Vector3;

use crate::foundation::linalg::clamp_norm;
use crate::foundation::real::{sqrt, Real};
use crate::foundation::stored::bool_intact;

/// Which parts of the requested wrench the team could not deliver in one period.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Saturation {
    /// The force part: the projection trimmed it (`t_Tf < 1` or `t_eta < 1`, eqs. 10, 13), the
    /// planner found it unreachable at every tilt (eq. 11), or the allocation left a wrench
    /// error.
    pub force: bool,
    /// The torque part: the allocation left a wrench error.
    pub torque: bool,
}

impl Saturation {
    /// Nothing saturated.
    pub const NONE: Self = Self {
        force: false,
        torque: false,
    };

    /// From one period's quantities: the projection's `t_Tf`, `t_eta`, whether the planner's
    /// status was `Unreachable`, and the allocation's `||u_d - M f||` against `||u_d||`. A
    /// wrench error counts when it exceeds `sqrt(eps) max(1, ||u_d||)` (about `3.5e-4`
    /// relative in `f32`, `1.5e-8` in `f64`: far above an exact allocator's round-off).
    pub fn from_cycle<T: Real>(
        t_tf: T,
        t_eta: T,
        unreachable: bool,
        wrench_error: T,
        wrench_norm: T,
    ) -> Self {
        let tolerance = sqrt(T::default_epsilon()) * wrench_norm.max(T::one());
        // A NaN error counts as short.
        let short = wrench_error > tolerance || !wrench_error.is_finite();
        Self {
            force: t_tf < T::one() || t_eta < T::one() || unreachable || short,
            torque: short,
        }
    }
}

/// One guarded update of a bounded vector state (a force or torque the state adds to the
/// request): the `candidate` replaces `old` unless it is not finite, or the part is
/// `saturated` and the candidate is larger than `old` (conditional integration: the state may
/// shrink but not grow while the team cannot deliver). The result is clamped onto
/// `||.|| <= bound`, so it is finite and bounded whatever the inputs (`old` finite, `bound`
/// finite and non-negative).
pub(crate) fn guarded<T: Real>(
    old: &Vector3<T>,
    candidate: &Vector3<T>,
    saturated: bool,
    bound: T,
) -> Vector3<T> {
    let finite = candidate.iter().all(|x| x.is_finite());
    let grows = candidate.norm_squared() > old.norm_squared();
    let next = if !finite || (saturated && grows) {
        old
    } else {
        candidate
    };
    clamp_norm(next, bound)
}

impl Saturation {
    /// Whether the flags at `this` are each 0 or 1 (read raw, for
    /// [`crate::Controller::storage_intact`]).
    ///
    /// # Safety
    /// `this` is aligned and points to `size_of::<Self>()` readable bytes.
    pub(crate) unsafe fn storage_intact(this: *const Self) -> bool {
        bool_intact(core::ptr::addr_of!((*this).force))
            && bool_intact(core::ptr::addr_of!((*this).torque))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn saturation_flags() {
        assert_eq!(
            Saturation::from_cycle(1.0, 1.0, false, 0.0, 30.0),
            Saturation::NONE
        );
        let trimmed = Saturation::from_cycle(1.0f64, 0.9, false, 0.0, 30.0);
        assert!(trimmed.force && !trimmed.torque);
        assert!(Saturation::from_cycle(0.5f64, 1.0, false, 0.0, 30.0).force);
        assert!(Saturation::from_cycle(1.0f64, 1.0, true, 0.0, 30.0).force);
        let short = Saturation::from_cycle(1.0f32, 1.0, false, 0.1, 30.0);
        assert!(short.force && short.torque);
        // Round-off of an exact allocator is not a shortfall.
        assert_eq!(
            Saturation::from_cycle(1.0f32, 1.0, false, 1e-5, 30.0),
            Saturation::NONE
        );
        assert!(Saturation::from_cycle(1.0f64, 1.0, false, f64::NAN, 30.0).torque);
    }

    #[test]
    fn guarded_never_grows_while_saturated_and_stays_bounded() {
        let old = Vector3::new(1.0f64, 0.0, 0.0);
        let bigger = Vector3::new(2.0, 0.0, 0.0);
        let smaller = Vector3::new(0.5, 0.1, 0.0);
        assert_eq!(guarded(&old, &bigger, true, 10.0), old);
        assert_eq!(guarded(&old, &bigger, false, 10.0), bigger);
        assert_eq!(guarded(&old, &smaller, true, 10.0), smaller);
        assert!((guarded(&old, &bigger, false, 1.5).norm() - 1.5).abs() < 1e-15);
        let nan = Vector3::new(f64::NAN, 0.0, 0.0);
        assert_eq!(guarded(&old, &nan, false, 10.0), old);
        let inf = Vector3::new(f64::INFINITY, 0.0, 0.0);
        assert_eq!(guarded(&old, &inf, false, 10.0), old);
    }
}
