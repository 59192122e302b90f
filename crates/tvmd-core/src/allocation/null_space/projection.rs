//! Steps that leave the wrench alone: the projection onto `null(M)` and the drift it may leave.

use nalgebra::Vector3;

#[cfg(feature = "null-space")]
use super::super::exact_boundary::active::ActiveSet;
use crate::agent::effectiveness::Effectiveness;
use crate::foundation::linalg::norm;
#[cfg(feature = "null-space")]
use crate::foundation::linalg::solve_gram;
use crate::foundation::real::{eps, lit, Real};

/// The step direction in `null(M)` for gradient `g`, with every agent that sits on a boundary
/// of its set kept from crossing it (`active[i]` holds those constraints, updated at the
/// forces): with `P_i` the projection onto agent `i`'s held tangent planes and `q_i` the inward
/// part of `g_i` along its held normals (`sum_u u min(g_i . u, 0)`), `d_i = P_i (g_i - M_i^T
/// lambda) + q_i` with `(sum_j M_j P_j M_j^T) lambda = M (P g + q)`, so `M d = 0` to round-off
/// and a held agent moves along or into its set, never out (`P = I`, `q = 0` without held
/// boundaries: `d = g - M^T (M M^T)^-1 M g`). Zero for failed agents. `None` when the result is
/// not finite. A `frozen` agent does not move (`P_i = 0`, `q_i = 0`).
#[cfg(feature = "null-space")]
pub(super) fn project_null<T: Real, const N: usize>(
    effectiveness: &Effectiveness<T, N>,
    active: &[ActiveSet<T>; N],
    frozen: &[bool; N],
    g: &[Vector3<T>; N],
) -> Option<[Vector3<T>; N]> {
    let mut gram = effectiveness.gram();
    let mut moved = [Vector3::zeros(); N];
    let mut inward = [Vector3::zeros(); N];
    for (((((block, a), gi), m), q), cold) in effectiveness
        .blocks()
        .iter()
        .zip(active)
        .zip(g)
        .zip(moved.iter_mut())
        .zip(inward.iter_mut())
        .zip(frozen)
    {
        if let (Some(b), true) = (block.as_ref(), *cold) {
            gram -= b * b.transpose();
        } else if let Some(b) = block.as_ref() {
            a.downdate(b, &mut gram);
            if !a.fixed() {
                *q = a.normals().fold(Vector3::zeros(), |acc, u| {
                    acc + u * u.dot(gi).min(T::zero())
                });
            }
            *m = a.project(gi) + *q;
        }
    }
    let lambda = solve_gram(&gram, &effectiveness.wrench(&moved));
    let mut d = [Vector3::zeros(); N];
    for (((((slot, block), gi), a), q), cold) in d
        .iter_mut()
        .zip(effectiveness.blocks())
        .zip(g)
        .zip(active)
        .zip(&inward)
        .zip(frozen)
    {
        if let (Some(b), false) = (block.as_ref(), *cold) {
            *slot = a.project(&(gi - b.tr_mul(&lambda))) + q;
        }
    }
    d.iter()
        .all(|v| v.iter().all(|x| x.is_finite()))
        .then_some(d)
}

/// `1e3 eps max(1, max |M_ij|) max(sum_i ||f_i||, sum_i ||f_i'||)`: the wrench drift
/// `||M f' - M f||` the stage accepts (round-off of `M f` is about `eps |M| sum ||f_i||` per
/// product; the margin covers a few steps' projections and the Gram solve's conditioning).
pub(super) fn drift_bound<T: Real, const N: usize>(
    effectiveness: &Effectiveness<T, N>,
    before: &[Vector3<T>; N],
    after: &[Vector3<T>; N],
) -> T {
    let scale = effectiveness
        .blocks()
        .iter()
        .flatten()
        .fold(T::one(), |m, b| m.max(b.amax()));
    let total = |f: &[Vector3<T>; N]| {
        f.iter()
            .zip(effectiveness.blocks())
            .filter(|(_, b)| b.is_some())
            .fold(T::zero(), |s, (v, _)| s + norm(v))
    };
    eps::<T>() * lit(1e3) * scale * total(before).max(total(after))
}

#[cfg(all(test, feature = "null-space"))]
mod tests {
    #![allow(clippy::unwrap_used, clippy::indexing_slicing)]
    use super::*;

    #[test]
    fn projected_steps_leave_the_wrench_and_skip_failed_agents() {
        let positions = [
            Vector3::new(0.3, 0.3, 0.0),
            Vector3::new(-0.3, 0.3, 0.0),
            Vector3::new(-0.3, -0.3, 0.0),
            Vector3::new(0.3, -0.3, 0.1),
        ];
        let e: Effectiveness<f64, 4> =
            Effectiveness::new(positions.iter().enumerate().map(|(i, p)| (i, p, i as i32)));
        let g = [0, 1, 2, 3].map(|i| Vector3::new(1.0 + i as f64, -0.5, 2.0 * i as f64));
        let free = [ActiveSet::default(); 4];
        let d = project_null(&e, &free, &[false; 4], &g).unwrap();
        assert!(e.wrench(&d).norm() < 1e-12 * 10.0);
        // Idempotent: `d` is already in null(M).
        let again = project_null(&e, &free, &[false; 4], &d).unwrap();
        for (a, b) in again.iter().zip(&d) {
            assert!((a - b).norm() < 1e-12);
        }
        // Not the zero map: `g` has a null-space part.
        assert!(d.iter().map(|v| v.norm()).sum::<f64>() > 0.1);
        let bound = drift_bound(&e, &g, &d);
        assert!(bound > 0.0 && bound < 1e-9);
        // A frozen agent stays; the others still keep the wrench.
        let frozen = [false, true, false, false];
        let d = project_null(&e, &free, &frozen, &g).unwrap();
        assert_eq!(d[1], Vector3::zeros());
        assert!(e.wrench(&d).norm() < 1e-11 && d[0].norm() > 1e-3);
    }
}
