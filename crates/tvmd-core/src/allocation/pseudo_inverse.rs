//! Moore-Penrose and weighted pseudo-inverse allocation, saturated per agent.

use nalgebra::Vector3;

use super::{pseudo_inverse_forces, working_mask, Allocation, AllocationRequest, Allocator};
use crate::error::{ConfigError, ConfigField};
use crate::gimbal::GimbalCommand;
use crate::real::Real;

/// `f = M^T (M M^T)^-1 u_d` through the 6x6 Gram matrix (`O(n)`), then each agent outside its
/// admissible set is clamped onto it (so the result is admissible but the wrench may be off;
/// [`super::RedistributedPseudoInverse`] redistributes what the clamp loses).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PseudoInverse;

impl<T: Real, const N: usize> Allocator<T, N> for PseudoInverse {
    fn allocate(&mut self, request: &AllocationRequest<'_, T, N>) -> Allocation<T, N> {
        saturated_pseudo_inverse(request, None)
    }

    fn name(&self) -> &'static str {
        super::any::PSEUDO_INVERSE
    }
}

/// The weighted pseudo-inverse: minimizes `sum_i w_i ||f_i||^2` subject to `M f = u_d`, then
/// clamps as [`PseudoInverse`]. A larger `w_i` makes agent `i` work less.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WeightedPseudoInverse<T: Real, const N: usize> {
    weights: [T; N],
}

impl<T: Real, const N: usize> WeightedPseudoInverse<T, N> {
    /// Validates positive, finite weights (one per capacity slot).
    pub fn new(weights: [T; N]) -> Result<Self, ConfigError> {
        if weights.iter().any(|w| !w.is_finite() || *w <= T::zero()) {
            return Err(ConfigError::Parameter {
                field: ConfigField::AllocatorWeights,
            });
        }
        Ok(Self { weights })
    }

    /// The weights.
    pub fn weights(&self) -> &[T; N] {
        &self.weights
    }
}

impl<T: Real, const N: usize> Allocator<T, N> for WeightedPseudoInverse<T, N> {
    fn allocate(&mut self, request: &AllocationRequest<'_, T, N>) -> Allocation<T, N> {
        saturated_pseudo_inverse(request, Some(&self.weights))
    }

    fn name(&self) -> &'static str {
        super::any::WEIGHTED_PSEUDO_INVERSE
    }
}

fn saturated_pseudo_inverse<T: Real, const N: usize>(
    request: &AllocationRequest<'_, T, N>,
    weights: Option<&[T; N]>,
) -> Allocation<T, N> {
    let working = working_mask(request.effectiveness);
    let mut forces = [Vector3::zeros(); N];
    pseudo_inverse_forces(
        request.effectiveness,
        &working,
        weights,
        &request.wrench,
        &mut forces,
    );
    let mut saturated = [false; N];
    for (((f, set), sat), ok) in forces
        .iter_mut()
        .zip(request.sets)
        .zip(saturated.iter_mut())
        .zip(working)
    {
        if ok && set.violation(&GimbalCommand::from_force(f)) > T::zero() {
            *f = set.saturate(f);
            *sat = true;
        }
    }
    Allocation::from_forces(request, forces, 1, saturated)
}
