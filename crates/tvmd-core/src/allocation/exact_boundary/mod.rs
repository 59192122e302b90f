//! Exact-boundary incremental redistribution (the authors' "EBRCA", `docs/method.md`,
//! "Allocation"): walk from admissible forces toward the request and stop each agent on the
//! exact boundary of its admissible set, found in closed form, instead of clamping.

pub(super) mod active;
pub(super) mod constraint;
mod cost;
mod round_cap;
mod walk;
mod workspace;

use nalgebra::{Vector3, Vector6};

use self::constraint::regular;
pub use self::cost::WalkCost;
pub use self::round_cap::{RoundCap, DEFAULT_MAX_ROUNDS};
use self::walk::{on_boundary, Walk};
use self::workspace::Workspace;
use super::{
    outside_fast, redistributed::redistribute, working_mask, Allocation, AllocationRequest,
    Allocator,
};
use crate::agent::admissible::AdmissibleSet;
use crate::agent::effectiveness::Effectiveness;
use crate::agent::gimbal::GimbalCommand;
use crate::foundation::linalg::{max_abs, norm};
use crate::foundation::real::{eps, fmax, lit, Real};
use crate::foundation::stored::bool_intact;

/// Incremental allocation on the exact admissible boundary.
///
/// Each period starts from admissible forces `f`: the previous period's forces (saturated into
/// this period's sets) or the redistributed pseudo-inverse's, whichever leaves the smaller
/// torque-first wrench error (torque weighted by [`Self::TORQUE_PRIORITY`]). A previous-period
/// start that does not meet the request first moves in
/// `null(M)` toward the minimum-norm forces of its own wrench, as far as the exact sets allow,
/// so the internal forces of a saturation bleed off as the request returns inside instead of
/// jumping away at once later. Then, in rounds:
/// 1. the remaining wrench `r = u_d - M f` is spread over the agents that can still move,
///    each restricted to the tangent planes of the boundaries it is held on:
///    `delta_i = P_i M_i^T (sum_j M_j P_j M_j^T)^-1 r`;
/// 2. the step `tau <= 1` along `delta` stops where the first agent reaches a constraint of its
///    exact set (gimbal cones and planes of eq. 1, thrust spheres; closed form, see
///    `constraint.rs`), so no agent is ever clamped;
/// 3. that agent is held on that boundary from now on (a cone or sphere is re-entered after a
///    tangent step); an agent held on three independent boundaries stops moving.
///
/// It ends when `r` is spent, nothing can move, after its round cap ([`Self::with_round_cap`]:
/// 2 rounds by default, for a flight controller's period) or at most `2 n + 4` rounds. A start that
/// already meets the request is returned as it is. The result is the candidate (the
/// redistributed pseudo-inverse's forces, the walk's start and each of its points) with the
/// smallest torque-first error, so it is never worse than the redistributed pseudo-inverse by
/// that measure. The walk keeps `|eta_x|` one milliradian
/// inside `pi/2`, where the gimbal inverse is singular (see `constraint::regular`). Every force is
/// inside its set (the last rounds' forces are saturated if round-off left one outside).
/// `rounds` counts the start's rounds and the walk's; `saturated` marks agents that end on a boundary.
/// The previous forces are forgotten by [`Allocator::configure`] (new team or failures) and
/// [`Allocator::reset`].
///
/// Worst case ([`WalkCost::bound`], counted per allocation by [`Self::last_cost`]): with `n`
/// working agents, at most `n` start rounds, `2 n + 4` walk rounds, `4 n + 11` Gram solves,
/// `2 n + 5` releases and `2 n + 5` line searches.
///
/// ```
/// use tvmd_core::{team::presets, AdmissibleSet, AllocationRequest, Allocator, FailureMask};
/// use tvmd_core::{ExactBoundaryRedistribution, GimbalCommand, RedistributedPseudoInverse, RoundCap};
/// let team = presets::a4_inc::<f64, 4>()?;
/// let effectiveness = team.effectiveness(&FailureMask::none());
/// let set = AdmissibleSet::from_limits(team.limits());
/// let sets = [set; 4];
/// // Every agent on the same corner of its gimbal set: attainable by construction, and far
/// // beyond what clamping each angle separately recovers.
/// let corner = GimbalCommand { eta_x: set.eta_x().hi, eta_y: set.eta_y().hi, thrust: 4.0 };
/// let wrench = effectiveness.wrench(&[corner.force(); 4]);
/// let request = AllocationRequest { effectiveness: &effectiveness, sets: &sets, wrench };
/// let walked = ExactBoundaryRedistribution::new().with_round_cap(RoundCap::Uncapped).allocate(&request);
/// let clamped = RedistributedPseudoInverse.allocate(&request);
/// // Measured: 0.0185 against 0.936 (N and N m, the whole wrench), uncapped.
/// assert!(walked.wrench_error < 0.05 * clamped.wrench_error);
/// # Ok::<(), tvmd_core::ConfigError>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ExactBoundaryRedistribution<T: Real, const N: usize> {
    /// The previous forces, valid while `has_previous` is set (a value and a flag, not a
    /// [`crate::foundation::stored::Stored`]: as one, writing it each period cost the cycle about 500 Cortex-M4F
    /// instructions more).
    previous: [Vector3<T>; N],
    has_previous: bool,
    round_cap: RoundCap,
    last: WalkCost,
    workspace: Workspace<T, N>,
}

