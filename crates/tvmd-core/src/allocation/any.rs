//! Run-time choice of allocator (for configuration files and bindings), and the one table of
//! allocator names.

use super::{
    Allocation, AllocationRequest, Allocator, ExactBoundaryRedistribution, PseudoInverse,
    RedistributedPseudoInverse, WeightedPseudoInverse,
};
use crate::effectiveness::Effectiveness;
use crate::error::{ConfigError, ConfigField};
use crate::real::Real;

use super::names::{
    CLARABEL, CLARABEL_SEQUENTIAL, EXACT_BOUNDARY_REDISTRIBUTION, PSEUDO_INVERSE,
    REDISTRIBUTED_PSEUDO_INVERSE, WEIGHTED_PSEUDO_INVERSE,
};

#[cfg(feature = "clarabel")]
const NAMES: &[&str] = &[
    EXACT_BOUNDARY_REDISTRIBUTION,
    REDISTRIBUTED_PSEUDO_INVERSE,
    PSEUDO_INVERSE,
    WEIGHTED_PSEUDO_INVERSE,
    CLARABEL,
    CLARABEL_SEQUENTIAL,
];
#[cfg(not(feature = "clarabel"))]
const NAMES: &[&str] = &[
    EXACT_BOUNDARY_REDISTRIBUTION,
    REDISTRIBUTED_PSEUDO_INVERSE,
    PSEUDO_INVERSE,
    WEIGHTED_PSEUDO_INVERSE,
];

/// Options of [`AnyAllocator::from_name`]; each applies to one allocator only.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AllocatorOptions<T: Real, const N: usize> {
    /// Per-agent weights `w_i` of [`WeightedPseudoInverse`] (default: all 1).
    pub agent_weights: Option<[T; N]>,
    /// Wrench weights `W` of `ClarabelAllocator` and `SequentialConvexAllocator` (default:
    /// identity).
    pub wrench_weights: Option<[T; 6]>,
    /// Regularisation `lambda` of `ClarabelAllocator` (default `1e-6`) and
    /// `SequentialConvexAllocator` (default `0`).
    pub regularization: Option<T>,
    /// Round cap of [`ExactBoundaryRedistribution::with_max_rounds`] (default: none, the walk's
    /// own `2 n + 4`): bounds the allocator's work per period, see `docs/allocation-benchmark.md`.
    pub max_rounds: Option<u32>,
}

impl<T: Real, const N: usize> Default for AllocatorOptions<T, N> {
    fn default() -> Self {
        Self {
            agent_weights: None,
            wrench_weights: None,
            regularization: None,
            max_rounds: None,
        }
    }
}

/// One of the crate's allocators, chosen at run time.
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
#[derive(Clone, Debug)]
pub enum AnyAllocator<T: Real, const N: usize> {
    /// [`PseudoInverse`].
    PseudoInverse(PseudoInverse),
    /// [`WeightedPseudoInverse`].
    WeightedPseudoInverse(WeightedPseudoInverse<T, N>),
    /// [`RedistributedPseudoInverse`].
    RedistributedPseudoInverse(RedistributedPseudoInverse),
    /// [`ExactBoundaryRedistribution`].
    ExactBoundaryRedistribution(ExactBoundaryRedistribution<T, N>),
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
        let refuse = |given: bool, field| {
            if given {
                Err(ConfigError::UnusedOption { field })
            } else {
                Ok(())
            }
        };
        let no_clarabel_options = || {
            refuse(
                options.wrench_weights.is_some(),
                ConfigField::ClarabelWeights,
            )?;
            refuse(
                options.regularization.is_some(),
                ConfigField::ClarabelLambda,
            )
        };
        match name {
            PSEUDO_INVERSE | REDISTRIBUTED_PSEUDO_INVERSE | EXACT_BOUNDARY_REDISTRIBUTION => {
                refuse(
                    options.agent_weights.is_some(),
                    ConfigField::AllocatorWeights,
                )?;
                no_clarabel_options()?;
                refuse(
                    options.max_rounds.is_some() && name != EXACT_BOUNDARY_REDISTRIBUTION,
                    ConfigField::AllocatorMaxRounds,
                )?;
                Ok(match name {
                    PSEUDO_INVERSE => Self::PseudoInverse(PseudoInverse),
                    REDISTRIBUTED_PSEUDO_INVERSE => {
                        Self::RedistributedPseudoInverse(RedistributedPseudoInverse)
                    }
                    _ => Self::ExactBoundaryRedistribution(
                        ExactBoundaryRedistribution::new().with_max_rounds(options.max_rounds),
                    ),
                })
            }
            WEIGHTED_PSEUDO_INVERSE => {
                no_clarabel_options()?;
                refuse(
                    options.max_rounds.is_some(),
                    ConfigField::AllocatorMaxRounds,
                )?;
                let weights = options.agent_weights.unwrap_or([T::one(); N]);
                Ok(Self::WeightedPseudoInverse(WeightedPseudoInverse::new(
                    weights,
                )?))
            }
            CLARABEL | CLARABEL_SEQUENTIAL => {
                refuse(
                    options.agent_weights.is_some(),
                    ConfigField::AllocatorWeights,
                )?;
                refuse(
                    options.max_rounds.is_some(),
                    ConfigField::AllocatorMaxRounds,
                )?;
                if name == CLARABEL {
                    Self::clarabel(options)
                } else {
                    Self::clarabel_sequential(options)
                }
            }
            _ => Err(ConfigError::UnknownAllocator),
        }
    }

    #[cfg(feature = "clarabel")]
    fn clarabel(options: &AllocatorOptions<T, N>) -> Result<Self, ConfigError> {
        let lambda = options
            .regularization
            .unwrap_or_else(|| super::ClarabelAllocator::<T, N>::default().lambda());
        Ok(Self::Clarabel(super::ClarabelAllocator::new(
            lambda,
            options.wrench_weights,
        )?))
    }

    #[cfg(not(feature = "clarabel"))]
    fn clarabel(_options: &AllocatorOptions<T, N>) -> Result<Self, ConfigError> {
        Err(ConfigError::AllocatorUnavailable { name: CLARABEL })
    }

    #[cfg(feature = "clarabel")]
    fn clarabel_sequential(options: &AllocatorOptions<T, N>) -> Result<Self, ConfigError> {
        let lambda = options.regularization.unwrap_or_else(T::zero);
        Ok(Self::ClarabelSequential(
            super::SequentialConvexAllocator::new(lambda, options.wrench_weights)?,
        ))
    }

    #[cfg(not(feature = "clarabel"))]
    fn clarabel_sequential(_options: &AllocatorOptions<T, N>) -> Result<Self, ConfigError> {
        Err(ConfigError::AllocatorUnavailable {
            name: CLARABEL_SEQUENTIAL,
        })
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
    fn configure(&mut self, effectiveness: &Effectiveness<T, N>) {
        match self {
            Self::PseudoInverse(a) => a.configure(effectiveness),
            Self::WeightedPseudoInverse(a) => a.configure(effectiveness),
            Self::RedistributedPseudoInverse(a) => a.configure(effectiveness),
            Self::ExactBoundaryRedistribution(a) => a.configure(effectiveness),
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
            #[cfg(feature = "clarabel")]
            Self::Clarabel(a) => a.name(),
            #[cfg(feature = "clarabel")]
            Self::ClarabelSequential(a) => a.name(),
        }
    }
}
