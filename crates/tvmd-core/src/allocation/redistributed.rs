//! Redistributed pseudo-inverse allocation (Jin 2005).

use nalgebra::Vector3;

use super::{pseudo_inverse_forces, working_mask, Allocation, AllocationRequest, Allocator};
use crate::agent::admissible::AdmissibleSet;
use crate::agent::effectiveness::Effectiveness;
use crate::agent::gimbal::GimbalCommand;
use crate::foundation::real::Real;

/// The redistributed pseudo-inverse (Jin 2005; `docs/method.md`, "Allocation"): solve the pseudo-inverse
/// over the free agents; if some leave their admissible set, saturate the one that leaves it
/// furthest (largest normalized excess, see [`crate::agent::admissible::AdmissibleSet::violation`]),
/// fix it, and redistribute the remaining wrench over the others. At most `n` rounds; agents
/// still outside after the last round are clamped. Failed agents never take part.
///
/// ```
/// use tvmd_core::nalgebra::Vector6;
/// use tvmd_core::{team::presets, AdmissibleSet, AllocationRequest, Allocator, FailureMask};
/// use tvmd_core::RedistributedPseudoInverse;
/// let team = presets::a4_inc::<f64, 4>()?;
/// let effectiveness = team.effectiveness(&FailureMask::none());
/// let sets = [AdmissibleSet::from_limits(team.limits()); 4];
/// let mut allocator = RedistributedPseudoInverse;
/// allocator.configure(&effectiveness);
/// // Hover: the weight shared by the four agents, exactly.
/// let wrench = Vector6::new(0.0, 0.0, 0.0, 0.0, 0.0, team.mass() * 9.81);
/// let out = allocator.allocate(&AllocationRequest { effectiveness: &effectiveness, sets: &sets, wrench });
/// assert!(out.e_f < 1e-12 && out.saturated_count() == 0);
/// # Ok::<(), tvmd_core::ConfigError>(())
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RedistributedPseudoInverse;

impl<T: Real, const N: usize> Allocator<T, N> for RedistributedPseudoInverse {
    /// Nothing to do: the factor of `M M^T` is kept by the [`Effectiveness`] itself.
    fn configure(&mut self, _effectiveness: &Effectiveness<T, N>) {}

    fn allocate(&mut self, request: &AllocationRequest<'_, T, N>) -> Allocation<T, N> {
        redistribute(request, GimbalCommand::from_force, AdmissibleSet::saturate)
    }

    fn name(&self) -> &'static str {
        super::names::REDISTRIBUTED_PSEUDO_INVERSE
    }
}

/// The redistribution of [`RedistributedPseudoInverse`], with the gimbal inverse `inverse` and
/// the saturation `saturate` (the paper's: [`GimbalCommand::from_force`],
/// [`AdmissibleSet::saturate`]; the exact-boundary redistribution's start: their `_fast`
/// forms, without `libm`'s software-`f64` trigonometry on a Cortex-M4F).
///
/// Function pointers, not generic closures: one copy of the redistribution for both callers
/// (the C interface's text is bounded, `scripts/ffi.sh`), not inlined into either.
#[inline(never)]
pub(super) fn redistribute<T: Real, const N: usize>(
    request: &AllocationRequest<'_, T, N>,
    inverse: fn(&Vector3<T>) -> GimbalCommand<T>,
    saturate: fn(&AdmissibleSet<T>, &Vector3<T>) -> Vector3<T>,
) -> Allocation<T, N> {
    {
        let e = request.effectiveness;
        let mut free = working_mask(e);
        let mut forces = [Vector3::zeros(); N];
        let mut saturated = [false; N];
        let mut rounds: u32 = 0;
        let n = e.working_count();
        while (rounds as usize) < n {
            rounds += 1;
            let mut fixed_wrench = request.wrench;
            for ((block, f), is_free) in e.blocks().iter().zip(&forces).zip(&free) {
                if let (Some(b), false) = (block, *is_free) {
                    fixed_wrench -= b * f;
                }
            }
            // Round 1 inverts every working agent: the effectiveness's own factor of `M M^T`.
            let factor = (rounds == 1).then(|| e.gram_solver());
            pseudo_inverse_forces(e, &free, None, factor, &fixed_wrench, &mut forces);
            let worst = forces
                .iter()
                .zip(request.sets)
                .zip(&free)
                .enumerate()
                .filter(|(_, (_, is_free))| **is_free)
                // `outside` with the one gimbal inverse per agent; a non-finite force counts as
                // the worst.
                .filter_map(|(i, ((f, set), _))| {
                    let v = set.violation(&inverse(f));
                    let finite = f.iter().all(|x| x.is_finite());
                    match (finite, v > T::zero()) {
                        (true, true) => Some((i, v)),
                        (true, false) => None,
                        (false, _) => Some((i, T::one() / T::zero())),
                    }
                })
                .fold(None, |best: Option<(usize, T)>, (i, v)| match best {
                    Some((_, bv)) if bv >= v => best,
                    _ => Some((i, v)),
                });
            let Some((j, _)) = worst else {
                return Allocation::from_forces(request, forces, rounds, saturated);
            };
            if let (Some(f), Some(set), Some(is_free), Some(sat)) = (
                forces.get_mut(j),
                request.sets.get(j),
                free.get_mut(j),
                saturated.get_mut(j),
            ) {
                *f = saturate(set, f);
                *is_free = false;
                *sat = true;
            }
        }
        // Out of rounds (every agent fixed, or the last ones still outside): clamp the rest.
        for (((f, set), is_free), sat) in forces
            .iter_mut()
            .zip(request.sets)
            .zip(&free)
            .zip(saturated.iter_mut())
        {
            if *is_free
                && (!f.iter().all(|x| x.is_finite()) || set.violation(&inverse(f)) > T::zero())
            {
                *f = saturate(set, f);
                *sat = true;
            }
        }
        Allocation::from_forces(request, forces, rounds, saturated)
    }
}
