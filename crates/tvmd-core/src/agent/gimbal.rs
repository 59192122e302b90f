//! The agent's two-axis gimbal: thrust direction (eq. 1) and its inverse (paper, "Control
//! Allocation").

use nalgebra::Vector3;

use crate::foundation::linalg::EuclideanNorm;
use crate::foundation::linalg::{max_abs, plain_is_exact};
use crate::foundation::real::{asin, sqrt, Real};

/// `a_hat(eta_x, eta_y) = [cos eta_x sin eta_y, -sin eta_x, cos eta_x cos eta_y]` (eq. 1), the
/// unit thrust direction in the agent frame.
pub fn thrust_direction<T: Real>(eta_x: T, eta_y: T) -> Vector3<T> {
    let (sx, cx) = eta_x.sin_cos();
    let (sy, cy) = eta_y.sin_cos();
    Vector3::new(cx * sy, -sx, cx * cy)
}

/// Gimbal angles and thrust of one agent: the command that produces an agent-frame force.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GimbalCommand<T: Real> {
    /// `T = ||f_i||` (N).
    pub thrust: T,
    /// Inner gimbal angle `eta_x` (rad).
    pub eta_x: T,
    /// Outer gimbal angle `eta_y` (rad).
    pub eta_y: T,
}

impl<T: Real> GimbalCommand<T> {
    /// Zero thrust, gimbal centred.
    pub fn idle() -> Self {
        Self {
            thrust: T::zero(),
            eta_x: T::zero(),
            eta_y: T::zero(),
        }
    }

    /// The inverse of [`Self::force`]: `T = ||f||`, `eta_x = asin(-f_y / T)`,
    /// `eta_y = atan2(f_x / sgn(cos eta_x), f_z / sgn(cos eta_x))`.
    ///
    /// `asin` returns `|eta_x| <= pi/2`, so `cos eta_x >= 0` and the paper's sign is `+1`
    /// (taken as `+1` at `cos eta_x = 0` too, where `eta_y` is arbitrary). A zero or non-finite
    /// force gives zero thrust with a centred gimbal. The force is scaled by its largest component
    /// first, so the angles are exact to round-off at any magnitude (no overflow at `1e155`, no
    /// underflow at `1e-160` in `f64`); `T` is `+inf` only when `||f||` exceeds the type's `MAX`.
    pub fn from_force(force: &Vector3<T>) -> Self {
        Self::inverse(force, |s| s.asin())
    }

    /// [`Self::from_force`] with `asin` from [`crate::foundation::real::asin`]: the same bits in `f64`; in
    /// `f32` within 2 ulp without `libm`'s software-`f64` branch (a Cortex-M4F). The
    /// exact-boundary redistribution's; the paper's allocator keeps [`Self::from_force`]'s bits.
    pub(crate) fn from_force_fast(force: &Vector3<T>) -> Self {
        Self::inverse(force, asin)
    }

    /// The gimbal inverse with `asin` given (a function pointer, one copy for both forms: the
    /// C interface's text is bounded).
    #[inline(never)]
    fn inverse(force: &Vector3<T>, asin: fn(T) -> T) -> Self {
        let squared = force.norm_squared();
        let (unit_scaled, n, m) = if plain_is_exact(squared) {
            (*force, sqrt(squared), T::one())
        } else {
            let m = max_abs(force);
            if m == T::zero() || !m.is_finite() {
                return Self::idle();
            }
            let unit_scaled = force / m;
            (unit_scaled, unit_scaled.euclidean_norm(), m)
        };
        // Rounding can push |f_y|/T a hair above 1.
        let sin_x = (-unit_scaled.y / n).clamp(-T::one(), T::one());
        Self {
            thrust: n * m,
            eta_x: asin(sin_x),
            eta_y: unit_scaled.x.atan2(unit_scaled.z),
        }
    }

    /// `f = T a_hat(eta_x, eta_y)`, the agent-frame force.
    pub fn force(&self) -> Vector3<T> {
        thrust_direction(self.eta_x, self.eta_y) * self.thrust
    }
}
