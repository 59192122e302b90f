//! Typed errors: [`ConfigError`] for a team, limits, gains or settings that cannot be used, and
//! [`InputError`] for a control-cycle input that cannot be used.
//!
//! Values are reported as `f64`: the enums are not generic and print the same in `f32` and `f64`.

use core::fmt;

mod input;
pub use input::InputError;

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

/// The setting a [`ConfigError`] names: one variant per validated field, so callers (the
/// simulator's scenario checks, the Python bindings) map it to their own field names without
/// matching strings.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ConfigField {
    /// `p_i` of an agent.
    AgentPosition,
    /// `m_i` of an agent.
    AgentMass,
    /// `J_i` of an agent.
    AgentInertia,
    /// `m_0`.
    NavigatorMass,
    /// `J_0`.
    NavigatorInertia,
    /// `sigma_x`.
    SigmaX,
    /// `sigma_y`.
    SigmaY,
    /// `sigma_Tf`.
    MaxThrust,
    /// The idle thrust.
    MinThrust,
    /// `rho d^4 c_l`.
    ThrustCoefficient,
    /// Air density `rho` (eq. 5).
    Rho,
    /// Rotor diameter `d` (eq. 5).
    RotorDiameter,
    /// Lift coefficient `c_l` (eq. 5).
    LiftCoefficient,
    /// `sigma_omega` (eq. 5).
    MaxRotorSpeed,
    /// The AFS relaxation `s`.
    Relaxation,
    /// `K_x`.
    GainKx,
    /// `K_R`.
    GainKr,
    /// `K_Omega`.
    GainKomega,
    /// `K_v`.
    GainKv,
    /// `g`.
    Gravity,
    /// `m_C` of a [`crate::law::Plant`].
    PlantMass,
    /// `J_C` of a [`crate::law::Plant`].
    PlantInertia,
    /// `J_C` derived by [`crate::TeamConfig::new`].
    TeamInertia,
    /// The control period `dt`.
    Period,
    /// The gimbal rate limits.
    RateLimits,
    /// The planner's bisection tolerance.
    PlannerTolerance,
    /// The planner's iteration cap.
    PlannerMaxIterations,
    /// The per-agent weights of the weighted pseudo-inverse.
    AllocatorWeights,
    /// The exact-boundary redistribution's round cap.
    AllocatorMaxRounds,
    /// Clarabel's regularisation `lambda`.
    ClarabelLambda,
    /// Clarabel's wrench weights `W`.
    ClarabelWeights,
    /// Clarabel's tolerance.
    ClarabelTolerance,
    /// The null-space stage's iteration cap.
    NullSpaceIterations,
    /// The null-space stage's inward tilt.
    NullSpaceTilt,
    /// A closed-loop natural frequency of [`crate::NaturalGains`].
    NaturalFrequency,
    /// A closed-loop damping ratio of [`crate::NaturalGains`].
    DampingRatio,
    /// A gain of [`crate::IntegralAction`].
    IntegralGain,
    /// A bandwidth of [`crate::DisturbanceObserver`].
    ObserverBandwidth,
    /// The torque bound of the offset-free state ([`crate::OffsetFree`]).
    OffsetFreeTorqueBound,
    /// The bandwidth of [`crate::AttitudeRateFilter`].
    AttitudeRateBandwidth,
    /// The rate bound of [`crate::AttitudeRateFilter`].
    AttitudeRateLimit,
    /// A stated residual noise of [`crate::FaultDetector`].
    FaultNoise,
    /// The threshold of [`crate::FaultDetector`].
    FaultThreshold,
    /// The persistence of [`crate::FaultDetector`].
    FaultPersistence,
    /// Fault detection without the residual it reads (it needs the disturbance observer,
    /// [`crate::OffsetFree::Observer`]).
    FaultResidual,
    /// A tolerance of [`crate::fault::ReportCheck`] (thrust or gimbal angle).
    ReportTolerance,
    /// The servo rate of [`crate::fault::ReportCheck`].
    ReportServoRate,
    /// The link timeout of [`crate::fault::ReportCheck`].
    ReportLinkTimeout,
    /// The persistence of [`crate::fault::ReportCheck`].
    ReportPersistence,
}

