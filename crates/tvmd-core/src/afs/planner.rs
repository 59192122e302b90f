//! The attitude planner (eqs. 9-11): the smallest tilt of the reference attitude `R_r` that
//! makes the requested force attainable.

use nalgebra::{Matrix3, Vector3};

use crate::afs::{AttainableForceSpace, EllipticCone, Relaxation};
use crate::foundation::error::{ConfigError, ConfigField, InputError};
use crate::foundation::linalg::EuclideanNorm;
use crate::foundation::linalg::{columns, norm, normalize};
use crate::foundation::real::{eps, lit, sqrt, Real};
use crate::foundation::rotation::validate_rotation;

/// How the planner reached its output.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PlannerStatus {
    /// `R_r^T f_r` was already in the AFS: `R_d = R_r`, `theta = 0`.
    AlreadyFeasible,
    /// The search found the smallest feasible tilt (within the tolerance).
    Planned,
    /// `f_r = 0`: there is no direction to tilt toward; `R_d = R_r`.
    ZeroForce,
    /// Not even `b_zd` along `f_r` is feasible (`||f_r|| > n sigma_Tf`): `R_d` aligns `b_zd`
    /// with `f_r` as closely as the rotation allows (`theta = theta_max`).
    Unreachable,
}

impl PlannerStatus {
    /// Every status, in declaration order.
    pub const ALL: [Self; 4] = [
        Self::AlreadyFeasible,
        Self::Planned,
        Self::ZeroForce,
        Self::Unreachable,
    ];

    /// The one spelling used in logs and bindings: `"already-feasible"`, `"planned"`,
    /// `"zero-force"`, `"unreachable"` (kebab case, as the allocator names).
    pub const fn as_str(self) -> &'static str {
        match self {
            Self::AlreadyFeasible => "already-feasible",
            Self::Planned => "planned",
            Self::ZeroForce => "zero-force",
            Self::Unreachable => "unreachable",
        }
    }
}

impl core::fmt::Display for PlannerStatus {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// Output of [`AttitudePlanner::plan`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlannerOutput<T: Real> {
    /// `R_d = [b_xd b_yd b_zd]`, the planned attitude.
    pub r_d: Matrix3<T>,
    /// `theta*`, the tilt from `b_zr` toward `f_r` (rad).
    pub theta: T,
    /// Search steps (membership tests) used (0 unless [`PlannerStatus::Planned`]).
    pub iterations: u32,
    /// How the output was reached.
    pub status: PlannerStatus,
}

/// The attitude planner of eqs. (9)-(11), with the improvements recorded in `docs/method.md`: a
/// bracketed search on `theta` (regula falsi, Anderson-Bjorck variant, bisection as safeguard) in
/// place of the paper's bisection; it returns the last *feasible* point, stops on a tolerance or
/// an iteration cap, and tilts about `b_xr` when `f_r` is (anti)parallel to `b_zr`.
///
/// ```
/// use tvmd_core::nalgebra::Vector3;
/// use tvmd_core::rotation::{roll, roll_angle};
/// use tvmd_core::{team::presets, AttitudePlanner, FailureMask, PlannerStatus, Relaxation};
/// let team = presets::a4_inc::<f64, 4>()?;
/// let afs = team.afs(&FailureMask::none())?;
/// let planner = AttitudePlanner::new(Relaxation::new(0.5)?);
/// // Hover thrust with a reference roll of pi/3, beyond what the team can hold.
/// let f_r = Vector3::new(0.0, 0.0, team.mass() * 9.81);
/// let out = planner.plan(&afs, &roll(std::f64::consts::FRAC_PI_3), &f_r).unwrap();
/// assert_eq!(out.status, PlannerStatus::Planned);
/// assert!((roll_angle(&out.r_d) - 0.328708).abs() < 1e-5);
/// # Ok::<(), tvmd_core::ConfigError>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AttitudePlanner<T: Real> {
    relaxation: Relaxation<T>,
    tolerance: T,
    max_iterations: u32,
}

