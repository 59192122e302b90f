//! An allocator chosen by name and options and checked, but not made yet: small (the
//! exact-boundary redistribution's workspace is kilobytes), so a caller with little stack can
//! check a configuration first and make the allocator in place afterwards
//! ([`crate::Controller::init_in`]).

use super::names::{
    CAPPED_REDISTRIBUTION, CLARABEL, CLARABEL_SEQUENTIAL, EXACT_BOUNDARY_REDISTRIBUTION,
    PSEUDO_INVERSE, REDISTRIBUTED_PSEUDO_INVERSE, WEIGHTED_PSEUDO_INVERSE,
};
use super::{CappedRedistribution, RoundCap, WeightedPseudoInverse};
use crate::foundation::error::{ConfigError, ConfigField};
use crate::foundation::real::Real;

/// Options of [`super::AnyAllocator::from_name`]; each applies to one allocator only.
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
    /// Round cap of [`super::ExactBoundaryRedistribution::with_round_cap`] (`None`: the
    /// allocator's default, [`super::DEFAULT_MAX_ROUNDS`] rounds; [`RoundCap::Uncapped`] for
    /// the walk's own `2 n + 4`) and of [`CappedRedistribution`] (its rounds, at least 1;
    /// `None`: [`CappedRedistribution::DEFAULT_MAX_ROUNDS`]; `Uncapped`: every agent's
    /// round): bounds the allocator's work per period, see `docs/allocation-benchmark.md`.
    /// `Some(RoundCap::Rounds(_))` is refused by the other allocators; `Uncapped` is accepted
    /// by all (none caps anything).
    pub max_rounds: Option<RoundCap>,
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

/// A checked allocator choice: [`super::AnyAllocator::from_name`] is
/// `AnyAllocator::from_choice(AllocatorChoice::new(name, options)?)`.
///
/// ```
/// use tvmd_core::allocation::{AllocatorChoice, AllocatorOptions};
/// let choice = AllocatorChoice::<f32, 16>::new(
///     "exact-boundary-redistribution",
///     &AllocatorOptions::default(),
/// )?;
/// // Small: the exact-boundary redistribution's workspace is made only with the allocator.
/// assert!(core::mem::size_of_val(&choice) < core::mem::size_of::<tvmd_core::AnyAllocator<f32, 16>>() / 4);
/// let allocator = tvmd_core::AnyAllocator::from_choice(choice);
/// assert_eq!(allocator.name(), "exact-boundary-redistribution");
/// # Ok::<(), tvmd_core::ConfigError>(())
/// ```
#[derive(Clone, Debug)]
pub struct AllocatorChoice<T: Real, const N: usize>(Choice<T, N>);

/// The allocator a choice makes ([`super::AnyAllocator::from_choice`]).
///
/// Why a second enum of one variant per allocator beside [`super::AnyAllocator`]: a choice must
/// stay small, and an allocator cannot. The exact-boundary redistribution's workspace (its
/// held sets and factorizations, kilobytes at 16 agents) lives in the allocator, so a caller
/// on a flight controller's stack checks a choice here and has the allocator made in its own
/// storage afterwards (`Controller::init_in`, the C interface's `tvmd_create`). A variant
/// added to one enum does not compile until [`super::AnyAllocator::from_choice`] maps it to the
/// other.
#[derive(Clone, Debug)]
pub(super) enum Choice<T: Real, const N: usize> {
    PseudoInverse,
    Redistributed,
    ExactBoundary {
        max_rounds: RoundCap,
    },
    Weighted(WeightedPseudoInverse<T, N>),
    Capped(CappedRedistribution),
    #[cfg(feature = "clarabel")]
    Clarabel(super::ClarabelAllocator<T, N>),
    #[cfg(feature = "clarabel")]
    Sequential(super::SequentialConvexAllocator<T, N>),
}

