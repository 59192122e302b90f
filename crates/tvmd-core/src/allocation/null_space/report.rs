//! What the null-space stage changed in one period.

use crate::foundation::real::Real;

/// The null-space stage's account of one period ([`super::NullSpaceStage::refine`]), reported
/// in [`crate::ControlOutput::null_space`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NullSpaceReport<T: Real> {
    /// The stage ran: it is configured, and the allocation it was given was finite and inside
    /// the sets it walks in. `false`: every other field is zero and the forces are the
    /// allocator's.
    pub ran: bool,
    /// Accepted steps (0: the forces are the allocator's, unchanged).
    pub iterations: u32,
    /// The objective at the allocator's forces (see [`super::NullSpaceObjective`]).
    pub objective_before: T,
    /// The objective at the returned forces (never below `objective_before`).
    pub objective_after: T,
    /// The smallest normalized margin to the admissible boundary at the allocator's forces
    /// (the `h_j` of [`super::NullSpaceObjective::Margin`], whatever the objective).
    pub margin_before: T,
    /// The same at the returned forces.
    pub margin_after: T,
    /// `max_i ||f_i' - f_i||` (N), the largest change of one agent's force.
    pub largest_force_change: T,
    /// `||M f' - M f||` (N and N m), the wrench the stage moved, measured; at most
    /// [`super::NullSpaceStage::drift_bound`].
    pub wrench_drift: T,
}

impl<T: Real> NullSpaceReport<T> {
    /// The report of a period without the stage.
    pub fn off() -> Self {
        let zero = T::zero();
        Self {
            ran: false,
            iterations: 0,
            objective_before: zero,
            objective_after: zero,
            margin_before: zero,
            margin_after: zero,
            largest_force_change: zero,
            wrench_drift: zero,
        }
    }

    /// Whether the stage changed the forces.
    pub fn changed(&self) -> bool {
        self.iterations > 0
    }
}

impl<T: Real> Default for NullSpaceReport<T> {
    fn default() -> Self {
        Self::off()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_off_report_says_nothing_ran_or_changed() {
        let r = NullSpaceReport::<f32>::default();
        assert_eq!(r, NullSpaceReport::off());
        assert!(!r.ran && !r.changed());
        assert_eq!(r.wrench_drift, 0.0);
    }
}
