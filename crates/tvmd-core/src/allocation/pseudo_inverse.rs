//! Moore-Penrose and weighted pseudo-inverse allocation, saturated per agent.

use nalgebra::Vector3;

use super::interior::Interior;
use super::{
    gram_of, outside, pseudo_inverse_forces, working_mask, Allocation, AllocationRequest, Allocator,
};
use crate::agent::effectiveness::Effectiveness;
use crate::foundation::error::{ConfigError, ConfigField};
use crate::foundation::linalg::GramSolver;
use crate::foundation::real::Real;
use crate::foundation::stored::Stored;

/// `f = M^T (M M^T)^-1 u_d` through the 6x6 Gram matrix (`O(n)`), then each agent outside its
/// admissible set is clamped onto it (so the result is admissible but the wrench may be off;
/// [`super::RedistributedPseudoInverse`] redistributes what the clamp loses).
///
/// ```
/// use tvmd_core::nalgebra::Vector6;
/// use tvmd_core::{team::presets, AdmissibleSet, AllocationRequest, Allocator, FailureMask};
/// use tvmd_core::PseudoInverse;
/// let team = presets::a4_inc::<f64, 4>()?;
/// let effectiveness = team.effectiveness(&FailureMask::none());
/// let sets = [AdmissibleSet::from_limits(team.limits()); 4];
/// let mut allocator = PseudoInverse;
/// allocator.configure(&effectiveness);
/// // Hover: the weight shared by the four agents, exactly.
/// let wrench = Vector6::new(0.0, 0.0, 0.0, 0.0, 0.0, team.mass() * 9.81);
/// let out = allocator.allocate(&AllocationRequest { effectiveness: &effectiveness, sets: &sets, wrench });
/// assert!(out.e_f < 1e-12 && out.saturated_count() == 0);
/// # Ok::<(), tvmd_core::ConfigError>(())
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PseudoInverse;

impl<T: Real, const N: usize> Allocator<T, N> for PseudoInverse {
    /// Nothing to do: the factor of `M M^T` is kept by the [`Effectiveness`] itself.
    fn configure(&mut self, _effectiveness: &Effectiveness<T, N>) {}

    fn allocate(&mut self, request: &AllocationRequest<'_, T, N>) -> Allocation<T, N> {
        let factor = request.effectiveness.gram_solver();
        saturated_pseudo_inverse(request, None, Some(factor))
    }

    fn name(&self) -> &'static str {
        super::names::PSEUDO_INVERSE
    }
}

/// The weighted pseudo-inverse: minimizes `sum_i w_i ||f_i||^2` subject to `M f = u_d`, then
/// clamps as [`PseudoInverse`]. A larger `w_i` makes agent `i` work less.
///
/// ```
/// use tvmd_core::nalgebra::Vector6;
/// use tvmd_core::{team::presets, AdmissibleSet, AllocationRequest, Allocator, FailureMask};
/// use tvmd_core::WeightedPseudoInverse;
/// let team = presets::a4_inc::<f64, 4>()?;
/// let effectiveness = team.effectiveness(&FailureMask::none());
/// let sets = [AdmissibleSet::from_limits(team.limits()); 4];
/// let mut allocator = WeightedPseudoInverse::new([1.0, 1.0, 2.0, 2.0])?;
/// allocator.configure(&effectiveness);
/// // Hover: the weight shared by the four agents, exactly.
/// let wrench = Vector6::new(0.0, 0.0, 0.0, 0.0, 0.0, team.mass() * 9.81);
/// let out = allocator.allocate(&AllocationRequest { effectiveness: &effectiveness, sets: &sets, wrench });
/// assert!(out.e_f < 1e-12 && out.saturated_count() == 0);
/// # Ok::<(), tvmd_core::ConfigError>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WeightedPseudoInverse<T: Real, const N: usize> {
    weights: [T; N],
    /// The factor of `M W^-1 M^T` from [`Allocator::configure`], with the working agents it
    /// was computed for (used only while they match the request's).
    configured: Stored<([bool; N], GramSolver<T>)>,
}

impl<T: Real, const N: usize> WeightedPseudoInverse<T, N> {
    /// Validates positive, finite weights (one per capacity slot).
    pub fn new(weights: [T; N]) -> Result<Self, ConfigError> {
        if weights.iter().any(|w| !w.is_finite() || *w <= T::zero()) {
            return Err(ConfigError::Parameter {
                field: ConfigField::AllocatorWeights,
            });
        }
        Ok(Self {
            weights,
            configured: Stored::Absent,
        })
    }

    /// The weights.
    pub fn weights(&self) -> &[T; N] {
        &self.weights
    }
}