impl<T: Real, const N: usize> Default for ExactBoundaryRedistribution<T, N> {
    fn default() -> Self {
        Self {
            previous: [Vector3::zeros(); N],
            has_previous: false,
            round_cap: RoundCap::default(),
            last: WalkCost::default(),
            workspace: Workspace::default(),
        }
    }
}

impl<T: Real, const N: usize> ExactBoundaryRedistribution<T, N> {
    /// How much a torque error counts against a force error when the request cannot be met:
    /// 1 N m as much as `TORQUE_PRIORITY` N.
    ///
    /// The walk spreads the whole remaining wrench, so where it stalls the error can sit in the
    /// torque, and an attitude loop fed a torque it does not get drifts (measured: A4-Inc with one
    /// agent failed tilted to 0.6 rad in `agent-failure`'s descent when the walk's result was chosen
    /// by the plain wrench error). Choosing by this error keeps the torque first, as the
    /// redistributed pseudo-inverse does (it saturates agents, not the torque), and leaves every
    /// request the walk meets exactly unchanged.
    pub const TORQUE_PRIORITY: f64 = 100.0;

    /// A new allocator with no previous forces, its walk capped at [`DEFAULT_MAX_ROUNDS`].
    pub fn new() -> Self {
        Self::default()
    }

    /// The same allocator with its walk capped at `cap` ([`RoundCap::default`]: 2 rounds;
    /// [`RoundCap::Uncapped`]: the walk's own `2 n + 4`).
    pub fn with_round_cap(mut self, cap: RoundCap) -> Self {
        self.round_cap = cap;
        self
    }

    /// The cap of [`Self::with_round_cap`].
    pub fn round_cap(&self) -> RoundCap {
        self.round_cap
    }

    /// The work of the last allocation (zero before the first), within
    /// [`WalkCost::bound`]`(n, cap)`.
    pub fn last_cost(&self) -> WalkCost {
        self.last
    }

    /// The forces of the last allocation, the next one's candidate start.
    pub fn previous(&self) -> Option<&[Vector3<T>; N]> {
        self.has_previous.then_some(&self.previous)
    }
}

/// `f` of every set, computed once per run of equal sets (the agents usually share one set, and
/// the constraints cost trigonometry).
pub(in crate::allocation) fn per_set<T: Real, U: Copy, const N: usize>(
    sets: &[AdmissibleSet<T>; N],
    f: impl Fn(&AdmissibleSet<T>) -> U,
) -> [U; N] {
    let mut last: Option<(&AdmissibleSet<T>, U)> = None;
    sets.each_ref().map(|s| match last {
        Some((l, u)) if l == s => u,
        _ => {
            let u = f(s);
            last = Some((s, u));
            u
        }
    })
}

