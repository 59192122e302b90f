//! [`NullSpaceStage::refine`], the stage's ascent (cargo feature `null-space`, on by default:
//! without it the stage is not linked, and a controller refuses a null-space setting with
//! [`crate::ConfigError::StageUnavailable`]).

use nalgebra::Vector3;

use super::prepared::Prepared;
use super::projection::{self, project_null};
use super::{NullSpaceObjective, NullSpaceReport, NullSpaceStage, MAX_NULL_SPACE_ITERATIONS};
use crate::allocation::exact_boundary::active::ActiveSet;
use crate::allocation::exact_boundary::constraint::{
    constraints, regular, Constraint, CONSTRAINTS,
};
use crate::allocation::exact_boundary::per_set;
use crate::allocation::{outside, working_mask, Allocation, AllocationRequest};
use crate::foundation::linalg::{max_abs, norm};
use crate::foundation::real::{eps, lit, Real};

/// Halvings of a step before the stage gives up on it.
const HALVINGS: u32 = 8;

impl<T: Real> NullSpaceStage<T> {
    /// Refines `allocation` (the allocator's answer to `request`): the returned allocation has
    /// the refined forces, their wrench and errors against the request, the allocator's rounds
    /// and fallback flag, and `saturated` re-judged for the agents that moved (on a boundary
    /// within `sqrt(eps) T_max`). Unchanged forces return `allocation` itself.
    pub fn refine<const N: usize>(
        &self,
        request: &AllocationRequest<'_, T, N>,
        allocation: &Allocation<T, N>,
    ) -> (Allocation<T, N>, NullSpaceReport<T>) {
        let unchanged = (*allocation, NullSpaceReport::off());
        let e = request.effectiveness;
        let working = working_mask(e);
        let input = allocation.forces;
        let sets = &per_set(request.sets, regular);
        // An agent the allocator left just outside a set it walks in (the round-off of a
        // saturation) starts from its saturation when that is inside and within
        // `sqrt(eps) T_max` (the drift check below still holds it to the input's wrench); one
        // further out, or whose saturation is not inside either, keeps its force.
        let mut frozen = [false; N];
        let mut begin = input;
        for ((((z, b), f), (s, r)), w) in frozen
            .iter_mut()
            .zip(begin.iter_mut())
            .zip(&input)
            .zip(request.sets.iter().zip(sets))
            .zip(&working)
        {
            if !*w || (!outside(s, f) && !outside(r, f)) {
                continue;
            }
            let back = r.saturate(f);
            let near = norm(&(back - f)) <= eps::<T>().sqrt() * r.thrust().hi.max(T::one());
            if near && !outside(s, &back) && !outside(r, &back) {
                *b = back;
            } else {
                *z = true;
            }
        }
        let finite = input.iter().all(|f| f.iter().all(|x| x.is_finite()));
        if !finite || e.working_count() == 0 || frozen == working {
            return unchanged;
        }
        let objective = Prepared::new(self.objective, e, sets, working);
        let bounds = per_set(sets, |s| constraints(s));
        let reach = sets
            .iter()
            .zip(&working)
            .filter(|(_, w)| **w)
            .fold(T::zero(), |m, (s, _)| m.max(s.thrust().hi));
        let start = e.wrench(&input);
        let value0 = objective.value(&input);
        let margin0 = objective.smallest_margin(&input);
        if !value0.is_finite() || !margin0.is_finite() || !max_abs(&start).is_finite() {
            return unchanged;
        }
        let (mut forces, mut value, mut margin) = (
            begin,
            objective.value(&begin),
            objective.smallest_margin(&begin),
        );
        let mut iterations = 0;
        let margin_objective = matches!(self.objective, NullSpaceObjective::Margin);
        // The constant bounds it too: `new` allows no more, and a stored count a stray write
        // changed cannot spin the loop.
        let cap = self.iterations.min(MAX_NULL_SPACE_ITERATIONS);
        while iterations < cap {
            let active = hold_boundaries(&objective, &bounds, sets, &working, &forces);
            let Some(d) = project_null(e, &active, &frozen, &objective.gradient(&forces)) else {
                break;
            };
            let longest = d.iter().fold(T::zero(), |m, v| m.max(norm(v)));
            if longest.partial_cmp(&T::zero()) != Some(core::cmp::Ordering::Greater) {
                break;
            }
            let exit = first_exit(&bounds, &working, &forces, &d);
            let mut tau = (exit / lit(2.0)).min(reach / (longest * lit(4.0)));
            let mut kept = None;
            for _ in 0..HALVINGS {
                if tau.partial_cmp(&T::zero()) != Some(core::cmp::Ordering::Greater) {
                    break;
                }
                let mut next = forces;
                for ((f, di), w) in next.iter_mut().zip(&d).zip(&working) {
                    if *w {
                        *f += di * tau;
                    }
                }
                let v = objective.value(&next);
                let m = objective.smallest_margin(&next);
                let inside = next
                    .iter()
                    .zip(request.sets.iter().zip(sets))
                    .zip(working.iter().zip(&frozen))
                    .all(|((f, (s, r)), (w, z))| !*w || *z || (!outside(s, f) && !outside(r, f)));
                let drift = norm(&(e.wrench(&next) - start));
                if v > value
                    && (!margin_objective || m >= margin)
                    && inside
                    && drift <= projection::drift_bound(e, &input, &next)
                {
                    kept = Some((next, v, m));
                    break;
                }
                tau /= lit(2.0);
            }
            let Some((next, v, m)) = kept else {
                break;
            };
            (forces, value, margin) = (next, v, m);
            iterations += 1;
        }
        // Never worse than the input, also after the start's snap onto the sets.
        // Written so a NaN counts as worse.
        let at_least = |a: T, b: T| a >= b;
        let worse = !at_least(value, value0) || (margin_objective && !at_least(margin, margin0));
        if iterations == 0 || worse {
            let report = NullSpaceReport {
                ran: true,
                objective_before: value0,
                objective_after: value0,
                margin_before: margin0,
                margin_after: margin0,
                ..NullSpaceReport::off()
            };
            return (*allocation, report);
        }
        let mut saturated = allocation.saturated;
        let mut largest = T::zero();
        for ((((s, f), f0), (b, set)), w) in saturated
            .iter_mut()
            .zip(&forces)
            .zip(&input)
            .zip(bounds.iter().zip(sets))
            .zip(&working)
        {
            let change = norm(&(f - f0));
            largest = largest.max(change);
            if *w && change > T::zero() {
                let tol = eps::<T>().sqrt() * set.thrust().hi.max(T::one());
                *s = b.iter().any(|c| c.value(f) > -tol);
            }
        }
        let mut refined = Allocation::from_forces(request, forces, allocation.rounds, saturated);
        refined.fallback = allocation.fallback;
        let report = NullSpaceReport {
            ran: true,
            iterations,
            objective_before: value0,
            objective_after: value,
            margin_before: margin0,
            margin_after: margin,
            largest_force_change: largest,
            wrench_drift: norm(&(refined.wrench - start)),
        };
        (refined, report)
    }
}

