//! Elliptic-cone approximation of the attainable force space (AFS), eqs. (7)-(8), and the stages
//! that read it: the force projection ([`projection`], eqs. 10, 13), the attitude planner
//! ([`planner`], eqs. 9, 11) and the hover capability of a degraded team ([`hover`]).

use nalgebra::Vector3;

use crate::foundation::error::{ConfigError, ConfigField};
use crate::foundation::linalg::norm;
use crate::foundation::real::{count, to_f64, Real};

pub mod hover;
pub mod planner;
pub mod projection;

/// The AFS relaxation `s in (0, 1]`: gimbal limits are shrunk to `s sigma` when planning, which
/// leaves attitude-control authority in reserve (paper, eq. 8).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Relaxation<T: Real>(T);

impl<T: Real> Relaxation<T> {
    /// Validates `s in (0, 1]`.
    pub fn new(s: T) -> Result<Self, ConfigError> {
        if !s.is_finite() {
            return Err(ConfigError::NonFinite {
                field: ConfigField::Relaxation,
            });
        }
        if s <= T::zero() || s > T::one() {
            return Err(ConfigError::Relaxation { value: to_f64(s) });
        }
        Ok(Self(s))
    }

    /// `s = 1`: the full gimbal limits (used by the force projection).
    pub fn none() -> Self {
        Self(T::one())
    }

    /// The value of `s`.
    pub fn get(&self) -> T {
        self.0
    }
}

/// Semi-axes of the elliptic cross-section of the AFS at height `z`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SemiAxes<T: Real> {
    /// `c_x(z, s)`.
    pub c_x: T,
    /// `c_y(z, s)`.
    pub c_y: T,
    /// Whether a semi-axis comes from the `sigma >= pi/2` branch of eq. (8) (then the AFS admits
    /// forces at `z = 0` away from the apex; it never admits `z < 0`).
    pub unbounded_branch: bool,
}

/// The approximated AFS of a (possibly degraded) team:
/// `u_f in AFS  <=>  u_f^T C(u_fz) u_f <= 1  and  ||u_f|| <= n sigma_Tf` (eq. 7),
/// with `C = diag(1/c_x^2, 1/c_y^2, 0)` and `c_x, c_y` from eq. (8).
///
/// Every agent's thrust has `z = T cos(eta_x) cos(eta_y) >= 0`, so a force with `z < 0` is never
/// a member, whatever the branch; `z = 0` is a member only where a semi-axis comes from the
/// `sigma >= pi/2` branch, or at the apex `u = 0` (all thrusts zero). Otherwise membership needs
/// `z > 0` (the reading of `docs/method.md`; the authors' code checks `z > 0`). The thrust bound
/// is closed (`<=`), where the paper writes `<`, so that the projection's output `t_Tf u` is a
/// member.
///
/// ```
/// use tvmd_core::nalgebra::Vector3;
/// use tvmd_core::{team::presets, FailureMask, Relaxation};
/// let team = presets::a4_inc::<f64, 4>()?;
/// let afs = team.afs(&FailureMask::none())?;
/// let s = Relaxation::new(0.5)?;
/// // Hover is inside; a large sideways force at the same height is not.
/// assert!(afs.contains(&Vector3::new(0.0, 0.0, 27.5), s));
/// assert!(!afs.contains(&Vector3::new(0.0, 20.0, 27.5), s));
/// let axes = afs.semi_axes(1.0, s);
/// assert!((axes.c_y.atan() - 0.328708).abs() < 1e-6); // the hover saturation roll
/// # Ok::<(), tvmd_core::ConfigError>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AttainableForceSpace<T: Real> {
    pub(crate) n: usize,
    n_x: usize,
    sigma_x: T,
    sigma_y: T,
    max_thrust: T,
}

impl<T: Real> AttainableForceSpace<T> {
    /// The AFS of `n` working agents of which `n_x` have even quarter turns.
    pub fn new(
        n: usize,
        n_x: usize,
        sigma_x: T,
        sigma_y: T,
        max_thrust: T,
    ) -> Result<Self, ConfigError> {
        if n == 0 {
            return Err(ConfigError::NoAgents);
        }
        if n_x > n {
            return Err(ConfigError::AgentCount { n, n_x });
        }
        crate::agent::limits::AgentLimits::new(sigma_x, sigma_y, max_thrust)?;
        Ok(Self {
            n,
            n_x,
            sigma_x,
            sigma_y,
            max_thrust,
        })
    }

    /// `n`.
    pub fn n(&self) -> usize {
        self.n
    }

    /// `n_x`.
    pub fn n_x(&self) -> usize {
        self.n_x
    }

    /// `n sigma_Tf`, the largest attainable force magnitude.
    pub fn max_force(&self) -> T {
        count::<T>(self.n) * self.max_thrust
    }

    /// `g(n_k, sigma, z) = offset + slope |z|` of eq. (8): `n_k sigma_Tf` (offset) if
    /// `sigma >= pi/2`, else `(n_k/n)(1 - delta(n_k)) tan(sigma)` (slope). The flag tells whether
    /// the `sigma >= pi/2` branch contributed.
    fn g(&self, n_k: usize, sigma: T) -> (T, T, bool) {
        if sigma >= T::frac_pi_2() {
            (count::<T>(n_k) * self.max_thrust, T::zero(), n_k > 0)
        } else if n_k == 0 {
            // (1 - delta(n_k)) vanishes.
            (T::zero(), T::zero(), false)
        } else {
            (
                T::zero(),
                count::<T>(n_k) / count::<T>(self.n) * sigma.tan(),
                false,
            )
        }
    }

