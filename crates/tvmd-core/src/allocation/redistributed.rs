//! Redistributed pseudo-inverse allocation (Jin 2005).

use nalgebra::Vector3;

use super::interior::Interior;
use super::{pseudo_inverse_forces, working_mask, Allocation, AllocationRequest, Allocator};
use crate::agent::admissible::AdmissibleSet;
use crate::agent::effectiveness::Effectiveness;
use crate::agent::gimbal::GimbalCommand;
use crate::foundation::error::{ConfigError, ConfigField};
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
        redistribute(
            request,
            GimbalCommand::from_force,
            AdmissibleSet::saturate,
            u32::MAX,
        )
    }

    fn name(&self) -> &'static str {
        super::names::REDISTRIBUTED_PSEUDO_INVERSE
    }
}

/// The redistributed pseudo-inverse with at most `max_rounds` rounds per allocation: a flight
/// controller's bounded period where a request loads most agents to their limits (each round
/// saturates one agent and solves again: up to `n` rounds, at about 12,000 Cortex-M4F
/// instructions each at `n = 16`). After the last round every agent still outside its set is
/// clamped onto it, as [`RedistributedPseudoInverse`] does after its `n`-th: the forces stay
/// admissible and what they miss is in the allocation's `e_f` and `wrench_error` (and the
/// controller's `torque_error`), never dropped silently. Gimbal inverse and saturation are
/// the exact-boundary redistribution's start's (`f32` within 2 ulp of the paper's, without
/// `libm`'s software-`f64` trigonometry on a Cortex-M4F: a saturation there costs about
/// 4,500 instructions). With `max_rounds >= n` it allocates as [`RedistributedPseudoInverse`]
/// (the same bits in `f64`).
///
/// ```
/// use tvmd_core::nalgebra::Vector6;
/// use tvmd_core::{team::presets, AdmissibleSet, AllocationRequest, Allocator, FailureMask};
/// use tvmd_core::{CappedRedistribution, RedistributedPseudoInverse};
/// let team = presets::a4_inc::<f64, 4>()?;
/// let e = team.effectiveness(&FailureMask::none());
/// let sets = [AdmissibleSet::from_limits(team.limits()); 4];
/// // A request of the allocation set that saturates one agent (two rounds uncapped).
/// let wrench = Vector6::new(-4.16, -0.218, 1.63, -7.04, 2.62, 23.9);
/// let request = AllocationRequest { effectiveness: &e, sets: &sets, wrench };
/// let full = RedistributedPseudoInverse.allocate(&request);
/// let capped = CappedRedistribution::new(1)?.allocate(&request);
/// assert_eq!((capped.rounds, full.rounds), (1, 2));
/// // The cap's price is stated, not hidden: a larger error, reported.
/// assert!(capped.wrench_error >= full.wrench_error);
/// assert_eq!(CappedRedistribution::new(4)?.allocate(&request), full);
/// # Ok::<(), tvmd_core::ConfigError>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CappedRedistribution {
    max_rounds: u32,
}

impl CappedRedistribution {
    /// Rounds of [`Self::default`]: the first round's pseudo-inverse and one redistribution.
    pub const DEFAULT_MAX_ROUNDS: u32 = 2;

    /// At most `max_rounds` rounds (at least 1: the first round is the pseudo-inverse).
    ///
    /// Errors: [`ConfigError::Parameter`] naming [`ConfigField::AllocatorMaxRounds`] for 0.
    pub fn new(max_rounds: u32) -> Result<Self, ConfigError> {
        if max_rounds == 0 {
            return Err(ConfigError::Parameter {
                field: ConfigField::AllocatorMaxRounds,
            });
        }
        Ok(Self { max_rounds })
    }

    /// The round cap.
    pub fn max_rounds(&self) -> u32 {
        self.max_rounds
    }
}

impl Default for CappedRedistribution {
    /// [`Self::DEFAULT_MAX_ROUNDS`] rounds.
    fn default() -> Self {
        Self {
            max_rounds: Self::DEFAULT_MAX_ROUNDS,
        }
    }
}

impl<T: Real, const N: usize> Allocator<T, N> for CappedRedistribution {
    fn allocate(&mut self, request: &AllocationRequest<'_, T, N>) -> Allocation<T, N> {
        redistribute(
            request,
            GimbalCommand::from_force_fast,
            AdmissibleSet::saturate_fast,
            self.max_rounds,
        )
    }

    fn name(&self) -> &'static str {
        super::names::CAPPED_REDISTRIBUTION
    }
}