/// Each working agent's constraints held for one step: those it is near (margin below
/// `1 / kappa`) and those it sits on (within `sqrt(eps) T_max`, whatever their range).
fn hold_boundaries<T: Real, const N: usize>(
    objective: &Prepared<T, N>,
    bounds: &[[Constraint<T>; CONSTRAINTS]; N],
    sets: &[crate::agent::admissible::AdmissibleSet<T>; N],
    working: &[bool; N],
    forces: &[Vector3<T>; N],
) -> [ActiveSet<T>; N] {
    let near = objective.near(forces);
    let mut active = [ActiveSet::default(); N];
    for (((((a, b), set), w), f), bits) in active
        .iter_mut()
        .zip(bounds)
        .zip(sets)
        .zip(working)
        .zip(forces)
        .zip(near)
    {
        if !*w {
            continue;
        }
        let tol = eps::<T>().sqrt() * set.thrust().hi.max(T::one());
        for (k, c) in b.iter().enumerate() {
            if c.value(f) > -tol || bits & (1 << k) != 0 {
                a.hold(k);
            }
        }
        a.update(b, f);
    }
    active
}

/// The first `tau` at which some working agent's `f_i + tau d_i` leaves its set (`MAX` when
/// none does).
fn first_exit<T: Real, const N: usize>(
    bounds: &[[Constraint<T>; CONSTRAINTS]; N],
    working: &[bool; N],
    forces: &[Vector3<T>; N],
    d: &[Vector3<T>; N],
) -> T {
    let mut tau = T::max_value().unwrap_or_else(T::one);
    for (((b, w), f), di) in bounds.iter().zip(working).zip(forces).zip(d) {
        if !*w {
            continue;
        }
        for c in b {
            if let Some(t) = c.first_exit(f, di) {
                tau = tau.min(t);
            }
        }
    }
    tau
}
