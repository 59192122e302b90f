//! The core controller's float type `T` (f32, the flight configuration, or f64) and the
//! rounding of a scenario's f64 values into it: the one way in, shared by the configuration
//! ([`crate::core_config`]) and the simulator's state and reference.

use nalgebra::{Matrix3, Vector3};
use tvmd_core::Real;

use crate::Precision;

/// A float type the core controller runs in: `f32` (the flight configuration) or `f64`.
///
/// `Into<f64>` makes the way out exact; the way in (`f64 -> T`) rounds to nearest, and a
/// finite `f64` beyond `T`'s range becomes infinite, which the core rejects as a non-finite
/// input (a [`tvmd_core::CycleError`] holding the previous commands), never a NaN.
pub trait CoreFloat: Real + Into<f64> {
    /// The scenario's name for this type.
    const PRECISION: Precision;
}

impl CoreFloat for f32 {
    const PRECISION: Precision = Precision::F32;
}

impl CoreFloat for f64 {
    const PRECISION: Precision = Precision::F64;
}

/// `x` rounded to `T`.
pub fn to_core<T: CoreFloat>(x: f64) -> T {
    nalgebra::convert(x)
}

/// A vector rounded to `T`.
pub fn vector_to_core<T: CoreFloat>(v: &Vector3<f64>) -> Vector3<T> {
    v.map(to_core)
}

/// A matrix rounded to `T`.
pub fn matrix_to_core<T: CoreFloat>(m: &Matrix3<f64>) -> Matrix3<T> {
    m.map(to_core)
}