/// The redistribution of [`RedistributedPseudoInverse`], with the gimbal inverse `inverse` and
/// the saturation `saturate` (the paper's: [`GimbalCommand::from_force`],
/// [`AdmissibleSet::saturate`]; the exact-boundary redistribution's start: their `_fast`
/// forms, without `libm`'s software-`f64` trigonometry on a Cortex-M4F).
///
/// At most `max_rounds` rounds (and at most one per working agent, the paper's loop).
///
/// Function pointers, not generic closures: one copy of the redistribution for both callers
/// (the C interface's text is bounded, `scripts/ffi.sh`), not inlined into either.
#[inline(never)]
pub(super) fn redistribute<T: Real, const N: usize>(
    request: &AllocationRequest<'_, T, N>,
    inverse: fn(&Vector3<T>) -> GimbalCommand<T>,
    saturate: fn(&AdmissibleSet<T>, &Vector3<T>) -> Vector3<T>,
    max_rounds: u32,
) -> Allocation<T, N> {
    {
        let e = request.effectiveness;
        let mut free = working_mask(e);
        let mut forces = [Vector3::zeros(); N];
        let mut saturated = [false; N];
        let mut rounds: u32 = 0;
        let n = u32::try_from(e.working_count()).map_or(max_rounds, |n| n.min(max_rounds));
        // The agents' one set (the usual case) as a test without the gimbal inverse for the
        // forces well inside it; the others, and every force near a boundary, take the exact
        // test. The same decisions, so the same bits.
        let interior = Interior::shared(request.sets);
        let inside = |f: &Vector3<T>| interior.as_ref().is_some_and(|t| t.holds(f));
        let mut outside = [false; N];
        while rounds < n {
            rounds += 1;
            let mut fixed_wrench = request.wrench;
            for ((block, f), is_free) in e.blocks().iter().zip(&forces).zip(&free) {
                if let (Some(b), false) = (block.as_ref(), *is_free) {
                    fixed_wrench -= b * f;
                }
            }
            // Round 1 inverts every working agent: the effectiveness's own factor of `M M^T`.
            let factor = (rounds == 1).then(|| e.gram_solver());
            pseudo_inverse_forces(e, &free, None, factor, &fixed_wrench, &mut forces);
            // `outside` with the one gimbal inverse per agent; a non-finite force counts as the
            // worst. The agents found outside are kept: the clamp after the last round needs
            // no second inverse (their forces do not change in between).
            let mut worst: Option<(usize, T)> = None;
            for (i, (((f, set), is_free), out)) in forces
                .iter()
                .zip(request.sets)
                .zip(&free)
                .zip(outside.iter_mut())
                .enumerate()
            {
                // An agent outside last round most likely is again: straight to the exact test.
                let was_outside = core::mem::replace(out, false);
                if !*is_free || (!was_outside && inside(f)) {
                    continue;
                }
                let v = set.violation(&inverse(f));
                let v = match (f.iter().all(|x| x.is_finite()), v > T::zero()) {
                    (true, true) => v,
                    (true, false) => continue,
                    (false, _) => T::one() / T::zero(),
                };
                *out = true;
                if !matches!(worst, Some((_, bv)) if bv >= v) {
                    worst = Some((i, v));
                }
            }
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
        // Out of rounds (every agent fixed, the last ones still outside, or the cap reached):
        // clamp the rest, the free agents the last round found outside.
        for ((((f, set), is_free), sat), out) in forces
            .iter_mut()
            .zip(request.sets)
            .zip(&free)
            .zip(saturated.iter_mut())
            .zip(&outside)
        {
            if *is_free && *out {
                *f = saturate(set, f);
                *sat = true;
            }
        }
        Allocation::from_forces(request, forces, rounds, saturated)
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use crate::agent::failure::FailureMask;
    use crate::foundation::linalg::norm;
    use crate::team::presets;
    use nalgebra::Vector6;

    /// Over torque steps that saturate more and more agents of a 16-agent ring: every cap stays
    /// within its rounds, inside every set, its error is what its forces leave, and a cap of
    /// `n` rounds is the paper's allocator exactly (`f64`).
    #[test]
    fn a_cap_bounds_the_rounds_and_reports_what_it_misses() {
        let team = presets::ring::<f64, 16>(16, 1.0, true, presets::paper_limits()).unwrap();
        let e = team.effectiveness(&FailureMask::none());
        let sets = [AdmissibleSet::from_limits(team.limits()); 16];
        let mut saturating = 0;
        for k in 0..=14 {
            let roll = 5.0 * f64::from(k);
            let wrench = Vector6::new(roll, -0.1 * roll, 0.0, -5.0, 0.0, team.mass() * 9.81);
            let request = AllocationRequest {
                effectiveness: &e,
                sets: &sets,
                wrench,
            };
            let full = RedistributedPseudoInverse.allocate(&request);
            saturating += usize::from(full.rounds > 2);
            for cap in [1, 2, 3, 16] {
                let out = CappedRedistribution::new(cap).unwrap().allocate(&request);
                assert!(out.rounds <= cap && out.rounds <= full.rounds);
                for (f, set) in out.forces.iter().zip(&sets) {
                    assert!(set.violation(&GimbalCommand::from_force(f)) <= 1e-9);
                }
                assert_eq!(out.wrench_error, norm(&(wrench - e.wrench(&out.forces))));
                if cap >= full.rounds {
                    assert_eq!(out, full, "roll {roll}, cap {cap}");
                }
            }
        }
        assert!(
            saturating >= 3,
            "{saturating} requests saturate beyond 2 rounds"
        );
        assert!(CappedRedistribution::new(0).is_err());
    }
}
