//! Limits of one agent: gimbal limits and thrust range (eq. 6), the rotor model (eq. 5), gimbal
//! rate limits, and the intervals admissible sets are made of.

use crate::foundation::error::{ConfigError, ConfigField, GimbalAxis};
use crate::foundation::real::{fmax, fmin, sqrt, Real};

/// Limits shared by every agent: gimbal limits (eq. 6), thrust range and the rotor model
/// `T = rho d^4 c_l omega^2` (eq. 5).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AgentLimits<T: Real> {
    sigma_x: T,
    sigma_y: T,
    max_thrust: T,
    min_thrust: T,
    thrust_coefficient: T,
}

impl<T: Real> AgentLimits<T> {
    /// Unvalidated limits with `omega = 1` at `max_thrust`, for presets known to be valid.
    pub(crate) fn trusted(sigma_x: T, sigma_y: T, max_thrust: T) -> Self {
        Self {
            sigma_x,
            sigma_y,
            max_thrust,
            min_thrust: T::zero(),
            thrust_coefficient: max_thrust,
        }
    }

    /// `sigma_x`: limit of `|eta_x|` (rad), in `(0, pi/2]`.
    pub fn sigma_x(&self) -> T {
        self.sigma_x
    }

    /// `sigma_y`: limit of `|eta_y|` (rad), in `(0, pi/2]`.
    pub fn sigma_y(&self) -> T {
        self.sigma_y
    }

    /// `sigma_Tf`: maximum thrust of one agent (N).
    pub fn max_thrust(&self) -> T {
        self.max_thrust
    }

    /// Idle thrust (N), the smallest thrust the allocator commands; `0` by default.
    pub fn min_thrust(&self) -> T {
        self.min_thrust
    }

    /// `rho d^4 c_l`: thrust per squared rotor speed (N s^2 / rad^2).
    pub fn thrust_coefficient(&self) -> T {
        self.thrust_coefficient
    }

    /// Limits from the gimbal limits and the maximum thrust. Rotor speeds are then normalized:
    /// `omega = 1` at maximum thrust.
    pub fn new(sigma_x: T, sigma_y: T, max_thrust: T) -> Result<Self, ConfigError> {
        let limits = Self {
            sigma_x,
            sigma_y,
            max_thrust,
            min_thrust: T::zero(),
            thrust_coefficient: max_thrust,
        };
        limits.validate()?;
        Ok(limits)
    }

    /// Limits from the rotor constants of eq. (5): air density `rho`, rotor diameter `d`,
    /// lift coefficient `c_l` and maximum rotor speed `sigma_omega`; `sigma_Tf = T(sigma_omega)`.
    /// Finite constants whose `rho d^4 c_l`, `sigma_omega^2` or `sigma_Tf` overflow give
    /// [`ConfigError::Overflow`].
    pub fn from_rotor(
        sigma_x: T,
        sigma_y: T,
        rho: T,
        d: T,
        c_l: T,
        sigma_omega: T,
    ) -> Result<Self, ConfigError> {
        for (value, field) in [
            (rho, ConfigField::Rho),
            (d, ConfigField::RotorDiameter),
            (c_l, ConfigField::LiftCoefficient),
            (sigma_omega, ConfigField::MaxRotorSpeed),
        ] {
            if !value.is_finite() {
                return Err(ConfigError::NonFinite { field });
            }
            if value <= T::zero() {
                return Err(ConfigError::NonPositiveThrust {
                    field,
                    value: crate::foundation::real::to_f64(value),
                });
            }
        }
        let k = rho * d * d * d * d * c_l;
        // Finite constants can overflow in the products the rotor model uses.
        for (value, quantity, field) in [
            (
                k,
                "thrust coefficient rho d^4 c_l",
                ConfigField::RotorDiameter,
            ),
            (
                sigma_omega * sigma_omega,
                "squared rotor speed sigma_omega^2",
                ConfigField::MaxRotorSpeed,
            ),
            (
                k * sigma_omega * sigma_omega,
                "maximum thrust sigma_Tf",
                ConfigField::MaxRotorSpeed,
            ),
        ] {
            if !value.is_finite() {
                return Err(ConfigError::Overflow { quantity, field });
            }
        }
        let limits = Self {
            sigma_x,
            sigma_y,
            max_thrust: k * sigma_omega * sigma_omega,
            min_thrust: T::zero(),
            thrust_coefficient: k,
        };
        limits.validate()?;
        Ok(limits)
    }

    /// The same limits with an idle thrust `min_thrust` in `[0, sigma_Tf)`.
    pub fn with_min_thrust(mut self, min_thrust: T) -> Result<Self, ConfigError> {
        self.min_thrust = min_thrust;
        self.validate()?;
        Ok(self)
    }

