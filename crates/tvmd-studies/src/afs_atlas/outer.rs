//! Outer bounds by weak duality. For any `y` with `y . v = 1`, every attainable point
//! `w0 + t v` of the ray satisfies `t = y . (w0 + t v) - y . w0 <= h(y) - y . w0 =: D(y)`,
//! where `h` is the support function of the attainable wrench set ([`AtlasModel::support`],
//! closed form per agent). `D` is convex; its minimum is the farthest point of the ray in the
//! set's convex hull, and any `y` gives a valid bound, so an inexact minimizer only widens the
//! bracket. Minimized by BFGS with Armijo backtracking over the 5-dimensional affine set.

use nalgebra::{SMatrix, SVector, Vector6};
use tvmd_core::GimbalCommand;

use super::model::AtlasModel;
use super::ray::Ray;

type V5 = SVector<f64, 5>;
type M5 = SMatrix<f64, 5, 5>;

/// A dual value `D(y)` with its multiplier and the maximizing commands.
#[derive(Clone, Debug)]
pub struct DualBound {
    /// `D(y)`, an upper bound of the ray's farthest attainable `t`.
    pub value: f64,
    /// `y`, with `y . direction = 1`.
    pub multiplier: Vector6<f64>,
    /// The commands maximizing `y . w` over the set (each inside its box).
    pub commands: Vec<GimbalCommand<f64>>,
}

const MAX_ITERATIONS: usize = 400;

/// An orthonormal basis of the complement of the unit vector `v`.
fn complement(v: &Vector6<f64>) -> [Vector6<f64>; 5] {
    let mut basis = [Vector6::zeros(); 5];
    let mut axes: Vec<usize> = (0..6).collect();
    // Drop the axis most parallel to v.
    axes.sort_by(|a, b| v[*a].abs().total_cmp(&v[*b].abs()));
    for (k, &axis) in axes.iter().take(5).enumerate() {
        let mut e = Vector6::zeros();
        e[axis] = 1.0;
        let mut u = e - v * v[axis];
        for b in basis.iter().take(k) {
            u -= b * b.dot(&u);
        }
        basis[k] = u.normalize();
    }
    basis
}

/// `D(y)` and its gradient `w*(y) - w0` (the maximizers' wrench minus the origin).
fn dual(
    model: &AtlasModel,
    ray: &Ray,
    y: &Vector6<f64>,
) -> (f64, Vector6<f64>, Vec<GimbalCommand<f64>>) {
    let (h, commands) = model.support(y);
    let w = model.wrench(&commands);
    (h - y.dot(&ray.origin), w - ray.origin, commands)
}

/// The smallest `D(y)` found by BFGS from `start` (projected onto `y . direction = 1`).
pub fn minimize_dual(model: &AtlasModel, ray: &Ray, start: &Vector6<f64>) -> DualBound {
    let v = ray.direction;
    let basis = complement(&v);
    let to_y = |a: &V5| basis.iter().zip(a.iter()).fold(v, |y, (b, c)| y + b * *c);
    let mut a = V5::from_fn(|k, _| basis[k].dot(start));
    let eval = |a: &V5| {
        let y = to_y(a);
        let (value, g6, commands) = dual(model, ray, &y);
        (value, V5::from_fn(|k, _| basis[k].dot(&g6)), commands)
    };
    let (mut f, mut g, mut commands) = eval(&a);
    let mut best = DualBound {
        value: f,
        multiplier: to_y(&a),
        commands: commands.clone(),
    };
    let scale = model.scale();
    let mut h0 = 1.0 / scale;
    let mut h = M5::identity() * h0;
    let mut stalled = 0;
    for _ in 0..MAX_ITERATIONS {
        if !f.is_finite() || g.norm() <= 1e-12 * scale {
            break;
        }
        let mut p = -(h * g);
        if g.dot(&p) >= 0.0 {
            h = M5::identity() * h0;
            p = -(h * g);
        }
        let slope = g.dot(&p);
        let mut lambda = 1.0;
        let mut next = None;
        for _ in 0..40 {
            let trial = a + p * lambda;
            let (ft, gt, ct) = eval(&trial);
            if ft <= f + 1e-4 * lambda * slope {
                next = Some((trial, ft, gt, ct));
                break;
            }
            lambda *= 0.5;
        }
        let Some((a_new, f_new, g_new, c_new)) = next else {
            // No descent along the quasi-Newton direction: restart once from steepest descent.
            if h == M5::identity() * h0 {
                break;
            }
            h = M5::identity() * h0;
            continue;
        };
        let s = a_new - a;
        let yk = g_new - g;
        let sy = s.dot(&yk);
        if sy > 1e-16 * s.norm() * yk.norm() {
            if stalled == 0 && h == M5::identity() * h0 {
                h0 = sy / yk.norm_squared();
                h = M5::identity() * h0;
            }
            let rho = 1.0 / sy;
            let i = M5::identity();
            h = (i - s * yk.transpose() * rho) * h * (i - yk * s.transpose() * rho)
                + s * s.transpose() * rho;
        }
        stalled = if f - f_new <= 1e-14 * scale {
            stalled + 1
        } else {
            0
        };
        a = a_new;
        f = f_new;
        g = g_new;
        commands = c_new;
        if f < best.value {
            best = DualBound {
                value: f,
                multiplier: to_y(&a),
                commands: commands.clone(),
            };
        }
        if stalled >= 8 {
            break;
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn complement_is_orthonormal() {
        let v = Vector6::new(0.0, 0.0, 0.0, 0.6, 0.8, 0.0);
        let b = complement(&v);
        for (i, x) in b.iter().enumerate() {
            assert!(x.dot(&v).abs() < 1e-15);
            for (j, y) in b.iter().enumerate() {
                let want = if i == j { 1.0 } else { 0.0 };
                assert!((x.dot(y) - want).abs() < 1e-15);
            }
        }
    }
}
