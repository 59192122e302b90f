//! Run-time choice of allocator (for configuration files and bindings), and the one table of
//! allocator names.

use core::mem::align_of;

use super::choice::{AllocatorChoice, AllocatorOptions, Choice};
use super::{
    Allocation, AllocationRequest, Allocator, CappedRedistribution, ExactBoundaryRedistribution,
    PseudoInverse, RedistributedPseudoInverse, WeightedPseudoInverse,
};
use crate::agent::effectiveness::Effectiveness;
use crate::foundation::error::ConfigError;
use crate::foundation::real::Real;

use super::names::{
    CAPPED_REDISTRIBUTION, EXACT_BOUNDARY_REDISTRIBUTION, PSEUDO_INVERSE,
    REDISTRIBUTED_PSEUDO_INVERSE, WEIGHTED_PSEUDO_INVERSE,
};
#[cfg(feature = "clarabel")]
use super::names::{CLARABEL, CLARABEL_SEQUENTIAL};

#[cfg(feature = "clarabel")]
const NAMES: &[&str] = &[
    EXACT_BOUNDARY_REDISTRIBUTION,
    REDISTRIBUTED_PSEUDO_INVERSE,
    PSEUDO_INVERSE,
    WEIGHTED_PSEUDO_INVERSE,
    CAPPED_REDISTRIBUTION,
    CLARABEL,
    CLARABEL_SEQUENTIAL,
];
#[cfg(not(feature = "clarabel"))]
const NAMES: &[&str] = &[
    EXACT_BOUNDARY_REDISTRIBUTION,
    REDISTRIBUTED_PSEUDO_INVERSE,
    PSEUDO_INVERSE,
    WEIGHTED_PSEUDO_INVERSE,
    CAPPED_REDISTRIBUTION,
];

/// One of the crate's allocators, chosen at run time. Its checked-but-not-made counterpart is
/// the small `Choice` of [`AllocatorChoice`] (module `choice`, which says why the two stay two).
///
/// ```
/// use tvmd_core::{AnyAllocator, Allocator};
/// use tvmd_core::allocation::AllocatorOptions;
///
/// let names = AnyAllocator::<f64, 4>::NAMES;
/// assert_eq!(names[0], "exact-boundary-redistribution");
/// assert_eq!(AnyAllocator::<f64, 4>::default().name(), names[0]);
/// let a = AnyAllocator::<f64, 4>::from_name("pseudo-inverse", &AllocatorOptions::default())?;
/// assert_eq!(a.name(), "pseudo-inverse");
/// assert!(AnyAllocator::<f64, 4>::from_name("magic", &AllocatorOptions::default()).is_err());
/// # Ok::<(), tvmd_core::ConfigError>(())
/// ```
///
/// `repr(u8)`: the variant's tag is the first byte, in declaration order, so that
/// [`Allocator::storage_intact`] can check it raw.
#[derive(Clone, Debug)]
#[repr(u8)]
pub enum AnyAllocator<T: Real, const N: usize> {
    /// [`PseudoInverse`].
    PseudoInverse(PseudoInverse),
    /// [`WeightedPseudoInverse`].
    WeightedPseudoInverse(WeightedPseudoInverse<T, N>),
    /// [`RedistributedPseudoInverse`].
    RedistributedPseudoInverse(RedistributedPseudoInverse),
    /// [`ExactBoundaryRedistribution`].
    ExactBoundaryRedistribution(ExactBoundaryRedistribution<T, N>),
    /// [`CappedRedistribution`].
    CappedRedistribution(CappedRedistribution),
    /// [`super::ClarabelAllocator`] (feature `clarabel`).
    #[cfg(feature = "clarabel")]
    Clarabel(super::ClarabelAllocator<T, N>),
    /// [`super::SequentialConvexAllocator`] (feature `clarabel`).
    #[cfg(feature = "clarabel")]
    ClarabelSequential(super::SequentialConvexAllocator<T, N>),
}

impl<T: Real, const N: usize> AnyAllocator<T, N> {
    /// The names this build knows, the default first; `"clarabel"` and `"clarabel-sequential"`
    /// only with the feature.
    pub const NAMES: &'static [&'static str] = NAMES;

    /// The name of the default allocator.
    pub const DEFAULT_NAME: &'static str = EXACT_BOUNDARY_REDISTRIBUTION;

    /// The allocator named `name` (one of [`Self::NAMES`]) with `options`.
    ///
    /// Errors: [`ConfigError::UnknownAllocator`]; [`ConfigError::AllocatorUnavailable`] for
    /// `"clarabel"` and `"clarabel-sequential"` without the feature; [`ConfigError::UnusedOption`] for an option the
    /// allocator does not take; the allocator's own validation errors.
    pub fn from_name(name: &str, options: &AllocatorOptions<T, N>) -> Result<Self, ConfigError> {
        Ok(Self::from_choice(AllocatorChoice::new(name, options)?))
    }

    /// The allocator of a checked choice (with no previous forces): [`Self::from_name`] in two
    /// steps, for a caller that checks a configuration first and makes the allocator in place
    /// later ([`crate::Controller::init_in`]).
    // Inlined into the caller that writes the allocator in place (`Controller::init_in`'s
    // `make_at`): out of line, its frame held a second copy of the exact-boundary workspace
    // (the 16-agent C handle's `tvmd_create` and `tvmd_reconfigure` measured 9,996 and
    // 10,764 B of stack instead of 7,392 and 7,376).
    #[inline]
    pub fn from_choice(choice: AllocatorChoice<T, N>) -> Self {
        match choice.into_inner() {
            Choice::PseudoInverse => Self::PseudoInverse(PseudoInverse),
            Choice::Redistributed => Self::RedistributedPseudoInverse(RedistributedPseudoInverse),
            Choice::ExactBoundary { max_rounds } => Self::ExactBoundaryRedistribution(
                ExactBoundaryRedistribution::new().with_round_cap(max_rounds),
            ),
            Choice::Weighted(a) => Self::WeightedPseudoInverse(a),
            Choice::Capped(a) => Self::CappedRedistribution(a),
            #[cfg(feature = "clarabel")]
            Choice::Clarabel(a) => Self::Clarabel(a),
            #[cfg(feature = "clarabel")]
            Choice::Sequential(a) => Self::ClarabelSequential(a),
        }
    }

    /// The allocator's name, one of [`Self::NAMES`].
    pub fn name(&self) -> &'static str {
        Allocator::<T, N>::name(self)
    }
}

