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

/// `sqrt(x)`, correctly rounded (IEEE 754), so the same bits as `T::sqrt`. Why by hand: on a
/// hard-float Arm target (Cortex-M4F, M7) a `no_std` build's `f32::sqrt` is the `libm` crate's
/// software `sqrtf` (an integer iteration per call), where the FPU has
/// `vsqrt.f32`, one instruction; norms are the allocators' inner loop. Elsewhere `T::sqrt`.
#[inline]
pub(crate) fn sqrt<T: Real>(x: T) -> T {
    #[cfg(all(target_arch = "arm", target_abi = "eabihf"))]
    if let Some(v) = (&x as &dyn core::any::Any).downcast_ref::<f32>() {
        let root = vsqrt_f32(*v);
        if let Some(r) = (&root as &dyn core::any::Any).downcast_ref::<T>() {
            return *r;
        }
    }
    x.sqrt()
}

/// The FPU's square root (`vsqrt.f32`): IEEE 754's correctly rounded `sqrt`. Through a core
/// register and `s15` (saved and restored around it): Rust gives the single-precision register
/// class to `asm!` only with the `vfp2` feature, which the Cortex-M4F's FPv4-SP lacks.
#[cfg(all(target_arch = "arm", target_abi = "eabihf"))]
#[inline]
fn vsqrt_f32(x: f32) -> f32 {
    let mut bits = x.to_bits();
    // SAFETY: `s15` is pushed before and popped after, so no register the compiler uses
    // changes; the stack is balanced; only FPSCR's cumulative exception bits may change.
    unsafe {
        core::arch::asm!(
            "vpush {{s15}}",
            "vmov s15, {bits}",
            "vsqrt.f32 s15, s15",
            "vmov {bits}, s15",
            "vpop {{s15}}",
            bits = inout(reg) bits,
            options(pure, nomem, preserves_flags)
        );
    }
    f32::from_bits(bits)
}

/// The larger of `a` and `b`, a NaN ignored and `+0` above `-0` (IEEE 754 `maxNum`, as
/// `T::max`), by comparisons. Why by hand: on a Cortex-M4F `f32::max` is a call of `libm`'s
/// `fmaxf` (Armv7-M has no `vmaxnm`), about 11 instructions; the allocators take it per
/// component.
#[inline]
pub(crate) fn fmax<T: Real>(a: T, b: T) -> T {
    if b > a || a.partial_cmp(&a).is_none() || (b == a && a.is_sign_negative()) {
        b
    } else {
        a
    }
}

/// The smaller of `a` and `b`, a NaN ignored and `-0` below `+0` (IEEE 754 `minNum`, as
/// `T::min`), by comparisons (see [`fmax`]).
#[inline(never)]
pub(crate) fn fmin<T: Real>(a: T, b: T) -> T {
    if b < a || a.partial_cmp(&a).is_none() || (b == a && b.is_sign_negative()) {
        b
    } else {
        a
    }
}

/// `(sin x, cos x)`. In `f32` for `|x| <= pi`, an `f32`-only kernel ([`sin_cos_f32`]); else the
/// type's own `sin_cos`. Why by hand: the `libm` crate's `sincosf` (what nalgebra's `f32`
/// `sin_cos` is on a `no_std` target) evaluates in `f64`, which a Cortex-M4F (single-precision
/// FPU) runs in software: about 2,200 instructions a call, 60% of a searching control cycle
/// there. The planner's angles lie in `[0, pi]`.
#[inline]
pub(crate) fn sin_cos<T: Real>(x: T) -> (T, T) {
    if core::mem::size_of::<T>() == core::mem::size_of::<f32>() {
        if let Some(v) = x.to_subset() as Option<f64> {
            // `T` is `f32` here, so both conversions are exact.
            let v = v as f32;
            if (-core::f32::consts::PI..=core::f32::consts::PI).contains(&v) {
                let (s, c) = sin_cos_f32(v);
                return (
                    nalgebra::convert(f64::from(s)),
                    nalgebra::convert(f64::from(c)),
                );
            }
        }
    }
    x.sin_cos()
}

/// `asin x` for `|x| <= 1`. In `f32`, an `f32`-only kernel ([`asin_f32`]); else the type's
/// own `asin`. Why by hand: `libm`'s `asinf` takes the root of `(1 - |x|) / 2` in `f64` for
/// `|x| >= 0.5` (a gimbal angle beyond 30 degrees), in software on a Cortex-M4F (about 1,500
/// instructions a call).
#[inline]
pub(crate) fn asin<T: Real>(x: T) -> T {
    if core::mem::size_of::<T>() == core::mem::size_of::<f32>() {
        if let Some(v) = x.to_subset() as Option<f64> {
            // `T` is `f32` here, so both conversions are exact.
            return nalgebra::convert(f64::from(asin_f32(v as f32)));
        }
    }
    x.asin()
}