    /// The cone of eq. (8) for relaxation `s`: `c_x(z, s) = g(n_x, s sigma_y, z) + g(n_y, s sigma_x, z)`,
    /// `c_y(z, s) = g(n_x, s sigma_x, z) + g(n_y, s sigma_y, z)`, with the `tan` terms evaluated
    /// once (the planner tests many `z` at one `s`).
    pub fn cone(&self, s: Relaxation<T>) -> EllipticCone<T> {
        let n_y = self.n - self.n_x;
        let (sx, sy) = (s.get() * self.sigma_x, s.get() * self.sigma_y);
        let (ax, bx, ux) = self.g(self.n_x, sy);
        let (ay, by, uy) = self.g(n_y, sx);
        let (cx, dx, vx) = self.g(self.n_x, sx);
        let (cy, dy, vy) = self.g(n_y, sy);
        EllipticCone {
            offset_x: ax + ay,
            slope_x: bx + by,
            offset_y: cx + cy,
            slope_y: dx + dy,
            unbounded_branch: ux || uy || vx || vy,
            max_force: self.max_force(),
        }
    }

    /// `c_x(z, s)`, `c_y(z, s)` of eq. (8).
    pub fn semi_axes(&self, z: T, s: Relaxation<T>) -> SemiAxes<T> {
        self.cone(s).semi_axes(z)
    }

    /// `u^T C(u_z) u = (u_x / c_x)^2 + (u_y / c_y)^2` (eq. 7). A zero semi-axis contributes 0 if
    /// its component is 0 and `+inf` otherwise.
    pub fn quadratic_form(&self, u: &Vector3<T>, s: Relaxation<T>) -> T {
        self.cone(s).quadratic_form(u)
    }

    /// Membership in the approximated AFS (eq. 7, with the readings documented on the type).
    pub fn contains(&self, u: &Vector3<T>, s: Relaxation<T>) -> bool {
        self.cone(s).contains(u)
    }
}

/// The AFS at one relaxation: semi-axes affine in `|z|` (eq. 8) and the thrust bound.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EllipticCone<T: Real> {
    offset_x: T,
    slope_x: T,
    offset_y: T,
    slope_y: T,
    unbounded_branch: bool,
    max_force: T,
}

impl<T: Real> EllipticCone<T> {
    /// `c_x(z)`, `c_y(z)`.
    pub fn semi_axes(&self, z: T) -> SemiAxes<T> {
        SemiAxes {
            c_x: self.offset_x + self.slope_x * z.abs(),
            c_y: self.offset_y + self.slope_y * z.abs(),
            unbounded_branch: self.unbounded_branch,
        }
    }

    /// `u^T C(u_z) u` (eq. 7).
    pub fn quadratic_form(&self, u: &Vector3<T>) -> T {
        let axes = self.semi_axes(u.z);
        ratio_squared(u.x, axes.c_x) + ratio_squared(u.y, axes.c_y)
    }

    /// Membership: `||u|| <= n sigma_Tf` (an overflow-safe norm), `u^T C u <= 1`, never `z < 0`
    /// (see the type's rustdoc).
    pub fn contains(&self, u: &Vector3<T>) -> bool {
        u.iter().all(|x| x.is_finite()) && norm(u) <= self.max_force && self.admits(u)
    }

    /// Membership without the thrust bound (the planner checks `||u||` once per plan, as it is
    /// invariant under rotation): `z >= 0` and `(u_x / c_x)^2 + (u_y / c_y)^2 <= 1`, with the
    /// zero-semi-axis rule of [`Self::quadratic_form`]. At `z = 0` only the `sigma >= pi/2`
    /// branch gives a non-zero semi-axis, so elsewhere only the apex passes. The ratios neither
    /// overflow nor underflow where squares of the components would.
    pub fn admits(&self, u: &Vector3<T>) -> bool {
        // Written so a NaN height fails too.
        u.z >= T::zero() && self.quadratic_form(u) <= T::one()
    }

    /// `n sigma_Tf`.
    pub fn max_force(&self) -> T {
        self.max_force
    }
}

fn ratio_squared<T: Real>(x: T, c: T) -> T {
    if x == T::zero() {
        T::zero()
    } else if c == T::zero() {
        infinity()
    } else {
        (x / c) * (x / c)
    }
}

/// `+inf` for IEEE floats.
pub(crate) fn infinity<T: Real>() -> T {
    T::one() / T::zero()
}

impl<T: Real> EllipticCone<T> {
    /// Whether the cone at `this` holds a valid flag (its other fields are numbers).
    ///
    /// # Safety
    /// `this` is aligned and points to `size_of::<Self>()` readable bytes.
    pub(crate) unsafe fn storage_intact(this: *const Self) -> bool {
        crate::foundation::stored::bool_intact(core::ptr::addr_of!((*this).unbounded_branch))
    }
}

#[cfg(test)]
mod storage_tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use crate::foundation::stored::{accepts, refuses};
    use crate::{team::presets, FailureMask};

    #[test]
    fn an_invalid_flag_is_refused() {
        let team = presets::a4_inc::<f32, 4>().unwrap();
        let cone = team
            .afs(&FailureMask::none())
            .unwrap()
            .cone(Relaxation::none());
        let check = EllipticCone::<f32>::storage_intact;
        let flag = |p: *mut EllipticCone<f32>| unsafe {
            core::ptr::addr_of_mut!((*p).unbounded_branch).cast()
        };
        assert!(accepts(&cone, check) && refuses(&cone, 2, flag, check));
    }
}