/// The most iterations any planner runs, whatever its stored cap
/// ([`AttitudePlanner::with_tolerance`]): more than a valid search can take (halving `[0, pi]`
/// to the smallest positive `f64` takes about 1,080 steps, the secant adds at most 4), so no
/// valid plan changes; a cap or tolerance a stray write changed cannot spin the loop.
pub const PLANNER_ITERATION_LIMIT: u32 = 2048;

impl<T: Real> AttitudePlanner<T> {
    /// A planner with relaxation `s`, tolerance `max(1e-10, 8 eps)` rad and at most 64 iterations.
    pub fn new(relaxation: Relaxation<T>) -> Self {
        Self {
            relaxation,
            tolerance: lit::<T>(1e-10).max(eps::<T>() * lit(8.0)),
            max_iterations: 64,
        }
    }

    /// Sets the search tolerance on `theta` (rad, positive) and the iteration cap (>= 1; the
    /// search stops at [`PLANNER_ITERATION_LIMIT`] whatever the cap).
    pub fn with_tolerance(
        mut self,
        tolerance: T,
        max_iterations: u32,
    ) -> Result<Self, ConfigError> {
        if !tolerance.is_finite() || tolerance <= T::zero() {
            return Err(ConfigError::Parameter {
                field: ConfigField::PlannerTolerance,
            });
        }
        if max_iterations == 0 {
            return Err(ConfigError::Parameter {
                field: ConfigField::PlannerMaxIterations,
            });
        }
        self.tolerance = tolerance;
        self.max_iterations = max_iterations;
        Ok(self)
    }

    /// The relaxation `s`.
    pub fn relaxation(&self) -> Relaxation<T> {
        self.relaxation
    }

    /// The search tolerance on `theta` (rad).
    pub fn tolerance(&self) -> T {
        self.tolerance
    }

    /// The iteration cap of the search.
    pub fn max_iterations(&self) -> u32 {
        self.max_iterations
    }

    /// Plans `R_d` for the reference attitude `r_r` and the inertial force request `f_r`
    /// (eq. 9: `f_r = t_Tf R u_fr`). Errors: [`InputError::NonFinite`] for a non-finite input,
    /// [`InputError::NotRotation`] when `r_r` is not a rotation (the check of
    /// [`crate::foundation::rotation::validate_rotation`]).
    pub fn plan(
        &self,
        afs: &AttainableForceSpace<T>,
        r_r: &Matrix3<T>,
        f_r: &Vector3<T>,
    ) -> Result<PlannerOutput<T>, InputError> {
        self.plan_in(&afs.cone(self.relaxation), r_r, f_r)
    }

    /// As [`Self::plan`] with the AFS already evaluated at the planner's relaxation
    /// (`afs.cone(planner.relaxation())`), which a controller keeps between periods.
    pub fn plan_in(
        &self,
        cone: &EllipticCone<T>,
        r_r: &Matrix3<T>,
        f_r: &Vector3<T>,
    ) -> Result<PlannerOutput<T>, InputError> {
        validate_rotation(r_r, "planner.r_r")?;
        self.plan_in_valid_attitude(cone, r_r, f_r)
    }

    /// As [`Self::plan_in`] for an `r_r` the caller has already validated with
    /// [`validate_rotation`] (the controller checks `reference.attitude` on entry to the cycle,
    /// so checking it again here would repeat the same test each period). `f_r` is still checked.
    pub(crate) fn plan_in_valid_attitude(
        &self,
        cone: &EllipticCone<T>,
        r_r: &Matrix3<T>,
        f_r: &Vector3<T>,
    ) -> Result<PlannerOutput<T>, InputError> {
        if !f_r.iter().all(|x| x.is_finite()) {
            return Err(InputError::NonFinite {
                field: "planner.f_r",
            });
        }
        let unchanged = |status| PlannerOutput {
            r_d: *r_r,
            theta: T::zero(),
            iterations: 0,
            status,
        };
        // ||R^T f_r|| = ||f_r||: the thrust bound is checked once, the cross-section per attitude.
        let norm = norm(f_r);
        let within_thrust = norm <= cone.max_force();
        if norm == T::zero() {
            return Ok(unchanged(PlannerStatus::ZeroForce));
        }
        // Each end's membership and search guide from one evaluation (see `guide`).
        let (phi_r, admits_r) = guide(cone, &(r_r.transpose() * f_r));
        if within_thrust && admits_r {
            return Ok(unchanged(PlannerStatus::AlreadyFeasible));
        }
        let tilt = Tilt::new(r_r, f_r);
        let end = tilt.attitude(tilt.theta_max);
        let (phi_end, admits_end) = guide(cone, &(end.transpose() * f_r));
        if !(within_thrust && admits_end) {
            return Ok(PlannerOutput {
                r_d: end,
                theta: tilt.theta_max,
                iterations: 0,
                status: PlannerStatus::Unreachable,
            });
        }
        Ok(self.search(cone, f_r, &tilt, (end, phi_end), phi_r))
    }

