//! The walk of the exact-boundary redistribution: its state over the agents, the direction of
//! a round (with the active-set release test), the line search to the first boundary, the step
//! and its algebraic retraction onto a curved boundary, and the count of that work
//! ([`WalkCost`]).

use nalgebra::{Matrix6, Vector3, Vector6};

use super::active::ActiveSet;
use super::constraint::{Constraint, Ray, CONSTRAINTS};
use super::cost::WalkCost;
use crate::agent::admissible::AdmissibleSet;
use crate::agent::effectiveness::Effectiveness;
use crate::foundation::linalg::{norm, solve_gram};
use crate::foundation::real::{eps, fmax, sqrt, Real};

/// The walk's state over the agents.
pub(super) struct Walk<'a, T: Real, const N: usize> {
    pub(super) effectiveness: &'a Effectiveness<T, N>,
    pub(super) sets: &'a [AdmissibleSet<T>; N],
    /// Each agent's constraints and their largest offset `|k|` ([`offset`], for the line
    /// search's rays), in the allocator's workspace.
    pub(super) bounds: &'a [[Constraint<T>; CONSTRAINTS]; N],
    pub(super) offsets: &'a [T; N],
    /// `sum_i M_i M_i^T` over the working agents, before any is held.
    pub(super) gram: Matrix6<T>,
    pub(super) working: [bool; N],
    pub(super) forces: [Vector3<T>; N],
    pub(super) active: &'a mut [ActiveSet<T>; N],
    /// The work done so far (solves, releases, line searches; the rounds are the caller's).
    pub(super) cost: WalkCost,
}

impl<T: Real, const N: usize> Walk<'_, T, N> {
    pub(super) fn remaining(&self, wrench: &Vector6<T>) -> Vector6<T> {
        wrench - self.effectiveness.wrench(&self.forces)
    }

    /// `delta` of step 1, or `None` when nothing can move or the solve is not finite.
    pub(super) fn direction(&mut self, r: &Vector6<T>, release: bool) -> Option<[Vector3<T>; N]> {
        let mut gram = self.gram;
        let mut movable = false;
        let mut downdated = false;
        for (((block, a), f), (w, b)) in self
            .effectiveness
            .blocks()
            .iter()
            .zip(self.active.iter_mut())
            .zip(&self.forces)
            .zip(self.working.iter().zip(self.bounds.iter()))
        {
            if let (Some(block), true) = (block.as_ref(), *w) {
                a.update(b, f);
                a.downdate(block, &mut gram);
                movable |= !a.fixed();
                downdated |= a.downdates();
            }
        }
        if !movable {
            return None;
        }
        self.cost.solves += 1;
        // Nothing held (the first round): the effectiveness's own factor of this Gram matrix,
        // the same bits as factoring it again.
        let lambda = if downdated {
            solve_gram(&gram, r)
        } else {
            self.effectiveness.gram_solver().solve(r)
        };
        // `M_i^T lambda`, the free increments, once for the release test and the step.
        let mut delta = [Vector3::zeros(); N];
        for ((d, block), w) in delta
            .iter_mut()
            .zip(self.effectiveness.blocks())
            .zip(&self.working)
        {
            if let (Some(block), true) = (block.as_ref(), *w) {
                *d = block.tr_mul(&lambda);
            }
        }
        if release && self.release_one(&delta) {
            return self.direction(r, false);
        }
        for ((d, a), w) in delta.iter_mut().zip(self.active.iter()).zip(&self.working) {
            if *w {
                *d = a.project(d);
            }
        }
        delta
            .iter()
            .all(|d| d.iter().all(|x| x.is_finite()))
            .then_some(delta)
    }

    /// Lets go of the held constraint the free increment `free_i = M_i^T lambda` leaves most steeply
    /// inward (an active-set method's multiplier test), if any: holding it would keep the agent
    /// on a boundary the request pulls it away from.
    fn release_one(&mut self, free: &[Vector3<T>; N]) -> bool {
        let mut worst: Option<(usize, usize, T)> = None;
        for (i, (((free, a), f), (w, b))) in free
            .iter()
            .zip(self.active.iter())
            .zip(&self.forces)
            .zip(self.working.iter().zip(self.bounds.iter()))
            .enumerate()
        {
            if !*w || !a.any_releasable() {
                continue;
            }
            let free_norm = norm(free);
            let f_norm = norm(f);
            for (k, c) in b.iter().enumerate().filter(|(k, _)| a.releasable(*k)) {
                let g = c.gradient_with_norm(f, f_norm);
                let scale = norm(&g) * free_norm;
                if scale.partial_cmp(&T::zero()) != Some(core::cmp::Ordering::Greater) {
                    continue;
                }
                let slope = g.dot(free) / scale;
                if slope < -sqrt(eps::<T>()) && worst.is_none_or(|(_, _, s)| slope < s) {
                    worst = Some((i, k, slope));
                }
            }
        }
        match worst.and_then(|(i, k, _)| self.active.get_mut(i).map(|a| (a, k))) {
            Some((a, k)) => {
                a.release(k);
                self.cost.releases += 1;
                true
            }
            None => false,
        }
    }

    /// Step 2: the largest `tau <= 1`, and for each agent the constraint it stops on: the one
    /// agent that stops the step, or, when the step is zero, every agent already on a boundary
    /// the increment leaves (held together, one round instead of one each).
    pub(super) fn step(&mut self, delta: &[Vector3<T>; N]) -> (T, [Option<usize>; N]) {
        self.cost.line_searches += 1;
        let mut tau = T::one();
        let mut first = None;
        let mut at_once = [None; N];
        for (i, ((((f, d), (b, offset)), a), (w, now))) in self
            .forces
            .iter()
            .zip(delta)
            .zip(self.bounds.iter().zip(self.offsets.iter()))
            .zip(self.active.iter())
            .zip(self.working.iter().zip(at_once.iter_mut()))
            .enumerate()
        {
            if !*w || a.fixed() {
                continue;
            }
            let Some(ray) = Ray::new(f, d, *offset) else {
                continue;
            };
            for (k, c) in b.iter().enumerate() {
                if a.holds(k) {
                    continue;
                }
                if let Some(t) = c.first_exit_along(&ray, tau) {
                    if t == T::zero() && now.is_none() {
                        *now = Some(k);
                    }
                    if t < tau {
                        tau = t;
                        first = Some((i, k));
                    }
                }
            }
        }
        if tau > T::zero() {
            at_once = [None; N];
            if let Some((i, k)) = first {
                if let Some(slot) = at_once.get_mut(i) {
                    *slot = Some(k);
                }
            }
        }
        (tau, at_once)
    }

    /// Moves by `tau delta`; agents that left their set by moving along a curved boundary's
    /// tangent (or by round-off) are put back on it.
    pub(super) fn advance(&mut self, tau: T, delta: &[Vector3<T>; N]) {
        for ((((f, d), (set, w)), a), b) in self
            .forces
            .iter_mut()
            .zip(delta)
            .zip(self.sets.iter().zip(&self.working))
            .zip(self.active.iter())
            .zip(self.bounds.iter())
        {
            if *w {
                *f += d * tau;
                // Only a tangent step on a cone or sphere leaves the set by more than round-off
                // (the final forces are checked with the gimbal inverse anyway). The set's own
                // constraints decide without `asin`/`atan2`.
                if a.curved() && violated(b, f) {
                    *f = retract(b, a, f);
                    if violated(b, f) {
                        *f = set.saturate_fast(f);
                    }
                }
            }
        }
    }
}

