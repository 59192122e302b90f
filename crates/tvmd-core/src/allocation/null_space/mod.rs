//! The null-space stage (`docs/method.md`, "Null-space stage"): after any allocator, move the
//! forces inside `null(M)`, so the wrench `M f` (eq. 4) stays what the allocator made, toward a
//! stated objective, never leaving any agent's admissible set `E_f` (eq. 6).

mod objective;
#[cfg(feature = "null-space")]
mod prepared;
mod projection;
#[cfg(feature = "null-space")]
mod refine;
mod report;

pub use objective::NullSpaceObjective;
pub use report::NullSpaceReport;

use nalgebra::Vector3;

use crate::agent::effectiveness::Effectiveness;
use crate::foundation::error::{ConfigError, ConfigField};
use crate::foundation::real::Real;
use crate::foundation::stored::tag_below;

/// Largest iteration cap [`NullSpaceStage::new`] accepts.
pub const MAX_NULL_SPACE_ITERATIONS: u32 = 64;

/// Gradient ascent of a [`NullSpaceObjective`] inside `null(M)`, at most `iterations` steps.
///
/// Each step, from forces `f` (the allocator's at first):
/// 1. `g` = the objective's gradient, `d = g - M^T (M M^T)^-1 M g` (its part in `null(M)`,
///    so `M d = 0`; failed agents have no block and do not move), except that an agent near a
///    limit (normalized margin below `1/32`, or on it) is kept from moving toward it: `d_i`
///    keeps only the tangential part of the null-space step plus the inward part of `g_i`
///    along that limit's normal, the other agents absorbing the difference (the held-normal
///    projection of the exact-boundary allocator, with `M d = 0` still);
/// 2. `tau_max` = the first exit of `f + tau d` from any agent's exact admissible set (the
///    closed-form exits of the exact-boundary allocator: gimbal cones and planes, thrust
///    spheres, with `|eta_x|` one milliradian inside `pi/2`), and the step starts at
///    `tau = min(tau_max / 2, T_max / (4 max_i ||d_i||))`, so it stops halfway to the boundary
///    and moves no agent by more than a quarter of the largest thrust;
/// 3. the step is kept if the objective rises (the smallest margin must not fall either, for
///    [`NullSpaceObjective::Margin`]), every force is inside its set by the gimbal inverse
///    (the allocator's own test) and the wrench drift `||M f' - M f||` is at most
///    [`Self::drift_bound`]; else `tau` is halved, up to 8 times, and the stage stops when no
///    halving is kept.
///
/// It never makes the allocation worse: a non-finite allocation or one with no agent inside its
/// set is returned as it came (`ran = false`); an agent just outside its set (the round-off of
/// a saturation) starts from its saturation when that is inside and within `sqrt(eps) T_max`,
/// else keeps its force; every kept step satisfies all three tests of step 3; and a result whose
/// objective (or smallest margin) ends below the input's is dropped for the input. No
/// allocation, no panic path, `f32` and `f64`.
///
/// ```
/// use tvmd_core::{team::presets, AdmissibleSet, AllocationRequest, Allocator, FailureMask};
/// use tvmd_core::{NullSpaceObjective, NullSpaceStage, RedistributedPseudoInverse};
/// use tvmd_core::nalgebra::Vector6;
/// let team = presets::a4_inc::<f64, 4>()?;
/// let effectiveness = team.effectiveness(&FailureMask::none());
/// let sets = [AdmissibleSet::from_limits(team.limits()); 4];
/// let wrench = Vector6::new(0.0, 0.0, 0.0, 8.0, 0.0, 30.0);
/// let request = AllocationRequest { effectiveness: &effectiveness, sets: &sets, wrench };
/// let allocation = RedistributedPseudoInverse.allocate(&request);
/// let stage = NullSpaceStage::new(NullSpaceObjective::Margin, 8)?;
/// let (refined, report) = stage.refine(&request, &allocation);
/// assert!(report.ran && report.margin_after >= report.margin_before);
/// assert!((refined.wrench - allocation.wrench).norm() <= report.wrench_drift + 1e-15);
/// assert!(report.wrench_drift <= NullSpaceStage::drift_bound(&effectiveness, &allocation.forces, &refined.forces));
/// # Ok::<(), tvmd_core::ConfigError>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NullSpaceStage<T: Real> {
    objective: NullSpaceObjective<T>,
    iterations: u32,
}