    /// The search between `theta = 0` (infeasible, guide `phi_r`) and `theta_max` (`end`,
    /// feasible, guide `phi_end`; so `||f_r||` is within the thrust bound and only the
    /// cross-section is tested).
    fn search(
        &self,
        cone: &EllipticCone<T>,
        f_r: &Vector3<T>,
        tilt: &Tilt<T>,
        (end, phi_end): (Matrix3<T>, T),
        phi_r: T,
    ) -> PlannerOutput<T> {
        // Regula falsi on `phi(theta)` with the Anderson-Bjorck fix against a stalled end,
        // bracketed by the membership test. Invariant: `lo` infeasible, `hi` feasible; `hi` is
        // returned.
        let (mut lo, mut hi, mut r_hi) = (T::zero(), tilt.theta_max, end);
        let (mut z_lo, mut z_hi) = (tilt.b_zr, columns(&end)[2]);
        let (mut phi_lo, mut phi_hi) = (phi_r, phi_end);
        // Which end moved last: a second move of the same end scales the other end's phi by
        // `1 - phi_new / phi_old` (Anderson-Bjorck; by 1/2, the Illinois factor, when that is
        // not positive). Illinois's fixed 1/2 stalls where phi is steep near `z = 0`.
        let mut last_moved_hi: Option<bool> = None;
        // Bisection's bracket after the same number of steps, times 2^4: a secant step is taken
        // only while it cannot fall behind it, so at most 4 steps more than bisection are used.
        let mut budget = tilt.theta_max * lit(16.0);
        let half = lit::<T>(0.5);
        let shrink = |new: T, old: T| {
            let m = T::one() - new / old;
            if m > T::zero() {
                m
            } else {
                half
            }
        };
        let mut iterations = 0;
        // Bounded by the constant too: a cap a stray write changed cannot spin the loop.
        let cap = self.max_iterations.min(PLANNER_ITERATION_LIMIT);
        while hi - lo > self.tolerance && iterations < cap {
            iterations += 1;
            let width = hi - lo;
            let guard = self.tolerance * half;
            // The secant point needs phi(lo) > 0 >= phi(hi); a `z < 0` or zero-semi-axis end
            // (phi <= 0 while infeasible) or an overflow has no usable value.
            let secant = phi_lo > T::zero()
                && phi_lo.is_finite()
                && phi_hi <= T::zero()
                && width <= budget * half
                && width > self.tolerance * lit(2.0);
            budget *= half;
            let (theta, z) = if secant {
                let t = hi - phi_hi * width / (phi_hi - phi_lo);
                // Kept a tolerance inside the bracket: a point landing next to `hi` then lets
                // the next infeasible test close the bracket (the stop of Brent's method).
                let t = t.max(lo + guard).min(hi - guard);
                (t, tilt.direction(t))
            } else {
                let sum = z_lo + z_hi;
                let norm = sum.euclidean_norm();
                // The great-circle midpoint without trigonometry; |sum| = 2 cos(width / 2)
                // vanishes only for a half-turn bracket.
                let mid = (lo + hi) * half;
                let z_mid = if norm > half {
                    sum * (T::one() / norm)
                } else {
                    tilt.direction(mid)
                };
                (mid, z_mid)
            };
            let r = tilt.frame(z);
            let u = r.transpose() * f_r;
            let (value, inside) = guide(cone, &u);
            if inside {
                if last_moved_hi == Some(true) {
                    phi_lo *= shrink(value, phi_hi);
                }
                (hi, z_hi, r_hi, phi_hi) = (theta, z, r, value);
                last_moved_hi = Some(true);
            } else {
                if last_moved_hi == Some(false) {
                    phi_hi *= shrink(value, phi_lo);
                }
                (lo, z_lo, phi_lo) = (theta, z, value);
                last_moved_hi = Some(false);
            }
        }
        PlannerOutput {
            r_d: r_hi,
            theta: hi,
            iterations,
            status: PlannerStatus::Planned,
        }
    }
}

