//! The one float bound of the crate.

use nalgebra::RealField;

/// Scalar type of every tvmd computation: `f32` (flight controllers) or `f64` (analysis).
///
/// A blanket alias for nalgebra's [`RealField`] + [`Copy`], in the style of Clarabel.rs's
/// `FloatT`: every generic item in the crate takes exactly this bound.
pub trait Real: RealField + Copy {}

impl<T: RealField + Copy> Real for T {}

/// Converts an `f64` literal into `T` (exact for `f64`, rounded for `f32`).
#[inline]
pub(crate) fn lit<T: Real>(x: f64) -> T {
    nalgebra::convert(x)
}

/// Converts `T` to `f64` for error reports (`NaN` if `T` cannot be represented).
#[inline]
pub(crate) fn to_f64<T: Real>(x: T) -> f64 {
    x.to_subset().unwrap_or(f64::NAN)
}

/// Converts an agent count into `T`.
#[inline]
pub(crate) fn count<T: Real>(n: usize) -> T {
    // Agent counts are bounded by the const capacity, far below 2^24, so this is exact in f32.
    nalgebra::convert(n as f64)
}

/// Machine epsilon of `T`.
#[inline]
pub(crate) fn eps<T: Real>() -> T {
    T::default_epsilon()
}
