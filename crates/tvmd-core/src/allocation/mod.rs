//! Control allocation: inverting `u_d = M f` (eq. 4) into admissible agent forces.
//!
//! As in PX4's control_allocator, the effectiveness model ([`Effectiveness`], what the team can
//! do) is separate from the algorithms that invert it; every algorithm implements [`Allocator`].
//! Every allocator returns forces inside each agent's [`AdmissibleSet`], so the command inversion
//! downstream never has to clamp more than round-off.

mod any;
mod choice;
#[cfg(feature = "clarabel")]
mod clarabel;
mod exact_boundary;
mod interior;
mod names;
mod null_space;
mod pseudo_inverse;
mod redistributed;

pub use any::AnyAllocator;
pub use choice::{AllocatorChoice, AllocatorOptions};
#[cfg(feature = "clarabel")]
pub use clarabel::{
    ClarabelAllocator, ClarabelStatus, FallbackReason, SequentialConvexAllocator, SequentialReport,
    SolveReport, StopReason,
};
pub use exact_boundary::{ExactBoundaryRedistribution, RoundCap, WalkCost, DEFAULT_MAX_ROUNDS};
pub use names::{
    CAPPED_REDISTRIBUTION, CLARABEL, CLARABEL_SEQUENTIAL, EXACT_BOUNDARY_REDISTRIBUTION,
    PSEUDO_INVERSE, REDISTRIBUTED_PSEUDO_INVERSE, WEIGHTED_PSEUDO_INVERSE,
};
pub use null_space::{
    NullSpaceObjective, NullSpaceReport, NullSpaceStage, MAX_NULL_SPACE_ITERATIONS,
};
pub use pseudo_inverse::{PseudoInverse, WeightedPseudoInverse};
pub use redistributed::{CappedRedistribution, RedistributedPseudoInverse};

use nalgebra::{Matrix6, Vector3, Vector6};

use crate::agent::admissible::AdmissibleSet;
use crate::agent::effectiveness::Effectiveness;
use crate::agent::gimbal::GimbalCommand;
use crate::foundation::linalg::{
    max_abs, norm, solve_gram, weighted_gram, wrench_parts, GramSolver,
};
use crate::foundation::real::{sqrt, Real};

/// What an allocator is asked to do.
#[derive(Clone, Copy, Debug)]
pub struct AllocationRequest<'a, T: Real, const N: usize> {
    /// `M(Xi)` of the working agents.
    pub effectiveness: &'a Effectiveness<T, N>,
    /// Each agent's admissible set (ignored for failed agents).
    pub sets: &'a [AdmissibleSet<T>; N],
    /// `u_d = [u_tau; u_f]`, the desired wrench in the team frame.
    pub wrench: Vector6<T>,
}

/// The result of one allocation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Allocation<T: Real, const N: usize> {
    /// Agent-frame forces `f_i`, each inside its admissible set; zero for failed agents.
    pub forces: [Vector3<T>; N],
    /// `u = M f`, the wrench the forces produce.
    pub wrench: Vector6<T>,
    /// `e_f = ||u_fd - u_f||`, the paper's allocation error (force part).
    pub e_f: T,
    /// `||u_d - M f||` over the whole wrench.
    pub wrench_error: T,
    /// Solve rounds used (pseudo-inverse: 1; redistribution: up to `n`; exact-boundary
    /// redistribution: its start's and its walk's, up to `3 n + 4`).
    pub rounds: u32,
    /// Agents whose force was saturated onto the boundary of their admissible set.
    pub saturated: [bool; N],
    /// The allocator could not solve and fell back to another method (see its docs).
    pub fallback: bool,
}

impl<T: Real, const N: usize> Allocation<T, N> {
    /// Completes an allocation from admissible forces: the wrench they produce and the errors
    /// against the request (overflow-safe norms: `e_f` is what these forces leave, at any
    /// magnitude of the request).
    pub fn from_forces(
        request: &AllocationRequest<'_, T, N>,
        forces: [Vector3<T>; N],
        rounds: u32,
        saturated: [bool; N],
    ) -> Self {
        let wrench = request.effectiveness.wrench(&forces);
        let error = request.wrench - wrench;
        Self {
            forces,
            wrench,
            e_f: norm(&wrench_parts(&error).1),
            wrench_error: norm(&error),
            rounds,
            saturated,
            fallback: false,
        }
    }

    /// Number of saturated agents.
    pub fn saturated_count(&self) -> usize {
        self.saturated.iter().filter(|s| **s).count()
    }
}

/// An allocation algorithm. `&mut self` lets an allocator keep warm-start data between periods.
pub trait Allocator<T: Real, const N: usize> {
    /// Tells the allocator the effectiveness model it will be asked to invert, once per
    /// change of team or failures (as PX4's `setEffectivenessMatrix`), so it can prepare
    /// factorizations. [`crate::Controller`] calls it in `new` and `set_failures`; the default
    /// does nothing.
    fn configure(&mut self, effectiveness: &Effectiveness<T, N>) {
        let _ = effectiveness;
    }

