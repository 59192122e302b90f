//! The constraints an agent is held on during one allocation, and the projection of its force
//! increments onto their tangent planes.

use nalgebra::{Matrix6x3, Vector3, Vector6};

use super::constraint::{Constraint, CONSTRAINTS};
use crate::foundation::linalg::norm;
use crate::foundation::real::{lit, Real};
use crate::foundation::stored::{bool_intact, Stored};

/// Constraints an agent is held on (bit `k` for constraint `k`), with the orthonormal normals of
/// their tangent planes at the agent's current force.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(in crate::allocation) struct ActiveSet<T: Real> {
    bits: u8,
    /// Constraints already let go once in this allocation: never again, so no cycling.
    released: u8,
    /// Orthonormal basis of the normals, up to two; three independent normals fix the force.
    basis: [Stored<Vector3<T>>; 2],
    fixed: bool,
    curved: bool,
    /// The held bits and the force of the last [`Self::update`]: the normals are the same while
    /// both are (a fixed agent, or every agent after a release re-solves).
    updated: Stored<(u8, Vector3<T>)>,
}

impl<T: Real> Default for ActiveSet<T> {
    fn default() -> Self {
        Self {
            bits: 0,
            released: 0,
            basis: [Stored::Absent, Stored::Absent],
            fixed: false,
            curved: false,
            updated: Stored::Absent,
        }
    }
}

impl<T: Real> ActiveSet<T> {
    /// Whether constraint `k` is held.
    pub(in crate::allocation) fn holds(&self, k: usize) -> bool {
        k < CONSTRAINTS && self.bits & (1 << k) != 0
    }

    /// Whether constraint `k` is held and may still be let go.
    pub(in crate::allocation) fn releasable(&self, k: usize) -> bool {
        self.holds(k) && self.released & (1 << k) == 0
    }

    /// Whether some held constraint may still be let go.
    pub(super) fn any_releasable(&self) -> bool {
        self.bits & !self.released != 0
    }

    /// Stops holding constraint `k` (the walk wants to leave it inward), once per allocation.
    pub(in crate::allocation) fn release(&mut self, k: usize) {
        if k < CONSTRAINTS {
            self.bits &= !(1 << k);
            self.released |= 1 << k;
        }
    }

    /// Whether the held normals span all three directions: the agent cannot move.
    pub(in crate::allocation) fn fixed(&self) -> bool {
        self.fixed
    }

    /// Holds constraint `k` from now on.
    pub(in crate::allocation) fn hold(&mut self, k: usize) {
        if k < CONSTRAINTS {
            self.bits |= 1 << k;
        }
    }

    /// Recomputes the normals at `force` (they turn with the force on a cone or a sphere).
    pub(in crate::allocation) fn update(
        &mut self,
        constraints: &[Constraint<T>; CONSTRAINTS],
        force: &Vector3<T>,
    ) {
        if self.updated == Stored::Present((self.bits, *force)) {
            return;
        }
        self.updated = Stored::Present((self.bits, *force));
        self.basis = [Stored::Absent, Stored::Absent];
        self.fixed = false;
        self.curved = false;
        let force_norm = norm(force);
        for (k, c) in constraints.iter().enumerate() {
            if !self.holds(k) {
                continue;
            }
            self.curved |= c.curved();
            let mut v = c.gradient_with_norm(force, force_norm);
            let length = norm(&v);
            if length <= T::zero() {
                continue;
            }
            v /= length;
            for u in self.basis.iter().flatten() {
                v -= u * u.dot(&v);
            }
            let rest = norm(&v);
            // A normal this close to the span of the others adds no direction of its own.
            if rest <= lit(1e-3) {
                continue;
            }
            let v = v / rest;
            match self.basis.iter_mut().find(|b| b.is_none()) {
                Some(slot) => *slot = Stored::Present(v),
                None => self.fixed = true,
            }
        }
    }

    /// `P d`, the part of `d` in every held tangent plane.
    pub(in crate::allocation) fn project(&self, d: &Vector3<T>) -> Vector3<T> {
        if self.fixed {
            return Vector3::zeros();
        }
        let mut p = *d;
        for u in self.basis.iter().flatten() {
            p -= u * u.dot(d);
        }
        p
    }

    /// Turns the agent's term `B B^T` of a Gram matrix into `B P B^T` (`B` its effectiveness
    /// block; `P` symmetric and idempotent, so `B P (B P)^T = B P B^T`): one rank-one downdate per
    /// held normal, or the whole term for a fixed agent. The lower triangle and diagonal only:
    /// the `L D L^T` reads nothing else (the same bits there, half the work on a Cortex-M4F).
    pub(in crate::allocation) fn downdate(
        &self,
        block: &Matrix6x3<T>,
        gram: &mut nalgebra::Matrix6<T>,
    ) {
        if self.fixed {
            // `gram -= B B^T`, each entry's sum in the order of nalgebra's product.
            let b = block.as_slice();
            let g = gram.as_mut_slice();
            for j in 0..6 {
                for i in j..6 {
                    // Column-major: `B[(i, k)]` at `6 k + i`, `gram[(i, j)]` at `6 j + i`.
                    let entry = |k: usize| match (b.get(6 * k + i), b.get(6 * k + j)) {
                        (Some(x), Some(y)) => *x * *y,
                        _ => T::zero(),
                    };
                    let mut s = entry(0);
                    s += entry(1);
                    s += entry(2);
                    if let Some(x) = g.get_mut(6 * j + i) {
                        *x -= s;
                    }
                }
            }
            return;
        }
        for u in self.basis.iter().flatten() {
            lower_downdate(gram, &(block * u));
        }
    }