/// `||[w r_tau; r_f]||`, `w` = [`ExactBoundaryRedistribution::TORQUE_PRIORITY`]
/// (overflow-safe norm).
fn torque_first<T: Real>(r: &Vector6<T>) -> T {
    let w: T = lit(ExactBoundaryRedistribution::<T, 1>::TORQUE_PRIORITY);
    // Scaled first, so the weight cannot overflow a large but finite residual.
    let m = max_abs(r);
    if !(m > T::zero() && m.is_finite()) {
        return norm(r);
    }
    let mut weighted = r / m;
    for x in weighted.iter_mut().take(3) {
        *x *= w;
    }
    norm(&weighted) * m
}

impl<T: Real, const N: usize> Allocator<T, N> for ExactBoundaryRedistribution<T, N> {
    /// Forgets the previous forces: they belong to another team or failure mask.
    fn configure(&mut self, _effectiveness: &Effectiveness<T, N>) {
        self.has_previous = false;
    }

    fn reset(&mut self) {
        self.has_previous = false;
    }

    unsafe fn storage_intact(this: *const Self) -> bool {
        bool_intact(core::ptr::addr_of!((*this).has_previous))
            && RoundCap::storage_intact(core::ptr::addr_of!((*this).round_cap))
            && Workspace::storage_intact(core::ptr::addr_of!((*this).workspace))
    }