impl<T: Real, const N: usize> AllocatorChoice<T, N> {
    /// The allocator named `name` (one of [`super::AnyAllocator::NAMES`]) with `options`,
    /// checked.
    ///
    /// Errors: as [`super::AnyAllocator::from_name`].
    pub fn new(name: &str, options: &AllocatorOptions<T, N>) -> Result<Self, ConfigError> {
        let refuse = |given: bool, field| {
            if given {
                Err(ConfigError::UnusedOption { field })
            } else {
                Ok(())
            }
        };
        let solver = matches!(name, CLARABEL | CLARABEL_SEQUENTIAL);
        if !solver
            && !matches!(
                name,
                PSEUDO_INVERSE
                    | REDISTRIBUTED_PSEUDO_INVERSE
                    | EXACT_BOUNDARY_REDISTRIBUTION
                    | WEIGHTED_PSEUDO_INVERSE
                    | CAPPED_REDISTRIBUTION
            )
        {
            return Err(ConfigError::UnknownAllocator);
        }
        // Each option is refused by every allocator but its own, checked in one order.
        refuse(
            options.agent_weights.is_some() && name != WEIGHTED_PSEUDO_INVERSE,
            ConfigField::AllocatorWeights,
        )?;
        if !solver {
            refuse(
                options.wrench_weights.is_some(),
                ConfigField::ClarabelWeights,
            )?;
            refuse(
                options.regularization.is_some(),
                ConfigField::ClarabelLambda,
            )?;
        }
        // A cap of some rounds is the walk's and the capped redistribution's alone;
        // "uncapped" promises no bound, which every allocator keeps (so a scenario naming it
        // may switch allocators).
        refuse(
            matches!(options.max_rounds, Some(RoundCap::Rounds(_)))
                && !matches!(name, EXACT_BOUNDARY_REDISTRIBUTION | CAPPED_REDISTRIBUTION),
            ConfigField::AllocatorMaxRounds,
        )?;
        let choice = match name {
            PSEUDO_INVERSE => Choice::PseudoInverse,
            REDISTRIBUTED_PSEUDO_INVERSE => Choice::Redistributed,
            EXACT_BOUNDARY_REDISTRIBUTION => Choice::ExactBoundary {
                max_rounds: options.max_rounds.unwrap_or_default(),
            },
            WEIGHTED_PSEUDO_INVERSE => {
                let weights = options.agent_weights.unwrap_or([T::one(); N]);
                Choice::Weighted(WeightedPseudoInverse::new(weights)?)
            }
            CAPPED_REDISTRIBUTION => Choice::Capped(match options.max_rounds {
                None => CappedRedistribution::default(),
                Some(RoundCap::Rounds(k)) => CappedRedistribution::new(k)?,
                Some(RoundCap::Uncapped) => CappedRedistribution::new(u32::MAX)?,
            }),
            _ => clarabel(name, options)?,
        };
        Ok(Self(choice))
    }

    pub(super) fn into_inner(self) -> Choice<T, N> {
        self.0
    }
}

#[cfg(feature = "clarabel")]
fn clarabel<T: Real, const N: usize>(
    name: &str,
    options: &AllocatorOptions<T, N>,
) -> Result<Choice<T, N>, ConfigError> {
    if name == CLARABEL {
        let lambda = options
            .regularization
            .unwrap_or_else(|| super::ClarabelAllocator::<T, N>::default().lambda());
        Ok(Choice::Clarabel(super::ClarabelAllocator::new(
            lambda,
            options.wrench_weights,
        )?))
    } else {
        let lambda = options.regularization.unwrap_or_else(T::zero);
        Ok(Choice::Sequential(super::SequentialConvexAllocator::new(
            lambda,
            options.wrench_weights,
        )?))
    }
}

#[cfg(not(feature = "clarabel"))]
fn clarabel<T: Real, const N: usize>(
    name: &str,
    _options: &AllocatorOptions<T, N>,
) -> Result<Choice<T, N>, ConfigError> {
    Err(ConfigError::AllocatorUnavailable {
        name: if name == CLARABEL {
            CLARABEL
        } else {
            CLARABEL_SEQUENTIAL
        },
    })
}
