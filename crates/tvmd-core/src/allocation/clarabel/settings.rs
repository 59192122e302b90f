//! Tolerances and defaults of the constrained allocator, and the Clarabel settings it uses.

use ::clarabel::solver::DefaultSettings;

/// Largest gimbal angle used in the `tan` rows (rad): `pi/2 - 1e-3`, `tan` about 1000.
pub(super) const MAX_TAN_ANGLE: f64 = core::f64::consts::FRAC_PI_2 - 1e-3;
/// Relative slack (of the agent's maximum thrust) under which a constraint counts as active.
pub(super) const ACTIVE_TOL: f64 = 1e-6;
/// Relative (of the maximum thrust) violation below which a closed-form answer counts as
/// feasible; [`Bounds::repair`] then removes it.
pub(super) const FEASIBLE_TOL: f64 = 1e-12;
/// Default regularisation `lambda`.
pub(super) const DEFAULT_LAMBDA: f64 = 1e-6;
/// Default Clarabel gap and feasibility tolerance.
pub(super) const DEFAULT_TOLERANCE: f64 = 1e-9;
/// Default Clarabel iteration limit.
pub(super) const DEFAULT_MAX_ITER: u32 = 100;

/// Quiet Clarabel settings with data updates allowed (no presolve, no dropped zeros).
pub(super) fn default_settings() -> DefaultSettings<f64> {
    DefaultSettings {
        verbose: false,
        max_iter: DEFAULT_MAX_ITER,
        tol_gap_abs: DEFAULT_TOLERANCE,
        tol_gap_rel: DEFAULT_TOLERANCE,
        tol_feas: DEFAULT_TOLERANCE,
        presolve_enable: false,
        input_sparse_dropzeros: false,
        max_threads: 1,
        ..DefaultSettings::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn settings_allow_data_updates() {
        let s = default_settings();
        // Presolve and dropped zeros would change the structure Cache::update relies on.
        assert!(!s.presolve_enable && !s.input_sparse_dropzeros && !s.verbose);
        assert_eq!(
            (s.max_iter, s.tol_feas),
            (DEFAULT_MAX_ITER, DEFAULT_TOLERANCE)
        );
        let max_tan = MAX_TAN_ANGLE.tan();
        assert!(max_tan > 999.0 && max_tan < 1001.0);
    }
}
