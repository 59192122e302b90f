//! The walk's working set, kept in the allocator instead of on the stack: each agent's
//! constraints (built once per admissible set and kept while the set does not change), their
//! offsets, and the held sets. With 16 agents in `f32` it is about 3.7 KB, more than a flight
//! stack's work queue has (PX4: 2.2-3.2 KB), so every caller of `allocate` would pay it in stack.

use super::active::ActiveSet;
use super::constraint::{constraints, Constraint, CONSTRAINTS};
use super::walk::offset;
use crate::admissible::AdmissibleSet;
use crate::real::Real;

/// Scratch of one allocation, and the constraints of the sets it last saw.
#[derive(Clone, Copy, Debug)]
pub(super) struct Workspace<T: Real, const N: usize> {
    /// The set each agent's constraints were built from (`None`: not built).
    built_from: [Option<AdmissibleSet<T>>; N],
    pub(super) bounds: [[Constraint<T>; CONSTRAINTS]; N],
    /// Each agent's largest constraint offset `|k|` ([`offset`]), for the line search's rays.
    pub(super) offsets: [T; N],
    pub(super) active: [ActiveSet<T>; N],
}

impl<T: Real, const N: usize> Default for Workspace<T, N> {
    fn default() -> Self {
        Self {
            built_from: [None; N],
            bounds: [[Constraint::placeholder(); CONSTRAINTS]; N],
            offsets: [T::zero(); N],
            active: [ActiveSet::default(); N],
        }
    }
}

/// Scratch, not state: two allocators equal in everything else allocate alike whatever their
/// workspaces hold (every allocation rebuilds what it reads), so workspaces compare equal.
impl<T: Real, const N: usize> PartialEq for Workspace<T, N> {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

impl<T: Real, const N: usize> Workspace<T, N> {
    /// Ready for a walk over `sets`: each agent's constraints for its set (built only for a set
    /// that changed, and copied from the previous agent when it has the same set: the agents
    /// usually share one, and the constraints cost trigonometry), nothing held.
    pub(super) fn prepare(&mut self, sets: &[AdmissibleSet<T>; N]) {
        let mut previous: Option<(&AdmissibleSet<T>, [Constraint<T>; CONSTRAINTS])> = None;
        for (((set, built), bounds), (offset_of, active)) in sets
            .iter()
            .zip(self.built_from.iter_mut())
            .zip(self.bounds.iter_mut())
            .zip(self.offsets.iter_mut().zip(self.active.iter_mut()))
        {
            *active = ActiveSet::default();
            if built.as_ref() != Some(set) {
                *bounds = match previous {
                    Some((s, b)) if s == set => b,
                    _ => constraints(set),
                };
                *offset_of = offset(bounds);
                *built = Some(*set);
            }
            previous = Some((set, *bounds));
        }
    }
}