impl<T: Real, const N: usize> Allocator<T, N> for WeightedPseudoInverse<T, N> {
    /// Factors `M W^-1 M^T` once for this effectiveness.
    fn configure(&mut self, effectiveness: &Effectiveness<T, N>) {
        let working = working_mask(effectiveness);
        let gram = gram_of(effectiveness, &working, Some(&self.weights));
        self.configured = Stored::Present((working, GramSolver::new(&gram)));
    }

    unsafe fn storage_intact(this: *const Self) -> bool {
        // The mask's flags each 0 or 1 (their OR has no other bit) and the factor's tag.
        Stored::storage_intact(core::ptr::addr_of!((*this).configured), |c| {
            let flags = core::ptr::addr_of!((*c).0).cast::<[u8; N]>().read();
            flags.iter().fold(0, |bits, f| bits | f) <= 1
                && GramSolver::storage_intact(core::ptr::addr_of!((*c).1))
        })
    }

    fn allocate(&mut self, request: &AllocationRequest<'_, T, N>) -> Allocation<T, N> {
        let working = working_mask(request.effectiveness);
        let factor = self
            .configured
            .as_ref()
            .filter(|(mask, _)| *mask == working)
            .map(|(_, f)| f);
        saturated_pseudo_inverse(request, Some(&self.weights), factor)
    }

    fn name(&self) -> &'static str {
        super::names::WEIGHTED_PSEUDO_INVERSE
    }
}

fn saturated_pseudo_inverse<T: Real, const N: usize>(
    request: &AllocationRequest<'_, T, N>,
    weights: Option<&[T; N]>,
    factor: Option<&GramSolver<T>>,
) -> Allocation<T, N> {
    let working = working_mask(request.effectiveness);
    let mut forces = [Vector3::zeros(); N];
    pseudo_inverse_forces(
        request.effectiveness,
        &working,
        weights,
        factor,
        &request.wrench,
        &mut forces,
    );
    let mut saturated = [false; N];
    // The agents' one set as a test without the gimbal inverse (the same decisions).
    let interior = Interior::shared(request.sets);
    for (((f, set), sat), ok) in forces
        .iter_mut()
        .zip(request.sets)
        .zip(saturated.iter_mut())
        .zip(working)
    {
        let inside = interior.as_ref().is_some_and(|t| t.holds(f));
        if ok && !inside && outside(set, f) {
            *f = set.saturate(f);
            *sat = true;
        }
    }
    Allocation::from_forces(request, forces, 1, saturated)
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::indexing_slicing)]
    use super::*;
    use crate::agent::admissible::AdmissibleSet;
    use crate::agent::failure::FailureMask;
    use crate::team::presets;
    use nalgebra::Vector6;

    #[test]
    fn configured_factor_gives_the_same_bits_as_a_fresh_one() {
        let team = presets::a4_inc::<f64, 4>().unwrap();
        let sets = [AdmissibleSet::from_limits(team.limits()); 4];
        let weights = [1.0, 2.0, 0.5, 3.0];
        for failed in [&[][..], &[1][..]] {
            let e = team.effectiveness(&FailureMask::with_failed(failed).unwrap());
            let request = AllocationRequest {
                effectiveness: &e,
                sets: &sets,
                wrench: Vector6::new(0.3, -0.2, 0.1, 1.0, -2.0, 25.0),
            };
            let mut fresh = WeightedPseudoInverse::new(weights).unwrap();
            let mut configured = fresh;
            configured.configure(&e);
            assert!(configured.configured.is_some());
            assert_eq!(configured.allocate(&request), fresh.allocate(&request));
            // The effectiveness's own factor of M M^T against a fresh factorization.
            let mut forces = [Vector3::zeros(); 4];
            let working = working_mask(&e);
            pseudo_inverse_forces(&e, &working, None, None, &request.wrench, &mut forces);
            assert_eq!(PseudoInverse.allocate(&request).forces.len(), 4);
            let mut cached = [Vector3::zeros(); 4];
            let f = e.gram_solver();
            pseudo_inverse_forces(&e, &working, None, Some(f), &request.wrench, &mut cached);
            assert_eq!(forces, cached);
        }
    }
}

#[cfg(test)]
mod storage_tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use crate::foundation::stored::{accepts, refused_bytes};
    use crate::{team::presets, FailureMask};

    #[test]
    fn its_tag_flags_and_factor_tag_are_checked() {
        let team = presets::a4_inc::<f32, 4>().unwrap();
        let check = <WeightedPseudoInverse<f32, 4> as Allocator<f32, 4>>::storage_intact;
        let mut a = WeightedPseudoInverse::new([1.0, 2.0, 1.0, 2.0]).unwrap();
        assert!(accepts(&a, check));
        a.configure(&team.effectiveness(&FailureMask::with_failed(&[1]).unwrap()));
        assert!(a.configured.is_some() && accepts(&a, check));
        // 3: past the option's and the flags' 0 or 1, and past the factor's three tags.
        assert_eq!(refused_bytes(&a, 3, check), 1 + 4 + 1);
    }
}
