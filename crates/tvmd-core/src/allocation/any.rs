//! Run-time choice of allocator (for configuration files and bindings).

use super::{
    Allocation, AllocationRequest, Allocator, PseudoInverse, RedistributedPseudoInverse,
    WeightedPseudoInverse,
};
use crate::real::Real;

/// One of the crate's allocators, chosen at run time.
#[derive(Clone, Debug)]
pub enum AnyAllocator<T: Real, const N: usize> {
    /// [`PseudoInverse`].
    PseudoInverse(PseudoInverse),
    /// [`WeightedPseudoInverse`].
    WeightedPseudoInverse(WeightedPseudoInverse<T, N>),
    /// [`RedistributedPseudoInverse`].
    RedistributedPseudoInverse(RedistributedPseudoInverse),
    /// [`super::ClarabelAllocator`] (feature `clarabel`).
    #[cfg(feature = "clarabel")]
    Clarabel(super::ClarabelAllocator<T, N>),
}

impl<T: Real, const N: usize> Default for AnyAllocator<T, N> {
    /// The redistributed pseudo-inverse.
    fn default() -> Self {
        Self::RedistributedPseudoInverse(RedistributedPseudoInverse)
    }
}

impl<T: Real, const N: usize> Allocator<T, N> for AnyAllocator<T, N> {
    fn allocate(&mut self, request: &AllocationRequest<'_, T, N>) -> Allocation<T, N> {
        match self {
            Self::PseudoInverse(a) => a.allocate(request),
            Self::WeightedPseudoInverse(a) => a.allocate(request),
            Self::RedistributedPseudoInverse(a) => a.allocate(request),
            #[cfg(feature = "clarabel")]
            Self::Clarabel(a) => a.allocate(request),
        }
    }

    fn name(&self) -> &'static str {
        match self {
            Self::PseudoInverse(a) => Allocator::<T, N>::name(a),
            Self::WeightedPseudoInverse(a) => a.name(),
            Self::RedistributedPseudoInverse(a) => Allocator::<T, N>::name(a),
            #[cfg(feature = "clarabel")]
            Self::Clarabel(a) => a.name(),
        }
    }
}