/// The search's guide and the membership test at `u = R_d(theta)^T f_r` from one evaluation of
/// the quadratic form: `(phi, cone.admits(u))`, each exactly as evaluated apart.
/// `phi = sqrt(u^T C u) - 1` is continuous in `theta`, positive outside the cross-section and
/// `<= 0` inside (for a round cone of half-angle `alpha`, `tan(angle) / tan(alpha) - 1`: nearer
/// linear in `theta` than `u^T C u - 1` or the cone's division-free margin, so fewer secant
/// steps). The ratios of `quadratic_form` neither overflow nor underflow. Where it cannot guide
/// (`z < 0`, where `|z|` mirrors the cone; a zero semi-axis, `+inf`), the search bisects.
fn guide<T: Real>(cone: &EllipticCone<T>, u: &Vector3<T>) -> (T, bool) {
    if u.z < T::zero() {
        return (T::one() / T::zero(), false);
    }
    let q = cone.quadratic_form(u);
    // `u.z >= 0` is not implied here: a NaN height reaches this line and is not admitted.
    (sqrt(q) - T::one(), u.z >= T::zero() && q <= T::one())
}

/// `R_d(theta)` of eqs. (10)-(11): `R_r` tilted by `theta` toward `f_r`, the family the planner
/// searches (exposed for diagnostics and tests). `f_r` must be finite and non-zero; otherwise
/// `R_r` is returned.
pub fn tilted_attitude<T: Real>(r_r: &Matrix3<T>, f_r: &Vector3<T>, theta: T) -> Matrix3<T> {
    let norm = norm(f_r);
    if norm == T::zero() || !norm.is_finite() || !theta.is_finite() {
        return *r_r;
    }
    Tilt::new(r_r, f_r).attitude(theta)
}

/// The one-parameter family `R_d(theta)` of eqs. (10)-(11).
struct Tilt<T: Real> {
    b_xr: Vector3<T>,
    b_yr: Vector3<T>,
    b_zr: Vector3<T>,
    /// `k x b_zr`, the direction `b_zd` moves toward.
    k_cross_bz: Vector3<T>,
    theta_max: T,
}

impl<T: Real> Tilt<T> {
    fn new(r_r: &Matrix3<T>, f_r: &Vector3<T>) -> Self {
        let [b_xr, b_yr, b_zr] = columns(r_r);
        // The direction of f_r only: scaled so a huge or tiny f_r neither overflows nor underflows.
        let f_hat = normalize(f_r);
        let cross = b_zr.cross(&f_hat);
        let cross_norm = cross.euclidean_norm();
        // f_r (anti)parallel to b_zr: no unique axis; roll about b_xr (documented choice).
        let k = if cross_norm > eps::<T>() * lit(8.0) {
            cross / cross_norm
        } else {
            b_xr
        };
        let cos_max = b_zr.dot(&f_hat).clamp(-T::one(), T::one());
        Self {
            k_cross_bz: k.cross(&b_zr),
            b_xr,
            b_yr,
            b_zr,
            theta_max: cos_max.acos(),
        }
    }

    /// `b_zd = rot(b_zr, k, theta)` (Rodrigues; `k . b_zr = 0`), `b_yd = b_zd x b_xr / ||.||`,
    /// `b_xd = b_yd x b_zd` (eq. 11). When `b_zd` is parallel to `b_xr`, `b_xd` is instead taken
    /// from `b_yr x b_zd`.
    fn attitude(&self, theta: T) -> Matrix3<T> {
        self.frame(self.direction(theta))
    }