impl<T: Real> NullSpaceStage<T> {
    /// A stage with at most `iterations` steps (`1..=64`). Errors with
    /// [`ConfigField::NullSpaceIterations`] outside that, and [`ConfigField::NullSpaceTilt`]
    /// for a tilt that is not finite or not below `pi/2` in magnitude.
    pub fn new(objective: NullSpaceObjective<T>, iterations: u32) -> Result<Self, ConfigError> {
        if iterations == 0 || iterations > MAX_NULL_SPACE_ITERATIONS {
            return Err(ConfigError::Parameter {
                field: ConfigField::NullSpaceIterations,
            });
        }
        if let NullSpaceObjective::InwardTilt { angle } = objective {
            if !angle.is_finite() {
                return Err(ConfigError::NonFinite {
                    field: ConfigField::NullSpaceTilt,
                });
            }
            if angle.abs() >= T::frac_pi_2() {
                return Err(ConfigError::Parameter {
                    field: ConfigField::NullSpaceTilt,
                });
            }
        }
        Ok(Self {
            objective,
            iterations,
        })
    }

    /// The objective.
    pub fn objective(&self) -> NullSpaceObjective<T> {
        self.objective
    }

    /// The iteration cap.
    pub fn iterations(&self) -> u32 {
        self.iterations
    }

    /// The wrench drift the stage accepts between forces `before` and `after`:
    /// `1e3 eps max(1, max |M_ij|) max(sum_i ||f_i||, sum_i ||f_i'||)` over the working agents
    /// (a bound relative to the forces: `M f` itself is only known to about
    /// `eps |M| sum ||f_i||`).
    pub fn drift_bound<const N: usize>(
        effectiveness: &Effectiveness<T, N>,
        before: &[Vector3<T>; N],
        after: &[Vector3<T>; N],
    ) -> T {
        projection::drift_bound(effectiveness, before, after)
    }
}

#[cfg(all(test, feature = "null-space"))]
mod tests {
    #![allow(clippy::unwrap_used, clippy::indexing_slicing)]
    use super::*;
    use crate::agent::admissible::AdmissibleSet;
    use crate::agent::limits::Interval;
    use crate::allocation::{outside, AllocationRequest, Allocator, RedistributedPseudoInverse};
    use nalgebra::Vector6;

    fn team() -> (Effectiveness<f64, 4>, [AdmissibleSet<f64>; 4]) {
        let positions = [
            Vector3::new(0.25, 0.25, 0.0),
            Vector3::new(-0.25, 0.25, 0.0),
            Vector3::new(-0.25, -0.25, 0.0),
            Vector3::new(0.25, -0.25, 0.0),
        ];
        let e = Effectiveness::new(positions.iter().enumerate().map(|(i, p)| (i, p, i as i32)));
        let set = AdmissibleSet::new(
            Interval::symmetric(0.5),
            Interval::symmetric(0.5),
            Interval { lo: 0.0, hi: 10.0 },
        )
        .unwrap();
        (e, [set; 4])
    }

    #[test]
    fn iteration_caps_and_tilts_are_checked() {
        assert!(NullSpaceStage::<f64>::new(NullSpaceObjective::Margin, 0).is_err());
        assert!(NullSpaceStage::<f64>::new(NullSpaceObjective::Margin, 65).is_err());
        let tilt = |angle| NullSpaceStage::<f32>::new(NullSpaceObjective::InwardTilt { angle }, 4);
        assert_eq!(
            tilt(f32::NAN),
            Err(ConfigError::NonFinite {
                field: ConfigField::NullSpaceTilt
            })
        );
        assert!(tilt(2.0).is_err() && tilt(-0.3).is_ok());
    }