impl<T: Real, const N: usize> Walk<'_, T, N> {
    /// Moves the forces in `null(M)` toward the minimum-norm forces of their own wrench, as far
    /// as every agent's exact set allows (`M f` unchanged to round-off). The previous period's
    /// forces carry the internal forces of the last saturation; without this they persist
    /// until the redistributed pseudo-inverse's start is exact again, and the commands jump
    /// there (measured: 0.17 rad in one period on paper-tilt at `s = 1`).
    pub(super) fn shed_internal(&mut self) {
        self.cost.solves += 1;
        // `self.gram` is the effectiveness's Gram matrix: its factor, kept there.
        let lambda = self
            .effectiveness
            .gram_solver()
            .solve(&self.effectiveness.wrench(&self.forces));
        let mut delta = [Vector3::zeros(); N];
        for (((d, block), f), w) in delta
            .iter_mut()
            .zip(self.effectiveness.blocks())
            .zip(&self.forces)
            .zip(&self.working)
        {
            if let (Some(block), true) = (block.as_ref(), *w) {
                *d = block.tr_mul(&lambda) - f;
            }
        }
        if delta.iter().all(|d| d.iter().all(|x| x.is_finite())) {
            let (tau, _) = self.step(&delta);
            self.advance(tau, &delta);
        }
    }
}

/// `f` put back on the curved constraints it is held on, without trigonometry: onto a thrust
/// sphere first (a scaling, which keeps every cone), then onto a cone (`f_y` set at the held
/// `||f||`; see [`Constraint::retract`]). What this leaves outside (round-off, or a constraint
/// not held) is saturated by the caller with the gimbal inverse.
fn retract<T: Real>(
    bounds: &[Constraint<T>; CONSTRAINTS],
    active: &ActiveSet<T>,
    f: &Vector3<T>,
) -> Vector3<T> {
    let mut out = *f;
    // Spheres (4, 5) before cones (0, 1): a scaling keeps a cone, a cone fix keeps the norm.
    for k in [4, 5, 0, 1] {
        if let Some(c) = bounds.get(k).filter(|c| active.holds(k) && c.curved()) {
            if c.value(&out) > T::zero() {
                out = c.retract(&out);
            }
        }
    }
    out
}

/// The largest `|k|` of an agent's constraints (the scale its line-search rays need).
pub(super) fn offset<T: Real>(bounds: &[Constraint<T>; CONSTRAINTS]) -> T {
    bounds.iter().map(|c| c.offset()).fold(T::zero(), fmax)
}

/// Whether `f` is outside the set its constraints describe (or not finite): the same test as
/// [`outside`] up to round-off, with a dot product per constraint and one norm instead of the
/// gimbal inverse.
fn violated<T: Real>(bounds: &[Constraint<T>; CONSTRAINTS], f: &Vector3<T>) -> bool {
    if !f.iter().all(|x| x.is_finite()) {
        return true;
    }
    let n = norm(f);
    bounds.iter().any(|c| c.value_with_norm(f, n) > T::zero())
}

/// Whether `f` is on a constraint of its set, within `sqrt(eps)` of the largest thrust.
pub(super) fn on_boundary<T: Real>(
    bounds: &[Constraint<T>; CONSTRAINTS],
    set: &AdmissibleSet<T>,
    f: &Vector3<T>,
) -> bool {
    let tol = sqrt(eps::<T>()) * fmax(set.thrust().hi, T::one());
    bounds.iter().any(|c| c.value(f) > -tol)
}
