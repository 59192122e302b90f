//! The admissible control space `E_f` of one agent (eq. 6): gimbal limits on the exact map,
//! the thrust range, and optional gimbal rate limits from the previous command.

use nalgebra::Vector3;

use crate::agent::gimbal::{thrust_direction, GimbalCommand};
use crate::agent::limits::AgentLimits;
/// The interval and rate limits, at their old paths (now in [`crate::agent::limits`]).
pub use crate::agent::limits::{Interval, RateLimits};
use crate::foundation::error::{ConfigError, ConfigField};
use crate::foundation::linalg::max_abs;
use crate::foundation::real::{fmax, sin_cos, Real};

/// Each agent's admissible set for one period: `base` everywhere, narrowed around each agent's
/// previous command by `rate_limits = (rates, dt)` when given
/// ([`AdmissibleSet::with_rate_limit`]). Slots beyond `previous` keep `base`. The one rule the
/// controller and the bindings share.
pub fn admissible_sets<T: Real, const N: usize>(
    base: &AdmissibleSet<T>,
    rate_limits: Option<(&RateLimits<T>, T)>,
    previous: impl IntoIterator<Item = GimbalCommand<T>>,
) -> [AdmissibleSet<T>; N] {
    let mut sets = [*base; N];
    if let Some((rates, dt)) = rate_limits {
        for (set, prev) in sets.iter_mut().zip(previous) {
            *set = base.with_rate_limit(&prev, rates, dt);
        }
    }
    sets
}

/// One agent's admissible set: `eta_x in eta_x`, `eta_y in eta_y`, `T in thrust`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AdmissibleSet<T: Real> {
    eta_x: Interval<T>,
    eta_y: Interval<T>,
    thrust: Interval<T>,
}

impl<T: Real> AdmissibleSet<T> {
    /// A set from its three ranges: finite, `lo <= hi`, angles within `[-pi/2, pi/2]`, thrust
    /// `>= 0`. Errors name the range ([`ConfigField::SigmaX`], [`ConfigField::SigmaY`],
    /// [`ConfigField::MaxThrust`]).
    pub fn new(
        eta_x: Interval<T>,
        eta_y: Interval<T>,
        thrust: Interval<T>,
    ) -> Result<Self, ConfigError> {
        let half_pi = T::frac_pi_2();
        for (range, field, lo, hi) in [
            (eta_x, ConfigField::SigmaX, -half_pi, half_pi),
            (eta_y, ConfigField::SigmaY, -half_pi, half_pi),
            (
                thrust,
                ConfigField::MaxThrust,
                T::zero(),
                T::one() / T::zero(),
            ),
        ] {
            if !range.lo.is_finite() || !range.hi.is_finite() {
                return Err(ConfigError::NonFinite { field });
            }
            if range.lo > range.hi || range.lo < lo || range.hi > hi {
                return Err(ConfigError::Parameter { field });
            }
        }
        Ok(Self {
            eta_x,
            eta_y,
            thrust,
        })
    }

    /// Range of `eta_x` (rad).
    pub fn eta_x(&self) -> Interval<T> {
        self.eta_x
    }

    /// Range of `eta_y` (rad).
    pub fn eta_y(&self) -> Interval<T> {
        self.eta_y
    }

    /// Range of the thrust (N).
    pub fn thrust(&self) -> Interval<T> {
        self.thrust
    }

    /// `E_f` of eq. (6): `|eta_x| <= sigma_x`, `|eta_y| <= sigma_y`, `T in [T_idle, sigma_Tf]`.
    pub fn from_limits(limits: &AgentLimits<T>) -> Self {
        Self {
            eta_x: Interval::symmetric(limits.sigma_x()),
            eta_y: Interval::symmetric(limits.sigma_y()),
            thrust: Interval {
                lo: limits.min_thrust(),
                hi: limits.max_thrust(),
            },
        }
    }

    /// Narrows the gimbal ranges to `|eta - eta_prev| <= rate * dt` (the rate-constrained variant).
    pub fn with_rate_limit(
        &self,
        previous: &GimbalCommand<T>,
        rates: &RateLimits<T>,
        dt: T,
    ) -> Self {
        Self {
            eta_x: self.eta_x.window(previous.eta_x, rates.eta_x() * dt),
            eta_y: self.eta_y.window(previous.eta_y, rates.eta_y() * dt),
            thrust: self.thrust,
        }
    }

    /// Whether a command lies in the set, each bound widened by `tol` (relative to the thrust
    /// range for the thrust).
    pub fn contains(&self, cmd: &GimbalCommand<T>, tol: T) -> bool {
        self.eta_x.contains(cmd.eta_x, tol)
            && self.eta_y.contains(cmd.eta_y, tol)
            && self.thrust.contains(cmd.thrust, tol * self.thrust.hi)
    }

