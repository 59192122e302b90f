//! One agent's explanation of the period's residual ([`crate::fault`]): the misfits of its loss
//! and stuck-gimbal hypotheses, from the normal equations of the fits in closed form.
//!
//! With `A = W M_i` (the agent's block weighted by the stated noise), `q = A^T r` and
//! `P = A^T A`, both hypotheses are projections of the weighted residual `r` onto subspaces of
//! `A`'s span, so their misfits need only 3-vectors:
//! - loss, `r = -c A f` with `c` in `[0, 1]`: `||r + c A f||^2 = r.r + 2 c f.q + c^2 f^T P f`;
//! - stuck gimbal, `r = A v` with `v` across `f` (`f^T v = 0`): the constrained least squares
//!   leaves `r.r - q^T P^-1 q + (f^T P^-1 q)^2 / (f^T P^-1 f)`.
//!
//! Every block is `M_i = [[p_i]x R_i; R_i]` with `R_i` a rotation
//! ([`crate::agent::effectiveness::agent_block`]), so `M_f^T M_tau = [p']x` with `p' = R_i^T p_i`, and
//! `P = w_tau^2 (|p'|^2 I - p' p'^T) + w_f^2 I` (`w_tau`, `w_f`: the torque and force weights),
//! whose inverse is `(I + (w_tau^2 / w_f^2) p' p'^T) / (w_tau^2 |p'|^2 + w_f^2)`
//! (Sherman-Morrison), so every `x^T P^-1 y` is a few dot products. About 100 flops an agent,
//! against 260 for forming `A f` and the stuck hypothesis' two columns in six dimensions, which
//! matters on a Cortex-M4F while a fault is isolated.
//!
//! Round-off: the squared misfits come from differences of squares, so they carry about
//! `eps r.r` (`f32`: about `4e-7 r.r`). A misfit of an exact fit reads about `sqrt(eps) ||r||`
//! instead of 0, and the likelihood ratio (`k^2 / 2 = 12.5` at `k = 5`) is affected only when
//! the statistic exceeds about 1,000 noise units in `f32`. The six-dimensional form is exact to
//! `eps ||r||` but costs twice the arithmetic.

use nalgebra::{Matrix6x3, Vector3, Vector6};

use super::FaultKind;
use crate::foundation::real::{fmax, fmin, sqrt, Real};

/// The period's weighted residual, shared by every agent's fit.
pub(super) struct WeightedResidual<T: Real> {
    /// `r.r`.
    rr: T,
    /// `W r`, so that `q = M_i^T (W r)`.
    wr: Vector6<T>,
    /// `w_tau^2`, `w_f^2` and their ratio.
    tau2: T,
    force2: T,
    ratio: T,
}

impl<T: Real> WeightedResidual<T> {
    /// From the weighted residual `r = W residual`, its `r.r` and the weights `w` (torque
    /// first).
    pub(super) fn new(r: &Vector6<T>, rr: T, w: &Vector6<T>) -> Self {
        let [[tau, _, _, force, _, _]] = w.data.0;
        let (tau2, force2) = (tau * tau, force * force);
        Self {
            rr,
            wr: r.component_mul(w),
            tau2,
            force2,
            ratio: tau2 / force2,
        }
    }
}

/// One agent's fit of the residual.
pub(super) struct Fit<T: Real> {
    /// The squared misfit (agents are ranked by it; only the best two are rooted).
    pub(super) misfit2: T,
    pub(super) kind: FaultKind<T>,
}

/// A misfit no agent reached: the largest finite value of `T`.
pub(super) fn none<T: Real>() -> T {
    T::max_value().unwrap_or_else(T::one)
}

/// The weighted residual read against one agent's block and force: `q = A^T r`, the axial
/// vector `p'`, `f.f`, `f^T P f` and `f.q`.
struct Projection<T: Real> {
    q: Vector3<T>,
    p: Vector3<T>,
    /// `f.f`.
    ff: T,
    /// `f^T P f = ||A f||^2`, positive and finite.
    ll: T,
    /// `f.q = (A f).r`.
    rl: T,
}