    fn allocate(&mut self, request: &AllocationRequest<'_, T, N>) -> Allocation<T, N> {
        let e = request.effectiveness;
        let working = working_mask(e);
        let sets = &per_set(request.sets, regular);
        let scale = fmax(max_abs(&request.wrench), T::one());
        let tol = eps::<T>() * lit(64.0) * scale;
        // The paper's redistribution, saturating without `libm`'s `f32` trigonometry.
        let start = redistribute(
            request,
            GimbalCommand::from_force_fast,
            AdmissibleSet::saturate_fast,
            u32::MAX,
        );
        let mut forces = start.forces;
        let mut moved = false;
        for ((f, set), ((given, saturated), w)) in forces
            .iter_mut()
            .zip(sets)
            .zip(request.sets.iter().zip(&start.saturated).zip(&working))
        {
            // A failed agent's zero force is not walked (its force stays zero). A working agent
            // the start left unsaturated was found inside `given` by the start's own test: the
            // same answer here when the set is unchanged (the gimbal inverse costs more than the
            // rest of an interior request's allocation on a Cortex-M4F).
            if !*w || (!*saturated && set == given) {
                continue;
            }
            if outside_fast(set, f) {
                *f = set.saturate_fast(f);
                moved = true;
            }
        }
        // Met by the start (hover, and most requests inside the attainable set): nothing to walk.
        self.last = WalkCost {
            start_rounds: start.rounds,
            ..WalkCost::default()
        };
        if !moved && max_abs(&(request.wrench - start.wrench)) <= tol {
            self.previous = start.forces;
            self.has_previous = true;
            return start;
        }
        // The redistributed pseudo-inverse keeps the torque whenever it can (it saturates agents,
        // not the torque); it stays a candidate for the result under the torque-first error.
        let rpi = (torque_first(&(request.wrench - e.wrench(&forces))), forces);
        if let Some(previous) = self.has_previous.then_some(&self.previous) {
            let mut kept = [Vector3::zeros(); N];
            for (((k, p), set), w) in kept.iter_mut().zip(previous).zip(sets).zip(&working) {
                if *w {
                    *k = if outside_fast(set, p) {
                        set.saturate_fast(p)
                    } else {
                        *p
                    };
                }
            }
            if torque_first(&(request.wrench - e.wrench(&kept))) < rpi.0 {
                forces = kept;
            }
        }
        self.workspace.prepare(sets);
        let Workspace {
            bounds,
            offsets,
            active,
            ..
        } = &mut self.workspace;
        let mut walk = Walk {
            effectiveness: e,
            sets,
            offsets,
            bounds,
            gram: e.gram(),
            working,
            forces,
            active,
            cost: WalkCost::default(),
        };
        // A kept start that already meets the request stays as it is (a repeated request keeps
        // its forces); any other sheds internal force before it walks.
        if forces != start.forces && max_abs(&walk.remaining(&request.wrench)) > tol {
            walk.shed_internal();
        }
        let limit = WalkCost::bound(e.working_count(), self.round_cap.rounds()).rounds;
        let mut rounds: u32 = 0;
        // The walk's best forces: a retraction onto a curved boundary can cost more wrench
        // than its step gained, and the result is never worse than the start.
        let mut best = rpi;
        while rounds < limit {
            let r = walk.remaining(&request.wrench);
            let error = torque_first(&r);
            if error < best.0 {
                best = (error, walk.forces);
            }
            // Written so a NaN residual stops the walk too.
            if max_abs(&r).partial_cmp(&tol) != Some(core::cmp::Ordering::Greater) {
                break;
            }
            let Some(delta) = walk.direction(&r, true) else {
                break;
            };
            rounds += 1;
            let (tau, stop) = walk.step(&delta);
            walk.advance(tau, &delta);
            for (a, k) in walk.active.iter_mut().zip(stop) {
                if let Some(k) = k {
                    a.hold(k);
                }
            }
        }
        let r = walk.remaining(&request.wrench);
        let error = torque_first(&r);
        if error < best.0 {
            best = (error, walk.forces);
        }
        let mut forces = best.1;
        let mut saturated = [false; N];
        for ((((f, set), b), w), s) in forces
            .iter_mut()
            .zip(sets)
            .zip(walk.bounds.iter())
            .zip(&working)
            .zip(saturated.iter_mut())
        {
            if !*w {
                *f = Vector3::zeros();
                continue;
            }
            if outside_fast(set, f) {
                *f = set.saturate_fast(f);
            }
            *s = on_boundary(b, set, f);
        }
        self.previous = forces;
        self.has_previous = true;
        self.last = WalkCost {
            start_rounds: start.rounds,
            rounds,
            ..walk.cost
        };
        Allocation::from_forces(request, forces, start.rounds + rounds, saturated)
    }

    fn name(&self) -> &'static str {
        super::names::EXACT_BOUNDARY_REDISTRIBUTION
    }
}

#[cfg(test)]
mod storage_tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use crate::foundation::stored::{accepts, refused_bytes};
    use crate::{team::presets, FailureMask};

    #[test]
    fn every_tag_and_flag_it_keeps_is_checked() {
        let team = presets::a4_inc::<f32, 4>().unwrap();
        let e = team.effectiveness(&FailureMask::none());
        let sets = [AdmissibleSet::from_limits(team.limits()); 4];
        let check = <ExactBoundaryRedistribution<f32, 4> as Allocator<f32, 4>>::storage_intact;
        let mut a = ExactBoundaryRedistribution::<f32, 4>::new().with_round_cap(RoundCap::Uncapped);
        assert!(accepts(&a, check));
        // A request past the attainable set: the walk runs and every agent's set is built.
        let wrench = Vector6::new(0.0, 0.0, 30.0, 40.0, 0.0, 60.0);
        a.allocate(&AllocationRequest {
            effectiveness: &e,
            sets: &sets,
            wrench,
        });
        assert!(a.has_previous && a.last.rounds > 0 && accepts(&a, check));
        // The previous forces' and the cap's tags, and per agent its built set's, its basis's
        // two, its last update's and its two flags.
        assert_eq!(refused_bytes(&a, 2, check), 2 + 4 * 6);
    }
}
