//! The range checks of scenario fields and their bounds, each error naming the field.

use crate::error::invalid;
use crate::ScenarioError;

/// Longest scenario (s): 1e6 s, about 11.6 days of flight.
pub const MAX_DURATION: f64 = 1e6;
/// Most physics steps of one run (about 20 minutes of rapier on the development machine).
pub const MAX_PHYSICS_STEPS: f64 = 1e9;
/// Physics step range (s): `[1e-6, 0.01]`.
pub const PHYSICS_DT: [f64; 2] = [1e-6, 0.01];
/// Controller period range (s): from one physics step to 1 s.
pub const MAX_CONTROLLER_PERIOD: f64 = 1.0;
/// Solver iterations range.
pub const SOLVER_ITERATIONS: [usize; 2] = [1, 1000];
/// Largest distance of positions in a scenario (m).
pub const MAX_DISTANCE: f64 = 1e4;
/// Largest external force or wind (N) and torque (N m).
pub const MAX_EXTERNAL: f64 = 1e4;

/// `Err` naming `field` unless `v` is in `[lo, hi]`.
pub(crate) fn check_range(field: &str, v: f64, lo: f64, hi: f64) -> Result<(), ScenarioError> {
    if v >= lo && v <= hi {
        Ok(())
    } else {
        Err(invalid(
            field,
            format!("must be in [{lo:e}, {hi:e}], got {v}"),
        ))
    }
}

/// `Err` naming `field` unless every component of `v` has `|x| <= limit`.
pub(crate) fn check_magnitude(field: &str, v: &[f64], limit: f64) -> Result<(), ScenarioError> {
    check_finite(field, v)?;
    match v.iter().find(|x| x.abs() > limit) {
        None => Ok(()),
        Some(x) => Err(invalid(
            field,
            format!("must be within +-{limit:e}, got {x}"),
        )),
    }
}

pub(crate) fn check_pos(field: &str, v: f64) -> Result<(), ScenarioError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(invalid(field, format!("must be finite and > 0, got {v}")))
    }
}

pub(crate) fn check_nonneg(field: &str, v: &[f64]) -> Result<(), ScenarioError> {
    match v.iter().find(|x| !(x.is_finite() && **x >= 0.0)) {
        None => Ok(()),
        Some(x) => Err(invalid(field, format!("must be finite and >= 0, got {x}"))),
    }
}

pub(crate) fn check_finite(field: &str, v: &[f64]) -> Result<(), ScenarioError> {
    if v.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(invalid(field, "must be finite"))
    }
}