    /// Checks every field; [`crate::TeamConfig::new`] calls it.
    pub fn validate(&self) -> Result<(), ConfigError> {
        let half_pi = T::frac_pi_2();
        for (value, axis, field) in [
            (self.sigma_x, GimbalAxis::X, ConfigField::SigmaX),
            (self.sigma_y, GimbalAxis::Y, ConfigField::SigmaY),
        ] {
            if !value.is_finite() {
                return Err(ConfigError::NonFinite { field });
            }
            if value <= T::zero() || value > half_pi {
                return Err(ConfigError::GimbalLimit {
                    axis,
                    value: crate::foundation::real::to_f64(value),
                });
            }
        }
        for (value, field) in [
            (self.max_thrust, ConfigField::MaxThrust),
            (self.thrust_coefficient, ConfigField::ThrustCoefficient),
            (self.min_thrust, ConfigField::MinThrust),
        ] {
            if !value.is_finite() {
                return Err(ConfigError::NonFinite { field });
            }
        }
        for (value, field) in [
            (self.max_thrust, ConfigField::MaxThrust),
            (self.thrust_coefficient, ConfigField::ThrustCoefficient),
        ] {
            if value <= T::zero() {
                return Err(ConfigError::NonPositiveThrust {
                    field,
                    value: crate::foundation::real::to_f64(value),
                });
            }
        }
        if self.min_thrust < T::zero() || self.min_thrust >= self.max_thrust {
            return Err(ConfigError::IdleThrust {
                value: crate::foundation::real::to_f64(self.min_thrust),
            });
        }
        Ok(())
    }

    /// Rotor speed for a thrust (eq. 5 inverted); negative thrust maps to 0.
    pub fn speed_for_thrust(&self, thrust: T) -> T {
        sqrt(thrust.max(T::zero()) / self.thrust_coefficient)
    }

    /// Thrust for a rotor speed (eq. 5).
    pub fn thrust_for_speed(&self, omega: T) -> T {
        self.thrust_coefficient * omega * omega
    }

    /// `sigma_omega`, the rotor speed at maximum thrust.
    pub fn max_speed(&self) -> T {
        self.speed_for_thrust(self.max_thrust)
    }
}

/// A closed interval `[lo, hi]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Interval<T: Real> {
    /// Lower end.
    pub lo: T,
    /// Upper end (`>= lo`).
    pub hi: T,
}

impl<T: Real> Interval<T> {
    /// `[-limit, limit]`.
    pub fn symmetric(limit: T) -> Self {
        Self {
            lo: -limit,
            hi: limit,
        }
    }

    /// Whether `x` lies within the interval widened by `tol`.
    pub fn contains(&self, x: T, tol: T) -> bool {
        x >= self.lo - tol && x <= self.hi + tol
    }

    /// The nearest point of the interval.
    pub fn clamp(&self, x: T) -> T {
        fmin(fmax(x, self.lo), self.hi)
    }

    /// How far `x` lies outside, 0 inside.
    pub fn excess(&self, x: T) -> T {
        // `max(lo - x, x - hi, 0)` by comparisons (`lo <= hi`; a NaN `x` gives 0, as `max` does).
        if x < self.lo {
            self.lo - x
        } else if x > self.hi {
            x - self.hi
        } else {
            T::zero()
        }
    }

    /// Intersection with `[centre - radius, centre + radius]`; if they do not meet, the end of
    /// `self` nearest to the window (so the result is never empty and stays inside `self`).
    pub(crate) fn window(&self, centre: T, radius: T) -> Self {
        let lo = self.clamp(centre - radius);
        let hi = self.clamp(centre + radius);
        Self { lo, hi: hi.max(lo) }
    }
}

/// Gimbal rate limits (rad/s) of the rate-constrained allocation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RateLimits<T: Real> {
    eta_x: T,
    eta_y: T,
}

impl<T: Real> RateLimits<T> {
    /// Validated rate limits (positive, finite).
    pub fn new(eta_x: T, eta_y: T) -> Result<Self, ConfigError> {
        for value in [eta_x, eta_y] {
            if !value.is_finite() || value <= T::zero() {
                return Err(ConfigError::Parameter {
                    field: ConfigField::RateLimits,
                });
            }
        }
        Ok(Self { eta_x, eta_y })
    }

    /// Largest `|d eta_x / dt|`.
    pub fn eta_x(&self) -> T {
        self.eta_x
    }

    /// Largest `|d eta_y / dt|`.
    pub fn eta_y(&self) -> T {
        self.eta_y
    }
}
