//! The allocators' names: one spelling each, used by every allocator's `name()` and by the
//! run-time table ([`super::AnyAllocator`]).

/// Name of [`super::PseudoInverse`].
pub const PSEUDO_INVERSE: &str = "pseudo-inverse";
/// Name of [`super::WeightedPseudoInverse`].
pub const WEIGHTED_PSEUDO_INVERSE: &str = "weighted-pseudo-inverse";
/// Name of [`super::RedistributedPseudoInverse`] (the paper's).
pub const REDISTRIBUTED_PSEUDO_INVERSE: &str = "redistributed-pseudo-inverse";
/// Name of [`super::CappedRedistribution`].
pub const CAPPED_REDISTRIBUTION: &str = "capped-redistribution";
/// Name of [`super::ExactBoundaryRedistribution`], the default (`docs/method.md`, "Allocation").
pub const EXACT_BOUNDARY_REDISTRIBUTION: &str = "exact-boundary-redistribution";
/// Name of `ClarabelAllocator` (feature `clarabel`; known to every build so a build without
/// the feature can say what is missing).
pub const CLARABEL: &str = "clarabel";
/// Name of `SequentialConvexAllocator` (feature `clarabel`, known to every build as
/// [`CLARABEL`] is).
pub const CLARABEL_SEQUENTIAL: &str = "clarabel-sequential";