impl<T: Real> Projection<T> {
    /// `None` for an agent with no command to lose (zero or non-finite force).
    #[inline(always)]
    fn new(res: &WeightedResidual<T>, m: &Matrix6x3<T>, f: &Vector3<T>) -> Option<Self> {
        // The block's columns, rows `[torque; force]`.
        let [[a0, a1, a2, a3, a4, a5], [b0, b1, b2, b3, b4, b5], [d0, d1, d2, d3, d4, d5]] =
            m.data.0;
        let [[z0, z1, z2, z3, z4, z5]] = res.wr.data.0;
        let q = Vector3::new(
            a0 * z0 + a1 * z1 + a2 * z2 + a3 * z3 + a4 * z4 + a5 * z5,
            b0 * z0 + b1 * z1 + b2 * z2 + b3 * z3 + b4 * z4 + b5 * z5,
            d0 * z0 + d1 * z1 + d2 * z2 + d3 * z3 + d4 * z4 + d5 * z5,
        );
        // `[p']x = M_f^T M_tau`: its entries (2,1), (0,2), (1,0).
        let p = Vector3::new(
            d3 * b0 + d4 * b1 + d5 * b2,
            a3 * d0 + a4 * d1 + a5 * d2,
            b3 * a0 + b4 * a1 + b5 * a2,
        );
        // `f^T P f = w_tau^2 |p' x f|^2 + w_f^2 |f|^2` (a sum, no cancellation).
        let ff = f.dot(f);
        let ll = res.tau2 * p.cross(f).norm_squared() + res.force2 * ff;
        (ll > T::zero() && ll.is_finite()).then(|| Self {
            rl: q.dot(f),
            q,
            p,
            ff,
            ll,
        })
    }
}

/// The share `c` of agent `i`'s commanded wrench that the residual lacks, `r = -c A f` in
/// least squares: the loss hypothesis' parameter, not clamped to `[0, 1]` (a mean of shares
/// is). `None` for an agent with no command to lose.
pub(super) fn share<T: Real>(
    res: &WeightedResidual<T>,
    m: &Matrix6x3<T>,
    f: &Vector3<T>,
) -> Option<T> {
    let x = Projection::new(res, m, f)?;
    let c = -x.rl / x.ll;
    c.is_finite().then_some(c)
}

/// Agent `i`'s explanation of the weighted residual (`m`: its block `M_i`, `f`: its commanded
/// force): the better of its two fault hypotheses, each with its misfit.
///
/// - Loss or partial loss: `r = -c W M_i f` for one `c` in `[0, 1]` (the share of the command
///   not delivered; efficiency `1 - c`, a loss at `c >= 0.8`).
/// - Stuck gimbal: `r = W M_i delta_f` with `delta_f` across `f` (the thrust kept, its
///   direction turned away from the command: the small-angle change), two parameters.
///
/// Both predict the residual from the agent's own command, so an agent whose span holds the
/// residual only with a force change unlike its own is not a candidate. `None` for an agent
/// with no command to lose (zero or non-finite force).
pub(super) fn fit<T: Real>(
    res: &WeightedResidual<T>,
    m: &Matrix6x3<T>,
    f: &Vector3<T>,
) -> Option<Fit<T>> {
    let Projection { q, p, ff, ll, rl } = Projection::new(res, m, f)?;
    let scale = res.tau2 * p.dot(&p) + res.force2;
    let (pf, pq) = (p.dot(f), p.dot(&q));
    let c = fmin(fmax(-rl / ll, T::zero()), T::one());
    let loss = fmax(res.rr + c * (rl + rl + c * ll), T::zero());
    // `x^T P^-1 y = (x.y + (w_tau^2 / w_f^2) (p'.x) (p'.y)) / scale`.
    let inverse = |xy: T, px: T, py: T| (xy + res.ratio * px * py) / scale;
    let ff_inv = inverse(ff, pf, pf);
    let stuck = if ff_inv > T::zero() && ff_inv.is_finite() {
        let fq_inv = inverse(rl, pf, pq);
        fmax(
            res.rr - inverse(q.dot(&q), pq, pq) + fq_inv * fq_inv / ff_inv,
            T::zero(),
        )
    } else {
        none()
    };
    // A squared misfit from differences may round just below zero: floored.
    let (misfit2, kind) = if stuck < loss {
        (stuck, FaultKind::StuckGimbal)
    } else {
        (loss, super::loss_kind(c))
    };
    misfit2.is_finite().then_some(Fit { misfit2, kind })
}

