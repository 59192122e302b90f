//! The walk's working set, kept in the allocator instead of on the stack: each agent's
//! constraints (built once per admissible set and kept while the set does not change), their
//! offsets, and the held sets. With 16 agents in `f32` it is about 3.7 KB, more than a flight
//! stack's work queue has (PX4: 2.2-3.2 KB), so every caller of `allocate` would pay it in stack.

use super::active::ActiveSet;
use super::constraint::{constraints, Constraint, CONSTRAINTS};
use super::walk::offset;
use crate::agent::admissible::AdmissibleSet;
use crate::foundation::real::Real;
use crate::foundation::stored::Stored;

/// Scratch of one allocation, and the constraints of the sets it last saw.
#[derive(Clone, Copy, Debug)]
pub(super) struct Workspace<T: Real, const N: usize> {
    /// The set each agent's constraints were built from (`None`: not built).
    built_from: [Stored<AdmissibleSet<T>>; N],
    pub(super) bounds: [[Constraint<T>; CONSTRAINTS]; N],
    /// Each agent's largest constraint offset `|k|` ([`offset`]), for the line search's rays.
    pub(super) offsets: [T; N],
    pub(super) active: [ActiveSet<T>; N],
}

impl<T: Real, const N: usize> Default for Workspace<T, N> {
    fn default() -> Self {
        Self {
            built_from: [Stored::Absent; N],
            bounds: [[Constraint::placeholder(); CONSTRAINTS]; N],
            offsets: [T::zero(); N],
            active: [ActiveSet::default(); N],
        }
    }
}

/// Scratch, not state: two allocators equal in everything else allocate alike whatever their
/// workspaces hold (an allocation rebuilds what it reads, or reuses constraints built from an
/// equal set), so workspaces compare equal.
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
        for i in 0..N {
            if let Some(active) = self.active.get_mut(i) {
                *active = ActiveSet::default();
            }
            let (Some(set), Some(built)) = (sets.get(i), self.built_from.get(i)) else {
                continue;
            };
            if built.as_ref() == Some(set) {
                continue;
            }
            // The previous agent's constraints are already this period's.
            let bounds = i
                .checked_sub(1)
                .filter(|&j| sets.get(j) == Some(set))
                .and_then(|j| self.bounds.get(j).copied())
                .unwrap_or_else(|| constraints(set));
            if let (Some(b), Some(o), Some(f)) = (
                self.bounds.get_mut(i),
                self.offsets.get_mut(i),
                self.built_from.get_mut(i),
            ) {
                *b = bounds;
                *o = offset(&bounds);
                *f = Stored::Present(*set);
            }
        }
    }
}

impl<T: Real, const N: usize> Workspace<T, N> {
    /// Whether the workspace at `this` holds valid tags: each agent's built set's and its
    /// held set's ([`ActiveSet::storage_intact`]). Reads only.
    ///
    /// # Safety
    /// `this` is aligned and points to `size_of::<Self>()` readable bytes.
    pub(super) unsafe fn storage_intact(this: *const Self) -> bool {
        let built = core::ptr::addr_of!((*this).built_from).cast::<Stored<AdmissibleSet<T>>>();
        let active = core::ptr::addr_of!((*this).active).cast::<ActiveSet<T>>();
        let mut intact = true;
        for i in 0..N {
            intact &= Stored::tag_intact(built.add(i)) && ActiveSet::storage_intact(active.add(i));
        }
        intact
    }
}