impl<T: Real, const N: usize> Default for AnyAllocator<T, N> {
    /// The exact-boundary redistribution, with no previous forces.
    fn default() -> Self {
        Self::ExactBoundaryRedistribution(ExactBoundaryRedistribution::new())
    }
}

impl<T: Real, const N: usize> Allocator<T, N> for AnyAllocator<T, N> {
    unsafe fn storage_intact(this: *const Self) -> bool {
        // The variants in declaration order (repr(u8)): 5, or 7 with `clarabel`; each a
        // `repr(C)` struct of the tag and the allocator, which starts at its alignment.
        unsafe fn inner<A: Allocator<T, N>, T: Real, const N: usize>(
            this: *const AnyAllocator<T, N>,
        ) -> bool {
            A::storage_intact(this.cast::<u8>().add(align_of::<A>()).cast::<A>())
        }
        match this.cast::<u8>().read() {
            // Unit structs and a round count (the walk bounds its rounds by `N` too).
            0 | 2 | 4 => true,
            1 => inner::<WeightedPseudoInverse<T, N>, T, N>(this),
            3 => inner::<ExactBoundaryRedistribution<T, N>, T, N>(this),
            // The `clarabel` allocators keep heap pointers no raw check can vouch for. The C
            // interface never builds one and is built without the feature; a build that
            // unifies it in (`--all-features`) accepts these two tags unchecked.
            #[cfg(feature = "clarabel")]
            5 | 6 => true,
            _ => false,
        }
    }

    fn configure(&mut self, effectiveness: &Effectiveness<T, N>) {
        match self {
            Self::PseudoInverse(a) => a.configure(effectiveness),
            Self::WeightedPseudoInverse(a) => a.configure(effectiveness),
            Self::RedistributedPseudoInverse(a) => a.configure(effectiveness),
            Self::ExactBoundaryRedistribution(a) => a.configure(effectiveness),
            Self::CappedRedistribution(a) => Allocator::<T, N>::configure(a, effectiveness),
            #[cfg(feature = "clarabel")]
            Self::Clarabel(a) => a.configure(effectiveness),
            #[cfg(feature = "clarabel")]
            Self::ClarabelSequential(a) => a.configure(effectiveness),
        }
    }

    fn reset(&mut self) {
        match self {
            Self::PseudoInverse(a) => Allocator::<T, N>::reset(a),
            Self::WeightedPseudoInverse(a) => a.reset(),
            Self::RedistributedPseudoInverse(a) => Allocator::<T, N>::reset(a),
            Self::ExactBoundaryRedistribution(a) => a.reset(),
            Self::CappedRedistribution(a) => Allocator::<T, N>::reset(a),
            #[cfg(feature = "clarabel")]
            Self::Clarabel(a) => a.reset(),
            #[cfg(feature = "clarabel")]
            Self::ClarabelSequential(a) => a.reset(),
        }
    }

    fn allocate(&mut self, request: &AllocationRequest<'_, T, N>) -> Allocation<T, N> {
        match self {
            Self::PseudoInverse(a) => a.allocate(request),
            Self::WeightedPseudoInverse(a) => a.allocate(request),
            Self::RedistributedPseudoInverse(a) => a.allocate(request),
            Self::ExactBoundaryRedistribution(a) => a.allocate(request),
            Self::CappedRedistribution(a) => a.allocate(request),
            #[cfg(feature = "clarabel")]
            Self::Clarabel(a) => a.allocate(request),
            #[cfg(feature = "clarabel")]
            Self::ClarabelSequential(a) => a.allocate(request),
        }
    }

    fn name(&self) -> &'static str {
        match self {
            Self::PseudoInverse(a) => Allocator::<T, N>::name(a),
            Self::WeightedPseudoInverse(a) => a.name(),
            Self::RedistributedPseudoInverse(a) => Allocator::<T, N>::name(a),
            Self::ExactBoundaryRedistribution(a) => a.name(),
            Self::CappedRedistribution(a) => Allocator::<T, N>::name(a),
            #[cfg(feature = "clarabel")]
            Self::Clarabel(a) => a.name(),
            #[cfg(feature = "clarabel")]
            Self::ClarabelSequential(a) => a.name(),
        }
    }
}
