//! Force projection `K_f` (eqs. 12-13): scales a requested force into the approximated AFS.

use nalgebra::{Matrix3, Vector3};

use crate::afs::{AttainableForceSpace, EllipticCone, Relaxation};
use crate::foundation::linalg::EuclideanNorm;
use crate::foundation::linalg::{max_abs, norm};
use crate::foundation::real::{eps, lit, sqrt, Real};

/// The projected force and the factors of `K_f = diag(t_eta t_Tf, t_eta t_Tf, t_Tf)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ForceProjection<T: Real> {
    /// `K_f u_fr`.
    pub force: Vector3<T>,
    /// `t_Tf = min(1, n sigma_Tf / ||u_fr||)` (`1` for a zero force).
    pub t_tf: T,
    /// `t_eta = min(1, sqrt(1 / (u'^T C(u'_z) u')))` at `s = 1`, `u' = t_Tf u_fr`
    /// (`1` when the quadratic form is 0, `0` when it is infinite).
    pub t_eta: T,
}

impl<T: Real> ForceProjection<T> {
    /// `K_f = diag(t_eta t_Tf, t_eta t_Tf, t_Tf)`.
    pub fn gain(&self) -> Matrix3<T> {
        let xy = self.t_eta * self.t_tf;
        Matrix3::from_diagonal(&Vector3::new(xy, xy, self.t_tf))
    }
}

/// Projects `u_fr` (team frame) into `afs`: first onto the thrust ball, then the horizontal
/// part onto the ellipse at the resulting height (eqs. 12-13, `s = 1`).
///
/// A non-finite `u_fr` projects to zero with both factors 0, so the output is never NaN.
/// A request with a downward part (`u_fr,z < 0`) cannot be brought into the AFS by any `K_f`
/// of this structure (it keeps the sign of `z`, and no agent pushes down): it projects to the
/// apex, zero force, with `t_Tf = t_eta = 0` (the flag; the planner then sees `f_r = 0`). Every
/// projected force is an AFS member at `s = 1` (to round-off of the `t_Tf` scaling).
///
/// ```
/// use tvmd_core::nalgebra::Vector3;
/// use tvmd_core::{project_force, team::presets, FailureMask};
/// let team = presets::a4_inc::<f64, 4>()?;
/// let afs = team.afs(&FailureMask::none())?;
/// // Inside: unchanged. Beyond the thrust ball: scaled by t_Tf.
/// let hover = project_force(&afs, &Vector3::new(0.0, 0.0, 27.5));
/// assert_eq!((hover.t_tf, hover.t_eta), (1.0, 1.0));
/// let big = project_force(&afs, &Vector3::new(0.0, 0.0, 100.0));
/// assert!((big.force.z - afs.max_force()).abs() < 1e-12);
/// # Ok::<(), tvmd_core::ConfigError>(())
/// ```
pub fn project_force<T: Real>(
    afs: &AttainableForceSpace<T>,
    u_fr: &Vector3<T>,
) -> ForceProjection<T> {
    project_force_in(&afs.cone(Relaxation::none()), u_fr)
}

/// As [`project_force`] with the AFS already evaluated at `s = 1` (`afs.cone(Relaxation::none())`).
pub fn project_force_in<T: Real>(cone: &EllipticCone<T>, u_fr: &Vector3<T>) -> ForceProjection<T> {
    if !u_fr.iter().all(|x| x.is_finite()) || u_fr.z < T::zero() {
        return ForceProjection {
            force: Vector3::zeros(),
            t_tf: T::zero(),
            t_eta: T::zero(),
        };
    }
    // Scaled by the largest component so that neither the norm nor the ratio overflows.
    let m = max_abs(u_fr);
    let limit = cone.max_force();
    // Both factors are shrunk by a few ulps so that the projected force is a member despite the
    // rounding of the products (`contains` at `s = 1` holds exactly).
    let shrink = T::one() - eps::<T>() * lit(4.0);
    let t_tf = if m > T::zero() && norm(u_fr) > limit {
        (limit / m) / (u_fr / m).euclidean_norm() * shrink
    } else {
        T::one()
    };
    let scaled = u_fr * t_tf;
    let q = cone.quadratic_form(&scaled);
    let t_eta = if q <= T::one() {
        T::one()
    } else if q.is_finite() {
        sqrt(T::one() / q) * shrink
    } else {
        T::zero()
    };
    let projection = ForceProjection {
        force: Vector3::zeros(),
        t_tf,
        t_eta,
    };
    let projected = ForceProjection {
        force: projection.gain() * u_fr,
        ..projection
    };
    // Subnormal components round absolutely, beyond the shrink: then keep only the vertical
    // part, which is always a member. (`t_eta = 1` needs no check: the force is `scaled`.)
    if t_eta < T::one() && !cone.contains(&projected.force) {
        let vertical = ForceProjection {
            t_eta: T::zero(),
            ..projection
        };
        return ForceProjection {
            force: vertical.gain() * u_fr,
            ..vertical
        };
    }
    projected
}
