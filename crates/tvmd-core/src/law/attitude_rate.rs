//! The planned attitude's rates: `Omega_d` and `Omega_d_dot` consistent with the planner's
//! `R_d` (eqs. 9, 11), which moves as the planner saturates, for the feed-forward of eq. (12)
//! (`docs/method.md#beyond-the-paper-the-planned-attitudes-rates`).
//!
//! A filtered finite difference on SO(3): each period the raw rate
//! `u = log(R_d,prev^T R_d) / dt` (body frame of `R_d`, clamped to `|u| <= max_rate`) drives a
//! critically damped second-order low-pass of bandwidth `w`, `y'' = w^2 (u - y) - 2 w y'`,
//! discretised exactly for an input held over the period (stable for every `w dt`). Its
//! output is `Omega_d = y` and `Omega_d_dot = y'`. The filter's impulse response
//! `w^2 t e^(-w t)` is non-negative with unit integral, so from rest `|Omega_d| <= max_rate` and
//! `|Omega_d_dot| <= (2/e) w max_rate` whatever the input: measurement noise in `R_d` cannot
//! blow up the feed-forward.

use nalgebra::{Matrix3, Vector3};

use crate::foundation::error::{positive, ConfigError, ConfigField};
use crate::foundation::linalg::{clamp_norm, norm};
use crate::foundation::real::{lit, Real};
use crate::foundation::rotation::vee;
use crate::foundation::stored::bool_intact;

/// Settings of the planned-rate filter: bandwidth `w` (rad/s) and the largest rate `max_rate`
/// (rad/s) a jump of `R_d` may stand for. Validated (each finite and positive).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AttitudeRateFilter<T: Real> {
    bandwidth: T,
    max_rate: T,
}

impl<T: Real> AttitudeRateFilter<T> {
    /// Errors: [`ConfigError::NonFinite`] or [`ConfigError::Parameter`] naming
    /// [`ConfigField::AttitudeRateBandwidth`] or [`ConfigField::AttitudeRateLimit`].
    pub fn new(bandwidth: T, max_rate: T) -> Result<Self, ConfigError> {
        Ok(Self {
            bandwidth: positive(bandwidth, ConfigField::AttitudeRateBandwidth)?,
            max_rate: positive(max_rate, ConfigField::AttitudeRateLimit)?,
        })
    }

    /// The bandwidth `w` (rad/s).
    pub fn bandwidth(&self) -> T {
        self.bandwidth
    }

    /// The rate bound `max_rate` (rad/s).
    pub fn max_rate(&self) -> T {
        self.max_rate
    }
}

/// `Omega_d` and `Omega_d_dot` of the planned attitude, in the body frame of `R_d` (the frame
/// of [`crate::Reference::angular_velocity`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlannedRates<T: Real> {
    /// `Omega_d` (rad/s).
    pub omega_d: Vector3<T>,
    /// `Omega_d_dot` (rad/s^2).
    pub omega_d_dot: Vector3<T>,
}

/// The filter's state between periods: the previous `R_d`, the filtered rate and its
/// derivative, and the per-period constants.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AttitudeRateState<T: Real> {
    filter: AttitudeRateFilter<T>,
    period: T,
    /// `e^(-w dt)`.
    decay: T,
    previous: Matrix3<T>,
    has_previous: bool,
    rate: Vector3<T>,
    acceleration: Vector3<T>,
}

impl<T: Real> AttitudeRateState<T> {
    /// A filter at rest for a control period `dt` (finite, positive).
    ///
    /// Errors: [`ConfigError::Parameter`] naming [`ConfigField::Period`] for a `dt` that is not.
    pub fn new(filter: AttitudeRateFilter<T>, period: T) -> Result<Self, ConfigError> {
        let period = positive(period, ConfigField::Period)?;
        Ok(Self {
            filter,
            period,
            decay: (-(filter.bandwidth * period)).exp(),
            previous: Matrix3::identity(),
            has_previous: false,
            rate: Vector3::zeros(),
            acceleration: Vector3::zeros(),
        })
    }

    /// Back to rest: no previous `R_d`, zero rates.
    pub fn reset(&mut self) {
        self.has_previous = false;
        self.rate = Vector3::zeros();
        self.acceleration = Vector3::zeros();
    }

