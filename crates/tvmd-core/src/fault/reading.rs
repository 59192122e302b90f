//! One agent's own report of what its actuators do ([`AgentReading`]): the measured rotor
//! thrust and gimbal angles and the report's age, the input of the report check
//! ([`crate::fault::reports`]), and the typed errors of a bad report ([`ReportError`]).
//!
//! On PX4 the rotor part comes from ESC telemetry (`esc_status`: rpm, converted to the
//! thrust the team's rotor model makes at that speed, [`AgentReading::from_speed`]) and the
//! angles from servo feedback.

use core::fmt;

use crate::agent::limits::AgentLimits;
use crate::foundation::real::{to_f64, Real};

/// A report the controller cannot use. The controller keeps the agent's previous report.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ReportError {
    /// A NaN or infinite value in the named quantity (`"thrust"`, `"speed"`, `"eta_x"`,
    /// `"eta_y"`, `"age"`).
    NonFinite {
        /// The quantity.
        quantity: &'static str,
    },
    /// A negative thrust or rotor speed.
    Negative {
        /// The quantity (`"thrust"`, `"speed"` or `"age"`).
        quantity: &'static str,
        /// Its value.
        value: f64,
    },
    /// The agent is not in the team.
    Agent {
        /// The agent's index.
        agent: usize,
        /// The team's size.
        len: usize,
    },
    /// The controller has no fault detection ([`crate::ControllerSettings::fault_detection`]):
    /// nothing would read the report.
    DetectionOff,
}

impl fmt::Display for ReportError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NonFinite { quantity } => write!(f, "report: {quantity} is not finite"),
            Self::Negative { quantity, value } => {
                write!(f, "report: {quantity} must be at least 0, got {value}")
            }
            Self::Agent { agent, len } => {
                write!(f, "report: agent {agent} is not in the team of {len}")
            }
            Self::DetectionOff => f.write_str("report: the controller has no fault detection"),
        }
    }
}

#[cfg(feature = "std")]
impl std::error::Error for ReportError {}

/// One agent's report: its measured rotor thrust `T = k omega^2` (N, from the measured speed
/// with an intact propeller), its gimbal angles `eta_x`, `eta_y` (rad) and the report's age
/// (s since it was measured). Validated: every value finite, thrust and age at least 0.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AgentReading<T: Real> {
    thrust: T,
    eta_x: T,
    eta_y: T,
    age: T,
}

impl<T: Real> AgentReading<T> {
    /// A report of thrust `thrust` (N), angles `eta_x`, `eta_y` (rad), measured `age` s ago.
    ///
    /// Errors: [`ReportError::NonFinite`], [`ReportError::Negative`] naming the quantity.
    pub fn new(thrust: T, eta_x: T, eta_y: T, age: T) -> Result<Self, ReportError> {
        let finite = |quantity, v: T| {
            if v.is_finite() {
                Ok(v)
            } else {
                Err(ReportError::NonFinite { quantity })
            }
        };
        let at_least_zero = |quantity, v: T| {
            if v >= T::zero() {
                Ok(v)
            } else {
                Err(ReportError::Negative {
                    quantity,
                    value: to_f64(v),
                })
            }
        };
        Ok(Self {
            thrust: at_least_zero("thrust", finite("thrust", thrust)?)?,
            eta_x: finite("eta_x", eta_x)?,
            eta_y: finite("eta_y", eta_y)?,
            age: at_least_zero("age", finite("age", age)?)?,
        })
    }

    /// A report of rotor speed `speed` in the unit of the team's rotor model (`omega` of
    /// [`crate::AgentCommand::omega`]: rad/s with rotor constants, else normalized to 1 at
    /// maximum thrust), converted to thrust by `limits` (eq. 5, `T = k omega^2`).
    ///
    /// Errors: as [`Self::new`], naming `"speed"` for a bad speed.
    pub fn from_speed(
        speed: T,
        eta_x: T,
        eta_y: T,
        age: T,
        limits: &AgentLimits<T>,
    ) -> Result<Self, ReportError> {
        if !speed.is_finite() {
            return Err(ReportError::NonFinite { quantity: "speed" });
        }
        if speed < T::zero() {
            return Err(ReportError::Negative {
                quantity: "speed",
                value: to_f64(speed),
            });
        }
        Self::new(limits.thrust_for_speed(speed), eta_x, eta_y, age)
    }

    /// The measured thrust (N).
    pub fn thrust(&self) -> T {
        self.thrust
    }

    /// The measured inner gimbal angle `eta_x` (rad).
    pub fn eta_x(&self) -> T {
        self.eta_x
    }

    /// The measured outer gimbal angle `eta_y` (rad).
    pub fn eta_y(&self) -> T {
        self.eta_y
    }

    /// The report's age (s).
    pub fn age(&self) -> T {
        self.age
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    #[test]
    fn bad_reports_are_typed_errors() {
        assert!(AgentReading::new(3.0f32, 0.1, -0.1, 0.02).is_ok());
        assert_eq!(
            AgentReading::new(f64::NAN, 0.0, 0.0, 0.0),
            Err(ReportError::NonFinite { quantity: "thrust" })
        );
        assert_eq!(
            AgentReading::new(1.0, 0.0, f64::INFINITY, 0.0),
            Err(ReportError::NonFinite { quantity: "eta_y" })
        );
        assert_eq!(
            AgentReading::new(1.0, 0.0, 0.0, -0.01),
            Err(ReportError::Negative {
                quantity: "age",
                value: -0.01
            })
        );
        assert!(matches!(
            AgentReading::new(-1.0, 0.0, 0.0, 0.0),
            Err(ReportError::Negative {
                quantity: "thrust",
                ..
            })
        ));
        let limits = AgentLimits::new(0.5, 0.5, 10.0).unwrap();
        // Normalized speed: 1 is the maximum thrust, 0.5 a quarter of it.
        let r = AgentReading::from_speed(0.5, 0.0, 0.0, 0.01, &limits).unwrap();
        assert!((r.thrust() - 2.5f64).abs() < 1e-12);
        assert_eq!(
            AgentReading::from_speed(-0.5, 0.0, 0.0, 0.0, &limits),
            Err(ReportError::Negative {
                quantity: "speed",
                value: -0.5
            })
        );
        assert!(AgentReading::from_speed(f64::NAN, 0.0, 0.0, 0.0, &limits).is_err());
    }
}