/// `asin x` in `f32` arithmetic only (NaN beyond `[-1, 1]`): `libm`'s `asinf` (musl's
/// rational approximation `R`) with its `f64` branch, `pi/2 - 2 asin(sqrt((1 - |x|) / 2))`,
/// taken in `f32` with `pi/2` split in two. Within 2 ulp of the correctly rounded value
/// (tested against `f64`).
fn asin_f32(x: f32) -> f32 {
    const PIO2_HI: f32 = core::f32::consts::FRAC_PI_2;
    // `pi/2 - PIO2_HI`.
    const PIO2_LO: f32 = -4.371_139e-8;
    let r = |z: f32| {
        let p = z * (1.666_658_7e-1 + z * (-4.274_342_2e-2 + z * -8.656_363e-3));
        let q = 1.0 + z * -7.066_296_3e-1;
        p / q
    };
    let a = x.abs();
    if a < 0.5 {
        // Below 2^-12 `asin x` rounds to `x`.
        if a < 2.441_406_3e-4 {
            return x;
        }
        return x + x * r(x * x);
    }
    if a >= 1.0 {
        return if a == 1.0 { x * PIO2_HI } else { f32::NAN };
    }
    // Exact: `1 - a` by Sterbenz's lemma (`a >= 0.5`), the halving by its exponent.
    let z = (1.0 - a) * 0.5;
    let s = sqrt(z);
    let y = (PIO2_HI - 2.0 * (s + s * r(z))) + PIO2_LO;
    if x < 0.0 {
        -y
    } else {
        y
    }
}

/// `(sin x, cos x)` for `|x| <= pi` (finite), in `f32` arithmetic only: Cody-Waite reduction
/// by `pi/2` (split in three parts, so the reduced argument is exact to about `1e-10`) to
/// `|r| <= pi/4`, then the minimax polynomials of Cephes' `sinf`/`cosf` (degree 7 and 8).
/// Within 2 ulp of the correctly rounded values (tested against `f64` on 2,000,001 points:
/// worst 1.41 ulp for `sin`, 1.55 for `cos`).
fn sin_cos_f32(x: f32) -> (f32, f32) {
    const DP1: f32 = 1.570_312_5;
    const DP2: f32 = 4.837_513e-4;
    const DP3: f32 = 7.549_79e-8;
    // The nearest quadrant, rounded half away from zero (`f32::round` needs std).
    let q = x * core::f32::consts::FRAC_2_PI;
    let quadrant = if q >= 0.0 {
        (q + 0.5) as i32
    } else {
        (q - 0.5) as i32
    };
    let j = quadrant as f32;
    let r = ((x - j * DP1) - j * DP2) - j * DP3;
    let z = r * r;
    let s = r + r * z * (-1.666_665_5e-1 + z * (8.332_161e-3 + z * -1.951_529_6e-4));
    let c = 1.0 - 0.5 * z + z * z * (4.166_664_6e-2 + z * (-1.388_731_6e-3 + z * 2.443_315_7e-5));
    // `x` in [-pi, pi] gives the quadrant j in {-2, .., 2}.
    match quadrant {
        0 => (s, c),
        1 => (c, -s),
        -1 => (-c, s),
        _ => (-s, -c),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Distance in units of the last place of the correctly rounded `f32`.
    fn ulps(got: f32, exact: f64) -> f64 {
        let want = exact as f32;
        let ulp = (f64::from(f32::from_bits(want.abs().to_bits() + 1)) - f64::from(want.abs()))
            .max(f64::from(f32::MIN_POSITIVE));
        (f64::from(got) - exact).abs() / ulp
    }

    #[test]
    fn f32_sin_cos_is_within_two_ulp_on_minus_pi_to_pi() {
        let (mut worst_s, mut worst_c) = (0.0f64, 0.0f64);
        let steps = 2_000_000;
        for k in 0..=steps {
            let x =
                -core::f32::consts::PI + 2.0 * core::f32::consts::PI * (k as f32 / steps as f32);
            let x = x.clamp(-core::f32::consts::PI, core::f32::consts::PI);
            let (s, c) = sin_cos_f32(x);
            let xd = f64::from(x);
            worst_s = worst_s.max(ulps(s, xd.sin()));
            worst_c = worst_c.max(ulps(c, xd.cos()));
        }
        // Near the zeros of sin and cos an ulp of the result is tiny; the reduction's error of
        // about 1e-10 absolute bounds it there instead.
        assert!(
            worst_s <= 2.0 && worst_c <= 2.0,
            "sin {worst_s} ulp, cos {worst_c} ulp"
        );
    }

    #[test]
    fn f32_asin_is_within_two_ulp_on_minus_one_to_one() {
        let mut worst = 0.0f64;
        let steps = 2_000_000;
        for k in 0..=steps {
            let x = (-1.0 + 2.0 * (k as f64 / steps as f64)) as f32;
            worst = worst.max(ulps(asin_f32(x), f64::from(x).asin()));
        }
        // Every float near the ends of the range, where the root's branch is steepest.
        for bits in 0..20_000u32 {
            for x in [
                f32::from_bits(1.0f32.to_bits() - bits),
                f32::from_bits(0.5f32.to_bits() + bits),
            ] {
                worst = worst.max(ulps(asin_f32(x), f64::from(x).asin()));
                worst = worst.max(ulps(asin_f32(-x), f64::from(-x).asin()));
            }
        }
        assert!(worst <= 2.0, "asin {worst} ulp");
        assert!(asin_f32(1.5).is_nan() && asin_f32(f32::NAN).is_nan());
        assert_eq!(asin(0.3f64), 0.3f64.asin());
        assert_eq!(asin(0.7f32), asin_f32(0.7));
    }

    #[test]
    fn f32_dispatch_and_f64_fallback() {
        let pi = core::f32::consts::PI;
        for x in [0.0f32, 1e-30, 0.3, 0.5 * pi, pi, -pi, -2.0] {
            let (s, c) = sin_cos(x);
            assert_eq!((s, c), sin_cos_f32(x));
        }
        // Beyond pi, and every f64: the type's own.
        assert_eq!(sin_cos(4.0f32), 4.0f32.sin_cos());
        assert_eq!(sin_cos(0.3f64), 0.3f64.sin_cos());
        let (s, c) = sin_cos(f32::NAN);
        assert!(s.is_nan() && c.is_nan());
    }
}