/// A misfit from its square, [`none`] kept as is.
pub(super) fn unsquare<T: Real>(misfit2: T) -> T {
    if misfit2 < none() {
        sqrt(misfit2)
    } else {
        none()
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::indexing_slicing)]
    use super::*;
    use crate::agent::effectiveness::agent_block;
    use crate::foundation::linalg::EuclideanNorm;
    use rand::{rngs::StdRng, Rng, SeedableRng};

    /// The misfits by the fits' definitions, in six dimensions: the loss by its clamped
    /// coefficient, the stuck gimbal by the least squares over two directions across `f`.
    fn direct(
        r: &Vector6<f64>,
        w: &Vector6<f64>,
        m: &Matrix6x3<f64>,
        f: &Vector3<f64>,
    ) -> (f64, f64) {
        let a = |v: &Vector3<f64>| (m * v).component_mul(w);
        let lost = a(f);
        let c = (-r.dot(&lost) / lost.dot(&lost)).clamp(0.0, 1.0);
        let loss = (r + lost * c).euclidean_norm();
        let e1 = f.cross(&Vector3::new(0.3, -0.7, 0.2)).normalize();
        let e2 = f.cross(&e1).normalize();
        let b = nalgebra::Matrix6x2::from_columns(&[a(&e1), a(&e2)]);
        let x = (b.transpose() * b).try_inverse().unwrap() * (b.transpose() * r);
        (loss, (r - b * x).euclidean_norm())
    }

    #[test]
    fn the_closed_form_misfits_are_the_fits_in_six_dimensions() {
        let mut rng = StdRng::seed_from_u64(47);
        for _ in 0..2000 {
            let p = Vector3::new(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-0.3..0.3),
            );
            let m = agent_block(&p, rng.random_range(0..4));
            let f = Vector3::new(
                rng.random_range(-3.0..3.0),
                rng.random_range(-3.0..3.0),
                rng.random_range(0.5..8.0),
            );
            let (tau, force) = (rng.random_range(0.5..20.0), rng.random_range(0.5..20.0));
            let w = Vector6::new(tau, tau, tau, force, force, force);
            // Half the residuals are an agent's hypothesis plus a little noise, half anything.
            let noise = Vector6::from_fn(|_, _| rng.random_range(-1.0..1.0));
            let r = if rng.random_bool(0.5) {
                -(m * f).component_mul(&w) * rng.random_range(0.0..1.2) + noise * 0.1
            } else {
                noise * 10.0
            };
            let (loss, stuck) = direct(&r, &w, &m, &f);
            let res = WeightedResidual::new(&r, r.norm_squared(), &w);
            let got = fit(&res, &m, &f).unwrap();
            // The share is the loss's least-squares coefficient, unclamped.
            let lost = (m * f).component_mul(&w);
            let c = -r.dot(&lost) / lost.dot(&lost);
            assert!((share(&res, &m, &f).unwrap() - c).abs() <= 1e-9 * c.abs().max(1.0));
            let scale = r.euclidean_norm().max(1.0);
            let (expected, kind_stuck) = if stuck < loss {
                (stuck, true)
            } else {
                (loss, false)
            };
            let misfit = unsquare(got.misfit2);
            assert!(
                (misfit - expected).abs() <= 1e-9 * scale,
                "misfit {misfit} against {expected} (loss {loss}, stuck {stuck})"
            );
            if (stuck - loss).abs() > 1e-6 * scale {
                assert_eq!(matches!(got.kind, FaultKind::StuckGimbal), kind_stuck);
            }
        }
    }

    #[test]
    fn no_command_no_fit_and_no_share() {
        let m = agent_block(&Vector3::new(0.5, 0.0, 0.0), 1);
        let w = Vector6::repeat(2.0);
        let r = Vector6::repeat(1.0);
        let res = WeightedResidual::new(&r, r.norm_squared(), &w);
        assert!(fit(&res, &m, &Vector3::zeros()).is_none());
        assert!(fit(&res, &m, &Vector3::new(f64::NAN, 0.0, 1.0)).is_none());
        assert!(fit(&res, &m, &Vector3::new(0.0, 0.0, 1.0)).is_some());
        assert!(share(&res, &m, &Vector3::zeros()).is_none());
        assert!(share(&res, &m, &Vector3::new(f64::NAN, 0.0, 1.0)).is_none());
    }
}