impl ConfigField {
    /// The dotted name used in messages, e.g. `"limits.sigma_x"` or `"gains.k_x"`.
    pub const fn as_str(self) -> &'static str {
        match self {
            Self::AgentPosition => "agent.position",
            Self::AgentMass => "agent.mass",
            Self::AgentInertia => "agent.inertia",
            Self::NavigatorMass => "navigator.mass",
            Self::NavigatorInertia => "navigator.inertia",
            Self::SigmaX => "limits.sigma_x",
            Self::SigmaY => "limits.sigma_y",
            Self::MaxThrust => "limits.max_thrust",
            Self::MinThrust => "limits.min_thrust",
            Self::ThrustCoefficient => "limits.thrust_coefficient",
            Self::Rho => "limits.rho",
            Self::RotorDiameter => "limits.d",
            Self::LiftCoefficient => "limits.c_l",
            Self::MaxRotorSpeed => "limits.sigma_omega",
            Self::Relaxation => "relaxation",
            Self::GainKx => "gains.k_x",
            Self::GainKr => "gains.k_r",
            Self::GainKomega => "gains.k_omega",
            Self::GainKv => "gains.k_v",
            Self::Gravity => "gravity",
            Self::PlantMass => "plant.mass",
            Self::PlantInertia => "plant.inertia",
            Self::TeamInertia => "team.inertia",
            Self::Period => "period",
            Self::RateLimits => "rate_limits",
            Self::PlannerTolerance => "planner.tolerance",
            Self::PlannerMaxIterations => "planner.max_iterations",
            Self::AllocatorWeights => "allocation.weights",
            Self::AllocatorMaxRounds => "allocation.max_rounds",
            Self::ClarabelLambda => "clarabel.lambda",
            Self::ClarabelWeights => "clarabel.weights",
            Self::ClarabelTolerance => "clarabel.tolerance",
            Self::NullSpaceIterations => "null_space.iterations",
            Self::NullSpaceTilt => "null_space.tilt",
            Self::NaturalFrequency => "gains.natural_frequency",
            Self::DampingRatio => "gains.damping_ratio",
            Self::IntegralGain => "offset_free.integral_gain",
            Self::ObserverBandwidth => "offset_free.bandwidth",
            Self::OffsetFreeTorqueBound => "offset_free.max_torque",
            Self::AttitudeRateBandwidth => "attitude_rate.bandwidth",
            Self::AttitudeRateLimit => "attitude_rate.max_rate",
            Self::FaultNoise => "fault.noise",
            Self::FaultThreshold => "fault.threshold",
            Self::FaultPersistence => "fault.persistence",
            Self::FaultResidual => "fault.residual",
            Self::ReportTolerance => "fault.report_tolerance",
            Self::ReportServoRate => "fault.report_servo_rate",
            Self::ReportLinkTimeout => "fault.report_link_timeout",
            Self::ReportPersistence => "fault.report_persistence",
        }
    }
}

/// `value` when it is finite and positive; else [`ConfigError::NonFinite`] or
/// [`ConfigError::Parameter`] naming `field` (the one check of the settings' plain numbers).
pub(crate) fn positive<T: nalgebra::RealField + Copy>(
    value: T,
    field: ConfigField,
) -> Result<T, ConfigError> {
    if !value.is_finite() {
        return Err(ConfigError::NonFinite { field });
    }
    if value <= T::zero() {
        return Err(ConfigError::Parameter { field });
    }
    Ok(value)
}

impl fmt::Display for ConfigField {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
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
        /// The field, e.g. [`ConfigField::AgentPosition`].
        field: ConfigField,
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
        /// Which constant.
        field: ConfigField,
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
    /// Agent `agent`'s inertia `J_i` is not symmetric positive semi-definite.
    AgentInertia {
        /// The agent's index in the team's agent list.
        agent: usize,
    },
    /// A matrix that must be symmetric positive definite (a gain, the plant's or the team's
    /// inertia) is not: it is not symmetric, or it has a non-positive eigenvalue.
    NotSymmetricPositiveDefinite {
        /// The matrix, e.g. [`ConfigField::GainKr`].
        field: ConfigField,
    },
    /// Finite inputs whose derived quantity (a sum, a product, `M M^T`) is not finite in the
    /// float type: the values are too large to be carried through the cycle.
    Overflow {
        /// The derived quantity, e.g. `"team mass m_C"`.
        quantity: &'static str,
        /// The input it is derived from.
        field: ConfigField,
    },
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
        /// The parameter, e.g. [`ConfigField::GainKx`].
        field: ConfigField,
    },
    /// A failure mask names an agent the team does not have.
    FailureIndex {
        /// The index.
        agent: usize,
    },
    /// No allocator has this name (see [`crate::AnyAllocator::NAMES`]).
    UnknownAllocator,
    /// The named allocator needs a cargo feature this build does not have.
    AllocatorUnavailable {
        /// The allocator (`"clarabel"` or `"clarabel-sequential"`, feature `clarabel`).
        name: &'static str,
    },
    /// A stage this build does not link (the null-space stage without the feature `null-space`).
    StageUnavailable {
        /// The stage (`"null-space"`).
        name: &'static str,
        /// The cargo feature of `tvmd-core` that links it.
        feature: &'static str,
    },
    /// An option given to [`crate::AnyAllocator::from_name`] that the named allocator does not
    /// take.
    UnusedOption {
        /// The option.
        field: ConfigField,
    },
}