    #[test]
    fn a_saturated_allocation_gains_margin_at_the_same_wrench() {
        let (e, sets) = team();
        // Thrust and a sideways force that push the pseudo-inverse into the gimbal limits.
        let wrench = Vector6::new(0.0, 0.0, 0.5, 12.0, 0.0, 22.0);
        let request = AllocationRequest {
            effectiveness: &e,
            sets: &sets,
            wrench,
        };
        let allocation = RedistributedPseudoInverse.allocate(&request);
        let stage = NullSpaceStage::new(NullSpaceObjective::Margin, 16).unwrap();
        let (refined, report) = stage.refine(&request, &allocation);
        assert!(report.ran && report.changed(), "{report:?}");
        assert!(
            report.margin_after > report.margin_before + 0.01,
            "{report:?}"
        );
        assert!(report.objective_after > report.objective_before);
        assert!(report.largest_force_change > 0.0);
        let drift = (refined.wrench - allocation.wrench).norm();
        assert!(drift <= NullSpaceStage::drift_bound(&e, &allocation.forces, &refined.forces));
        for (f, s) in refined.forces.iter().zip(&sets) {
            assert!(!outside(s, f));
        }
    }

    #[test]
    fn failed_agents_stay_and_bad_input_comes_back_untouched() {
        let (full, sets) = team();
        let positions = [
            Vector3::new(0.25, 0.25, 0.0),
            Vector3::new(-0.25, 0.25, 0.0),
            Vector3::new(0.25, -0.25, 0.0),
        ];
        // Agent 2 failed.
        let e: Effectiveness<f64, 4> = Effectiveness::new(
            [0usize, 1, 3]
                .iter()
                .zip(&positions)
                .map(|(i, p)| (*i, p, *i as i32)),
        );
        let request = AllocationRequest {
            effectiveness: &e,
            sets: &sets,
            wrench: Vector6::new(0.0, 0.0, 0.0, 2.0, 1.0, 20.0),
        };
        let allocation = RedistributedPseudoInverse.allocate(&request);
        let stage = NullSpaceStage::new(NullSpaceObjective::InwardTilt { angle: 0.2 }, 8).unwrap();
        let (refined, report) = stage.refine(&request, &allocation);
        assert!(report.ran);
        assert_eq!(refined.forces[2], Vector3::zeros());
        assert!(report.objective_after >= report.objective_before);
        let mut bad = RedistributedPseudoInverse.allocate(&AllocationRequest {
            effectiveness: &full,
            ..request
        });
        bad.forces[1].x = f64::NAN;
        let (back, report) = stage.refine(&request, &bad);
        assert!(!report.ran && back.forces[1].x.is_nan());
        assert_eq!(back.forces[0], bad.forces[0]);
    }
}

impl<T: Real> NullSpaceStage<T> {
    /// Whether the stage at `this` has a valid objective tag (two variants) and an iteration
    /// count in `1..=`[`MAX_NULL_SPACE_ITERATIONS`]. Reads only.
    ///
    /// # Safety
    /// `this` is aligned and points to `size_of::<Self>()` readable bytes.
    pub(crate) unsafe fn storage_intact(this: *const Self) -> bool {
        let iterations = core::ptr::addr_of!((*this).iterations).read();
        tag_below(core::ptr::addr_of!((*this).objective), 2)
            && (1..=MAX_NULL_SPACE_ITERATIONS).contains(&iterations)
    }
}

#[cfg(test)]
mod storage_tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use crate::foundation::stored::{accepts, refused_bytes};

    #[test]
    fn its_objective_tag_and_iterations_are_checked() {
        let check = NullSpaceStage::<f32>::storage_intact;
        let tilt = NullSpaceObjective::InwardTilt { angle: 0.1 };
        for objective in [NullSpaceObjective::Margin, tilt] {
            let stage = NullSpaceStage::new(objective, 8).unwrap();
            assert!(accepts(&stage, check));
            // The tag and the iteration count's three high bytes (2 iterations are valid, 65
            // are not: its low byte too).
            assert_eq!(refused_bytes(&stage, 2, check), 1 + 3);
            assert_eq!(refused_bytes(&stage, 0x41, check), 1 + 4);
        }
    }
}
