//! Typed errors: [`ConfigError`] for a team, limits, gains or settings that cannot be used, and
//! [`InputError`] for a control-cycle input that cannot be used.
//!
//! Values are reported as `f64` so the enums are not generic and print the same for `f32` and
//! `f64` builds.

use core::fmt;

/// Which mass a [`ConfigError::NonPositiveMass`] refers to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MassOf {
    /// Agent `i` (index into the team's agent list).
    Agent(usize),
    /// The navigator (mass must be `>= 0`; zero means "no navigator").
    Navigator,
}

/// A gimbal axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GimbalAxis {
    /// Inner axis, angle `eta_x`, limit `sigma_x`.
    X,
    /// Outer axis, angle `eta_y`, limit `sigma_y`.
    Y,
}

/// A configuration that cannot describe a flyable team or a usable controller.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ConfigError {
    /// The team has no agent (or every agent is marked failed).
    NoAgents,
    /// More agents than the const capacity `N` of the fixed-size storage.
    TooManyAgents {
        /// Number of agents given.
        count: usize,
        /// Capacity `N`.
        capacity: usize,
    },
    /// A NaN or infinite number in the named field.
    NonFinite {
        /// The field, e.g. `"agent.position"`.
        field: &'static str,
    },
    /// A gimbal limit outside `(0, pi/2]` (eq. 6).
    GimbalLimit {
        /// The axis.
        axis: GimbalAxis,
        /// The rejected limit in radians.
        value: f64,
    },
    /// A mass that must be positive (agents) or non-negative (navigator) is not.
    NonPositiveMass {
        /// Whose mass.
        of: MassOf,
        /// The rejected mass in kg.
        value: f64,
    },
    /// The maximum thrust `sigma_Tf` (or a rotor constant it follows from) is not positive.
    NonPositiveThrust {
        /// The rejected value.
        value: f64,
    },
    /// The idle (minimum) thrust is not in `[0, sigma_Tf)`.
    IdleThrust {
        /// The rejected idle thrust in N.
        value: f64,
    },
    /// The navigator inertia is not symmetric positive semi-definite.
    NavigatorInertia,
    /// `M(Xi)` of eq. (4) does not have rank 6: the team cannot produce every wrench.
    RankDeficient {
        /// Smallest over largest eigenvalue of `M M^T` (0 when exactly singular).
        conditioning: f64,
    },
    /// `n_x > n` for an attainable force space built from counts.
    AgentCount {
        /// Total agents `n`.
        n: usize,
        /// Agents with even quarter turns `n_x`.
        n_x: usize,
    },
    /// The AFS relaxation `s` is not in `(0, 1]`.
    Relaxation {
        /// The rejected value.
        value: f64,
    },
    /// A gain, weight, period or tolerance that must be positive (or positive semi-definite) is not.
    Parameter {
        /// The parameter, e.g. `"gains.k_x"`.
        name: &'static str,
    },
    /// A failure mask names an agent the team does not have.
    FailureIndex {
        /// The index.
        agent: usize,
    },
}

impl fmt::Display for ConfigError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Self::NoAgents => write!(f, "the team has no (working) agent"),
            Self::TooManyAgents { count, capacity } => write!(
                f,
                "{count} agents exceed the capacity of {capacity} (raise the const generic N)"
            ),
            Self::NonFinite { field } => write!(f, "`{field}` is not finite (NaN or infinite)"),
            Self::GimbalLimit { axis, value } => write!(
                f,
                "gimbal limit sigma_{} = {value} rad is outside (0, pi/2]",
                match axis {
                    GimbalAxis::X => "x",
                    GimbalAxis::Y => "y",
                }
            ),
            Self::NonPositiveMass { of, value } => match of {
                MassOf::Agent(i) => write!(f, "agent {i} has mass {value} kg; it must be > 0"),
                MassOf::Navigator => {
                    write!(f, "the navigator has mass {value} kg; it must be >= 0")
                }
            },
            Self::NonPositiveThrust { value } => {
                write!(f, "maximum thrust (or rotor constant) {value} must be > 0")
            }
            Self::IdleThrust { value } => {
                write!(f, "idle thrust {value} N must be in [0, max thrust)")
            }
            Self::NavigatorInertia => write!(
                f,
                "the navigator inertia must be symmetric positive semi-definite"
            ),
            Self::RankDeficient { conditioning } => write!(
                f,
                "M(Xi) is not rank 6 (eig_min/eig_max of M M^T = {conditioning:e}): the team cannot produce every wrench"
            ),
            Self::AgentCount { n, n_x } => write!(f, "n_x = {n_x} exceeds n = {n} (or n = 0)"),
            Self::Relaxation { value } => write!(f, "relaxation s = {value} is outside (0, 1]"),
            Self::Parameter { name } => write!(f, "`{name}` must be positive and finite"),
            Self::FailureIndex { agent } => {
                write!(f, "failure mask names agent {agent}, which the team does not have")
            }
        }
    }
}

/// A control-cycle input that cannot be used. The cycle still returns a safe output with it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum InputError {
    /// A NaN or infinite number in the named input.
    NonFinite {
        /// The input, e.g. `"state.position"`.
        field: &'static str,
    },
    /// A rotation matrix input is not a rotation (`R^T R != I` or `det R != 1` beyond tolerance).
    NotRotation {
        /// The input, e.g. `"state.attitude"`.
        field: &'static str,
    },
}

impl fmt::Display for InputError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Self::NonFinite { field } => {
                write!(f, "input `{field}` is not finite (NaN or infinite)")
            }
            Self::NotRotation { field } => write!(f, "input `{field}` is not a rotation matrix"),
        }
    }
}

#[cfg(feature = "std")]
impl std::error::Error for ConfigError {}

#[cfg(feature = "std")]
impl std::error::Error for InputError {}