    /// The rates of the last [`Self::update`] (zero at rest).
    pub fn rates(&self) -> PlannedRates<T> {
        PlannedRates {
            omega_d: self.rate,
            omega_d_dot: self.acceleration,
        }
    }

    /// One period with this period's planned `R_d` (a rotation; a non-finite one is taken as
    /// no motion). The first period after [`Self::new`] or [`Self::reset`] only records `R_d`.
    pub fn update(&mut self, r_d: &Matrix3<T>) -> PlannedRates<T> {
        let w = self.filter.bandwidth;
        let dt = self.period;
        let raw = if self.has_previous {
            log_so3(&(self.previous.transpose() * r_d)) / dt
        } else {
            Vector3::zeros()
        };
        let input = clamp_norm(&raw, self.filter.max_rate);
        if r_d.iter().all(|x| x.is_finite()) {
            self.previous = *r_d;
            self.has_previous = true;
        }
        // Exact solution over dt for a held input: with e = y - u and c = y' + w e,
        // e(dt) = (e + c dt) e^(-w dt), y'(dt) = (y' - w c dt) e^(-w dt).
        let e = self.rate - input;
        let c = self.acceleration + e * w;
        let rate = input + (e + c * dt) * self.decay;
        let acceleration = (self.acceleration - c * (w * dt)) * self.decay;
        // The bounds hold exactly in exact arithmetic; the clamps only catch round-off (and
        // make finiteness certain).
        let two_over_e: T = lit(2.0 / core::f64::consts::E);
        self.rate = clamp_norm(&rate, self.filter.max_rate);
        self.acceleration = clamp_norm(&acceleration, w * self.filter.max_rate * two_over_e);
        self.rates()
    }
}

/// The rotation vector `theta a` of a rotation `q` (`q = exp([theta a]x)`, `theta in [0, pi]`).
/// A half turn has no axis this formula can read; it (and a non-finite `q`) gives zero.
pub(crate) fn log_so3<T: Real>(q: &Matrix3<T>) -> Vector3<T> {
    let half: T = T::one() / (T::one() + T::one());
    let s = vee(&(q - q.transpose())) * half;
    let sin = norm(&s);
    let cos = (q.trace() - T::one()) * half;
    if !(sin.is_finite() && cos.is_finite()) || sin == T::zero() {
        return Vector3::zeros();
    }
    // theta / sin(theta) = 1 + x/6 + 3x^2/40 + ... with x = sin^2, for the small turns of one
    // period: past x^2 the series is below 1e-10 relative for sin < 0.03, under f32's and
    // near f64's round-off, and it spares the atan2 of every period.
    let small: T = lit(0.03);
    if cos > T::zero() && sin < small {
        let x = sin * sin;
        let series = T::one() + x * (lit::<T>(1.0 / 6.0) + x * lit::<T>(3.0 / 40.0));
        return s * series;
    }
    let theta = sin.atan2(cos);
    s * (theta / sin)
}

