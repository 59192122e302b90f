//! What the null-space stage maximizes: each agent's normalized margin to the boundary of its
//! admissible set `E_f` (eq. 6), or the alignment of each thrust with a configured inward tilt.

use crate::foundation::real::Real;

/// The objective of a [`super::NullSpaceStage`]. `repr(u8)`: the tag first, checked raw by
/// [`crate::Controller::storage_intact`].
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(u8)]
pub enum NullSpaceObjective<T: Real> {
    /// Keep every working agent away from its limits: maximize the soft minimum
    /// `-(1/kappa) ln sum_j exp(-kappa h_j)` (`kappa = 32`) of the normalized margins `h_j`, one
    /// per agent and limit, each a fraction of that limit's range (0 on the boundary, 1 at the
    /// opposite end):
    /// - `eta_x` limits: `(sin a_hi - sin eta_x) / (sin a_hi - sin a_lo)` and its mirror;
    /// - `eta_y` limits: `cos eta_x sin(b_hi - eta_y) / sin(min(b_hi - b_lo, pi/2))` and its
    ///   mirror (the distance to the plane `eta_y = b_hi`, as an angle);
    /// - thrust: `(T_max - T) / (T_max - T_min)` and, when `T_min > 0`, `(T - T_min) / (...)`.
    ///
    /// A step is kept only when the soft minimum rises and the smallest `h_j` does not fall.
    Margin,
    /// Drive each working agent's thrust direction toward the team's centre by `angle` (rad,
    /// `|angle| < pi/2`): the target is `cos(angle) z + sin(angle) u_i` in the team frame, with
    /// `u_i` the horizontal unit vector from agent `i` toward the centre of mass (`z` for an
    /// agent above it), so equal tilts cancel as internal forces. Maximizes the mean over the
    /// agents with thrust of `cos` of the angle between force and target (1: every agent on
    /// target). The internal-force objective of the authors' MATLAB allocation, as an objective
    /// to ascend rather than a fixed offset.
    InwardTilt {
        /// Tilt toward the centre (rad); negative tilts outward.
        angle: T,
    },
}