    /// How far a command lies outside the set in the units of [`Self::contains`]'s tolerance
    /// (0 inside): the largest of the angle excesses (rad) and the thrust excess over the
    /// largest thrust. For a finite command, `contains(cmd, tol)` exactly when
    /// `excess(cmd) <= tol` (up to the round-off of the widened bounds). Unlike
    /// [`Self::violation`] it stays meaningful on a range of zero width, where one ulp of an
    /// angle is a round-off, not a violation of the whole range.
    pub fn excess(&self, cmd: &GimbalCommand<T>) -> T {
        fmax(
            fmax(self.eta_x.excess(cmd.eta_x), self.eta_y.excess(cmd.eta_y)),
            self.thrust.excess(cmd.thrust) / fmax(self.thrust.hi, T::default_epsilon()),
        )
    }

    /// Normalized distance outside the set (0 inside): the largest of the angle excesses over
    /// their range widths and the thrust excess over the thrust range.
    pub fn violation(&self, cmd: &GimbalCommand<T>) -> T {
        let width = |i: &Interval<T>| fmax(i.hi - i.lo, T::default_epsilon());
        let x = self.eta_x.excess(cmd.eta_x) / width(&self.eta_x);
        let y = self.eta_y.excess(cmd.eta_y) / width(&self.eta_y);
        fmax(
            fmax(x, y),
            self.thrust.excess(cmd.thrust) / width(&self.thrust),
        )
    }

    /// The command clamped into the set, axis by axis on the exact gimbal map.
    pub fn clamp(&self, cmd: &GimbalCommand<T>) -> GimbalCommand<T> {
        GimbalCommand {
            thrust: self.thrust.clamp(cmd.thrust),
            eta_x: self.eta_x.clamp(cmd.eta_x),
            eta_y: self.eta_y.clamp(cmd.eta_y),
        }
    }

    /// The agent-frame force `f` saturated into the set: the gimbal angles clamped
    /// ([`Self::clamp`]), then the point of the clamped direction's ray `T a_hat`,
    /// `T in thrust`, closest to `f` (`T = clamp(f . a_hat)`). A force pointing away from the
    /// clamped direction (e.g. downward) gets the least thrust, never its own norm along a
    /// direction it does not have. A non-finite force gives the least thrust, gimbal clamped
    /// from centre. Always finite and inside the set (up to the gimbal inverse's round-off).
    pub fn saturate(&self, force: &Vector3<T>) -> Vector3<T> {
        self.saturate_along(force, GimbalCommand::from_force, thrust_direction)
    }

    /// [`Self::saturate`] with the gimbal inverse of [`GimbalCommand::from_force_fast`] and the
    /// clamped direction's sines and cosines from [`crate::foundation::real::sin_cos`]: the same bits in
    /// `f64`; in `f32` within 2 ulp, without `libm`'s `sincosf` (software `f64` on a
    /// Cortex-M4F, about 2,200 instructions a call). The
    /// exact-boundary redistribution's; the paper's allocator keeps [`Self::saturate`]'s bits.
    pub(crate) fn saturate_fast(&self, force: &Vector3<T>) -> Vector3<T> {
        self.saturate_along(force, GimbalCommand::from_force_fast, |x, y| {
            let (sx, cx) = sin_cos(x);
            let (sy, cy) = sin_cos(y);
            Vector3::new(cx * sy, -sx, cx * cy)
        })
    }

    /// [`Self::saturate`] with the gimbal inverse and the unit direction of clamped angles given
    /// (function pointers, one copy for both forms: the C interface's text is bounded).
    #[inline(never)]
    fn saturate_along(
        &self,
        force: &Vector3<T>,
        inverse: fn(&Vector3<T>) -> GimbalCommand<T>,
        direction: fn(T, T) -> Vector3<T>,
    ) -> Vector3<T> {
        let g = self.clamp(&inverse(force));
        let direction = direction(g.eta_x, g.eta_y);
        let m = max_abs(force);
        let along = if m > T::zero() && m.is_finite() {
            // Scaled so that a huge force does not overflow the dot product into NaN.
            (force / m).dot(&direction) * m
        } else {
            T::zero()
        };
        // A thrust below the range's resolution (`eps sigma_Tf`) is zero: its force would be
        // subnormal, and its gimbal inverse no longer exact.
        let along = if along <= self.thrust.hi * T::default_epsilon() {
            T::zero()
        } else {
            along
        };
        direction * self.thrust.clamp(along)
    }
}