    /// The orthonormal normals of the held tangent planes (up to two).
    #[cfg(feature = "null-space")]
    pub(in crate::allocation) fn normals(&self) -> impl Iterator<Item = &Vector3<T>> {
        self.basis.iter().flatten()
    }

    /// Whether [`Self::downdate`] changes a Gram matrix (a held normal, or a fixed agent).
    pub(in crate::allocation) fn downdates(&self) -> bool {
        self.fixed || self.basis.iter().any(Stored::is_some)
    }

    /// Whether a held constraint is a cone or a sphere.
    pub(in crate::allocation) fn curved(&self) -> bool {
        self.curved
    }
}

/// `gram -= v v^T` on the lower triangle and diagonal.
fn lower_downdate<T: Real>(gram: &mut nalgebra::Matrix6<T>, v: &Vector6<T>) {
    let v = v.as_slice();
    let g = gram.as_mut_slice();
    for j in 0..6 {
        for i in j..6 {
            if let (Some(x), Some(vi), Some(vj)) = (g.get_mut(6 * j + i), v.get(i), v.get(j)) {
                *x -= *vi * *vj;
            }
        }
    }
}

impl<T: Real> ActiveSet<T> {
    /// Whether the set at `this` holds valid tags: the basis's two, the last update's and the
    /// two flags. Reads only.
    ///
    /// # Safety
    /// `this` is aligned and points to `size_of::<Self>()` readable bytes.
    pub(in crate::allocation) unsafe fn storage_intact(this: *const Self) -> bool {
        let basis = core::ptr::addr_of!((*this).basis).cast::<Stored<Vector3<T>>>();
        Stored::tag_intact(basis)
            && Stored::tag_intact(basis.add(1))
            && Stored::tag_intact(core::ptr::addr_of!((*this).updated))
            && bool_intact(core::ptr::addr_of!((*this).fixed))
            && bool_intact(core::ptr::addr_of!((*this).curved))
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::indexing_slicing)]
    use super::*;
    use crate::agent::admissible::AdmissibleSet;
    use crate::agent::gimbal::GimbalCommand;
    use crate::agent::limits::Interval;
    use crate::allocation::exact_boundary::constraint::constraints;

    #[test]
    fn held_normals_are_removed_from_steps_and_three_fix_the_agent() {
        let set = AdmissibleSet::new(
            Interval { lo: -0.5, hi: 0.5 },
            Interval { lo: -0.5, hi: 0.5 },
            Interval { lo: 0.0, hi: 10.0 },
        )
        .unwrap();
        let cs = constraints(&set);
        // On the corner eta_x = 0.5, eta_y = 0.5, T = 10: three independent normals.
        let corner = GimbalCommand {
            thrust: 10.0,
            eta_x: 0.5,
            eta_y: 0.5,
        }
        .force();
        let mut active = ActiveSet::<f64>::default();
        let d = Vector3::new(1.0, -2.0, 3.0);
        active.hold(4);
        active.update(&cs, &corner);
        let p = active.project(&d);
        assert!(p.dot(&cs[4].gradient(&corner)).abs() < 1e-12);
        assert!((active.project(&p) - p).norm() < 1e-12);
        active.hold(0);
        active.update(&cs, &corner);
        let p = active.project(&d);
        assert!(p.dot(&cs[0].gradient(&corner)).abs() < 1e-12);
        assert!(p.dot(&cs[4].gradient(&corner)).abs() < 1e-12);
        assert!(!active.fixed() && p.norm() > 1e-3);
        active.hold(2);
        active.update(&cs, &corner);
        assert!(active.fixed());
        assert_eq!(active.project(&d), Vector3::zeros());
    }

    #[test]
    fn downdate_gives_the_projected_block_product() {
        let block = Matrix6x3::<f64>::from_fn(|i, j| (i as f64 * 0.7 + j as f64 * 1.3).sin());
        let set = AdmissibleSet::new(
            Interval { lo: -0.5, hi: 0.5 },
            Interval { lo: -0.5, hi: 0.5 },
            Interval { lo: 0.0, hi: 10.0 },
        )
        .unwrap();
        let cs = constraints(&set);
        let f = Vector3::<f64>::new(1.0, 2.0, 9.0);
        let mut active = ActiveSet::default();
        active.hold(4);
        active.update(&cs, &f);
        let n = f / f.norm();
        let p = nalgebra::Matrix3::identity() - n * n.transpose();
        let want = block * p * block.transpose();
        let mut got = block * block.transpose();
        active.downdate(&block, &mut got);
        assert!((got - want).lower_triangle().norm() < 1e-12);
        // The lower triangle in the same bits as the whole matrices' products, held or fixed.
        let full = block * block.transpose();
        let v: Vector6<f64> = block * n;
        for (fixed, want) in [(false, full - v * v.transpose()), (true, full - full)] {
            let mut got = full;
            if fixed {
                active.hold(0);
                active.hold(2);
                active.update(&cs, &f);
                assert!(active.fixed());
            }
            active.downdate(&block, &mut got);
            for j in 0..6 {
                for i in j..6 {
                    assert_eq!(got[(i, j)].to_bits(), want[(i, j)].to_bits(), "{i} {j}");
                }
            }
        }
    }
}