impl<T: Real> AttitudeRateState<T> {
    /// Whether the filter at `this` holds a valid flag (its other fields are numbers).
    ///
    /// # Safety
    /// `this` is aligned and points to `size_of::<Self>()` readable bytes.
    pub(crate) unsafe fn storage_intact(this: *const Self) -> bool {
        bool_intact(core::ptr::addr_of!((*this).has_previous))
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use crate::foundation::rotation::roll;

    fn exp_so3(v: Vector3<f64>) -> Matrix3<f64> {
        nalgebra::Rotation3::new(v).into_inner()
    }

    #[test]
    fn log_inverts_exp() {
        for v in [
            Vector3::new(0.1, -0.2, 0.3),
            Vector3::new(1e-9, 0.0, 0.0),
            Vector3::new(0.0, 2.5, 1.0),
        ] {
            assert!((log_so3(&exp_so3(v)) - v).norm() < 1e-12, "{v}");
        }
        // Either side of the series' threshold (sin = 0.03).
        for v in [
            Vector3::new(0.0299, 0.0, 0.0),
            Vector3::new(0.0, -0.0205, 0.0218),
        ] {
            assert!((log_so3(&exp_so3(v)) - v).norm() < 1e-11, "{v}");
        }
        assert_eq!(log_so3(&Matrix3::<f64>::identity()), Vector3::zeros());
        assert_eq!(
            log_so3(&(Matrix3::<f64>::identity() * f64::NAN)),
            Vector3::zeros()
        );
    }

    #[test]
    fn rejects_invalid_settings() {
        assert_eq!(
            AttitudeRateFilter::new(0.0f64, 1.0),
            Err(ConfigError::Parameter {
                field: ConfigField::AttitudeRateBandwidth
            })
        );
        assert_eq!(
            AttitudeRateFilter::new(10.0f64, f64::INFINITY),
            Err(ConfigError::NonFinite {
                field: ConfigField::AttitudeRateLimit
            })
        );
        let f = AttitudeRateFilter::new(10.0f64, 1.0).unwrap();
        assert!(AttitudeRateState::new(f, 0.0).is_err());
    }

    #[test]
    fn constant_rotation_rate_is_recovered() {
        let filter = AttitudeRateFilter::new(20.0f64, 5.0).unwrap();
        let mut state = AttitudeRateState::new(filter, 0.01).unwrap();
        let omega = Vector3::new(0.3, -0.2, 0.1);
        let mut r = roll(0.2);
        let mut out = state.update(&r);
        assert_eq!(out.omega_d, Vector3::zeros());
        for _ in 0..300 {
            r *= exp_so3(omega * 0.01);
            out = state.update(&r);
        }
        assert!((out.omega_d - omega).norm() < 1e-9, "{}", out.omega_d);
        assert!(out.omega_d_dot.norm() < 1e-8);
    }

    #[test]
    fn a_sinusoidal_roll_gives_its_rate_and_acceleration_with_the_filter_lag() {
        // phi = A sin(W t): the second-order filter at w = 20 lags by about 2 W / w = 0.1 rad.
        let filter = AttitudeRateFilter::new(20.0f64, 10.0).unwrap();
        let mut state = AttitudeRateState::new(filter, 0.01).unwrap();
        let (a, big_w) = (0.3, 1.0);
        let mut out = state.update(&roll(0.0));
        let mut worst = 0.0f64;
        for k in 1..1000 {
            let t = f64::from(k) * 0.01;
            out = state.update(&roll(a * (big_w * t).sin()));
            if t > 2.0 {
                let lag = 2.0 / 20.0 + 0.005;
                let rate = a * big_w * (big_w * (t - lag)).cos();
                worst = worst.max((out.omega_d.x - rate).abs());
            }
        }
        assert!(worst < 0.01, "rate error {worst}");
        assert!(out.omega_d.y.abs() < 1e-12 && out.omega_d.z.abs() < 1e-12);
    }

    #[test]
    fn noise_and_jumps_stay_within_the_stated_bounds() {
        let (w, max_rate) = (15.0f32, 2.0f32);
        let filter = AttitudeRateFilter::new(w, max_rate).unwrap();
        let mut state = AttitudeRateState::new(filter, 0.01).unwrap();
        let mut seed = 12345u32;
        let mut next = || {
            seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (seed >> 8) as f32 / (1u32 << 24) as f32 - 0.5
        };
        for k in 0..2000 {
            // Jitter of 0.05 rad (5 rad/s raw), and a jump of 1 rad every 100 periods.
            let jump = if k % 100 == 50 { 1.0 } else { 0.0 };
            let r = roll(0.05 * next() + jump);
            let out = state.update(&r);
            assert!(out.omega_d.norm() <= max_rate * 1.0001);
            assert!(out.omega_d_dot.norm() <= w * max_rate * 0.736);
            assert!(out.omega_d.iter().all(|x| x.is_finite()));
        }
        state.reset();
        assert_eq!(state.rates().omega_d, Vector3::zeros());
    }
}

#[cfg(test)]
mod storage_tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use crate::foundation::stored::{accepts, refuses};
    use core::ptr::addr_of_mut;

    #[test]
    fn an_invalid_flag_is_refused() {
        let filter = AttitudeRateFilter::new(20.0_f32, 5.0).unwrap();
        let mut s = AttitudeRateState::new(filter, 0.01).unwrap();
        s.update(&Matrix3::identity());
        let check = AttitudeRateState::<f32>::storage_intact;
        assert!(s.has_previous && accepts(&s, check));
        assert!(refuses(
            &s,
            2,
            |p| unsafe { addr_of_mut!((*p).has_previous).cast() },
            check
        ));
    }
}