    /// Forgets what the allocator kept from earlier periods (a new flight, as
    /// [`crate::Controller::reset`]); the default does nothing.
    fn reset(&mut self) {}

    /// Allocates `request.wrench` over the working agents.
    fn allocate(&mut self, request: &AllocationRequest<'_, T, N>) -> Allocation<T, N>;

    /// A short name for logs ("pseudo-inverse", ...).
    fn name(&self) -> &'static str;

    /// Whether the bytes at `this` hold valid enum tags where the allocator keeps any, read raw
    /// (no reference made), for [`crate::Controller::storage_intact`]: a controller in memory a
    /// stray write may have changed (a C caller's handle). The default, for an allocator
    /// without tags, is `true`.
    ///
    /// # Safety
    /// `this` is aligned and points to `size_of::<Self>()` readable bytes.
    unsafe fn storage_intact(this: *const Self) -> bool
    where
        Self: Sized,
    {
        let _ = this;
        true
    }
}

/// The weighted pseudo-inverse over the agents selected by `free`:
/// `f_i = w_i^-1 M_i^T (sum_j w_j^-1 M_j M_j^T)^-1 r`, `O(n)` in agents.
pub(crate) fn pseudo_inverse_forces<T: Real, const N: usize>(
    effectiveness: &Effectiveness<T, N>,
    free: &[bool; N],
    weights: Option<&[T; N]>,
    factor: Option<&GramSolver<T>>,
    rhs: &Vector6<T>,
    out: &mut [Vector3<T>; N],
) {
    let weight = |i: usize| weights.and_then(|w| w.get(i)).copied().unwrap_or(T::one());
    let rhs = &bounded_rhs(rhs);
    let lambda = match factor {
        Some(f) => f.solve(rhs),
        None => solve_gram(&gram_of(effectiveness, free, weights), rhs),
    };
    for (i, ((block, f), slot)) in effectiveness
        .blocks()
        .iter()
        .zip(free)
        .zip(out.iter_mut())
        .enumerate()
    {
        if let (Some(b), true) = (block.as_ref(), *f) {
            *slot = b.tr_mul(&lambda) / weight(i);
        }
    }
}

/// `rhs` scaled down, in its direction, to a largest component of `sqrt(MAX)` (`1.8e19` in
/// `f32`, `1.3e154` in `f64`): the Gram solve and `M_i^T lambda` then stay finite, and a request
/// that large saturates every agent it loads anyway. The allocation's errors are still taken
/// against the full request.
fn bounded_rhs<T: Real>(rhs: &Vector6<T>) -> Vector6<T> {
    let cap = sqrt(T::max_value().unwrap_or_else(T::one));
    let m = max_abs(rhs);
    if m > cap && m.is_finite() {
        rhs * (cap / m)
    } else {
        *rhs
    }
}

/// Whether `force` must be saturated into `set`: outside it, or not finite (the gimbal inverse
/// of a non-finite force is the idle command, which may lie inside, so it is caught here rather
/// than kept).
#[inline]
pub(crate) fn outside<T: Real>(set: &AdmissibleSet<T>, force: &Vector3<T>) -> bool {
    outside_with(set, force, GimbalCommand::from_force)
}

/// [`outside`] with [`GimbalCommand::from_force_fast`] (the exact-boundary redistribution's).
#[inline]
pub(crate) fn outside_fast<T: Real>(set: &AdmissibleSet<T>, force: &Vector3<T>) -> bool {
    outside_with(set, force, GimbalCommand::from_force_fast)
}

/// [`outside`] with the gimbal inverse given (one copy for both: the C interface's text is
/// bounded).
#[inline(never)]
fn outside_with<T: Real>(
    set: &AdmissibleSet<T>,
    force: &Vector3<T>,
    inverse: fn(&Vector3<T>) -> GimbalCommand<T>,
) -> bool {
    !force.iter().all(|x| x.is_finite()) || set.violation(&inverse(force)) > T::zero()
}

/// `sum_{i free} M_i M_i^T / w_i`.
pub(crate) fn gram_of<T: Real, const N: usize>(
    effectiveness: &Effectiveness<T, N>,
    free: &[bool; N],
    weights: Option<&[T; N]>,
) -> Matrix6<T> {
    let weight = |i: usize| weights.and_then(|w| w.get(i)).copied().unwrap_or(T::one());
    weighted_gram(
        Matrix6::zeros(),
        effectiveness
            .blocks()
            .iter()
            .zip(free)
            .enumerate()
            .filter_map(|(i, (block, f))| block.as_ref().filter(|_| *f).map(|b| (b, weight(i)))),
    )
}

/// Working agents as a mask.
pub(crate) fn working_mask<T: Real, const N: usize>(e: &Effectiveness<T, N>) -> [bool; N] {
    let mut mask = [false; N];
    for (m, b) in mask.iter_mut().zip(e.blocks()) {
        *m = b.is_some();
    }
    mask
}