impl ConfigError {
    /// The setting the error names, when it names one (`None` for errors about the team as a
    /// whole, e.g. [`ConfigError::RankDeficient`]).
    pub fn field(&self) -> Option<ConfigField> {
        match *self {
            Self::NonFinite { field }
            | Self::NotSymmetricPositiveDefinite { field }
            | Self::Overflow { field, .. }
            | Self::NonPositiveThrust { field, .. }
            | Self::Parameter { field }
            | Self::UnusedOption { field } => Some(field),
            Self::GimbalLimit {
                axis: GimbalAxis::X,
                ..
            } => Some(ConfigField::SigmaX),
            Self::GimbalLimit {
                axis: GimbalAxis::Y,
                ..
            } => Some(ConfigField::SigmaY),
            Self::NonPositiveMass {
                of: MassOf::Agent(_),
                ..
            } => Some(ConfigField::AgentMass),
            Self::NonPositiveMass {
                of: MassOf::Navigator,
                ..
            } => Some(ConfigField::NavigatorMass),
            Self::IdleThrust { .. } => Some(ConfigField::MinThrust),
            Self::NavigatorInertia => Some(ConfigField::NavigatorInertia),
            Self::AgentInertia { .. } => Some(ConfigField::AgentInertia),
            Self::Relaxation { .. } => Some(ConfigField::Relaxation),
            Self::NoAgents
            | Self::TooManyAgents { .. }
            | Self::RankDeficient { .. }
            | Self::AgentCount { .. }
            | Self::FailureIndex { .. }
            | Self::UnknownAllocator
            | Self::AllocatorUnavailable { .. }
            | Self::StageUnavailable { .. } => None,
        }
    }
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
            Self::NonPositiveThrust { value, .. } => {
                write!(f, "maximum thrust (or rotor constant) {value} must be > 0")
            }
            Self::IdleThrust { value } => {
                write!(f, "idle thrust {value} N must be in [0, max thrust)")
            }
            Self::NavigatorInertia => write!(
                f,
                "the navigator inertia must be symmetric positive semi-definite"
            ),
            Self::AgentInertia { agent } => write!(
                f,
                "agent {agent}'s inertia must be symmetric positive semi-definite"
            ),
            Self::NotSymmetricPositiveDefinite { field } => {
                write!(f, "`{field}` must be a symmetric positive definite matrix")
            }
            Self::Overflow { quantity, field } => write!(
                f,
                "the {quantity} derived from `{field}` is not finite in this float type (values too large)"
            ),
            Self::RankDeficient { conditioning } => write!(
                f,
                "M(Xi) is not rank 6 (eig_min/eig_max of M M^T = {conditioning:e}): the team cannot produce every wrench"
            ),
            Self::AgentCount { n, n_x } => write!(f, "n_x = {n_x} exceeds n = {n} (or n = 0)"),
            Self::Relaxation { value } => write!(f, "relaxation s = {value} is outside (0, 1]"),
            Self::Parameter {
                field: ConfigField::FaultResidual,
            } => f.write_str(
                "fault detection reads the disturbance observer's residual: it needs the \
                 offset-free law's observer",
            ),
            Self::Parameter { field } => write!(f, "`{field}` must be positive and finite"),
            Self::FailureIndex { agent } => {
                write!(f, "failure mask names agent {agent}, which the team does not have")
            }
            Self::UnknownAllocator => f.write_str(
                "unknown allocator name (the known ones are tvmd_core::AnyAllocator::NAMES)",
            ),
            Self::AllocatorUnavailable { name } => write!(
                f,
                "allocator `{name}` needs the cargo feature `clarabel`, which this build lacks"
            ),
            Self::StageUnavailable { name, feature } => {
                write!(f, "the {name} stage needs tvmd-core's cargo feature `{feature}`")
            }
            Self::UnusedOption { field } => {
                write!(f, "the allocator takes no `{field}` option")
            }
        }
    }
}

#[cfg(feature = "std")]
impl std::error::Error for ConfigError {}