    /// `b_zd(theta) = rot(b_zr, k, theta)`.
    fn direction(&self, theta: T) -> Vector3<T> {
        let (s, c) = crate::foundation::real::sin_cos(theta);
        // `v / ||v||` as nalgebra's `normalize`, the same bits, with the FPU's square root.
        let v = self.b_zr * c + self.k_cross_bz * s;
        v / v.euclidean_norm()
    }

    /// `R_d = [b_xd b_yd b_zd]` completed from `b_zd` as in [`Self::attitude`].
    fn frame(&self, b_zd: Vector3<T>) -> Matrix3<T> {
        let y = b_zd.cross(&self.b_xr);
        let y_norm = y.euclidean_norm();
        let (b_xd, b_yd) = if y_norm > sqrt(eps::<T>()) {
            let b_yd = y * (T::one() / y_norm);
            (b_yd.cross(&b_zd), b_yd)
        } else {
            let x = self.b_yr.cross(&b_zd);
            let b_xd = x / x.euclidean_norm();
            (b_xd, b_zd.cross(&b_xd))
        };
        Matrix3::from_columns(&[b_xd, b_yd, b_zd])
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use crate::team::presets;
    use crate::FailureMask;

    /// `guide` is `(phi, cone.admits(u))` with `phi` as the search evaluated it on its own:
    /// `+inf` below the apex, `sqrt(u^T C u) - 1` elsewhere (NaN for a NaN height, which is not
    /// admitted even where the form would pass, e.g. on the axis).
    #[test]
    fn guide_agrees_with_the_separate_evaluations() {
        let team = presets::a4_inc::<f64, 4>().unwrap();
        let cone = team
            .afs(&FailureMask::none())
            .unwrap()
            .cone(Relaxation::new(0.5).unwrap());
        let w = 2.8 * 9.81;
        for u in [
            Vector3::new(0.0, 0.0, w),
            Vector3::new(1.0, -0.5, w),
            Vector3::new(30.0, 0.0, w),
            Vector3::new(0.0, 0.0, 0.0),
            Vector3::new(1.0, 0.0, 0.0),
            Vector3::new(1.0, 2.0, -w),
            Vector3::new(0.0, 0.0, f64::NAN),
            Vector3::new(1.0, 0.0, f64::NAN),
        ] {
            let (phi, admits) = guide(&cone, &u);
            assert_eq!(admits, cone.admits(&u), "admits at {u:?}");
            let apart = if u.z < 0.0 {
                f64::INFINITY
            } else {
                cone.quadratic_form(&u).sqrt() - 1.0
            };
            assert!(
                phi.to_bits() == apart.to_bits() || (phi.is_nan() && apart.is_nan()),
                "phi at {u:?}: {phi} vs {apart}"
            );
        }
        assert!(!guide(&cone, &Vector3::new(0.0, 0.0, f64::NAN)).1);
    }

    /// A stored cap and tolerance a stray write changed (a negative tolerance never stops the
    /// search, a cap of `u32::MAX` would run it for minutes) stop at
    /// [`PLANNER_ITERATION_LIMIT`]; a valid planner's plan is unchanged by the limit.
    #[test]
    fn the_search_stops_at_the_constant_limit_whatever_the_stored_cap() {
        let team = presets::a4_inc::<f64, 4>().unwrap();
        let afs = team.afs(&FailureMask::none()).unwrap();
        let relaxation = Relaxation::new(0.5).unwrap();
        let force = Vector3::new(0.0, 0.0, 2.8 * 9.81);
        let r_r = crate::foundation::rotation::roll(1.2);
        let valid = AttitudePlanner::new(relaxation).with_tolerance(f64::from_bits(1), u32::MAX);
        let valid = valid.unwrap().plan(&afs, &r_r, &force).unwrap();
        assert_eq!(valid.status, PlannerStatus::Planned);
        assert!(valid.iterations < PLANNER_ITERATION_LIMIT);
        let mut changed = AttitudePlanner::new(relaxation);
        changed.tolerance = -1.0;
        changed.max_iterations = u32::MAX;
        let out = changed.plan(&afs, &r_r, &force).unwrap();
        assert_eq!(out.iterations, PLANNER_ITERATION_LIMIT);
        assert!(out.theta.is_finite() && out.r_d.iter().all(|x| x.is_finite()));
    }
}
