//! Status codes: `0` success; `1..=9` errors of the C boundary itself; `10..=19` one per
//! [`InputError`] variant (a control cycle refused its inputs); `20..=49` one per
//! [`ConfigError`] variant (a configuration or failure mask refused); `50..=59` actuator-map
//! errors. The mapping is exhaustive, so a new core variant fails to compile until it has a code.

use tvmd_core::{ConfigError, ConfigField, InputError};

/// A status code returned by every fallible entry point (`TVMD_OK` or one of `TVMD_ERR_*`).
pub type TvmdStatus = i32;

/// Success.
pub const TVMD_OK: TvmdStatus = 0;
/// A required pointer argument is null.
pub const TVMD_ERR_NULL_POINTER: TvmdStatus = 1;
/// A struct's `size` field (or the storage size argument) is not this library's
/// `sizeof` of it: the caller was built against another version of `tvmd.h`.
pub const TVMD_ERR_SIZE: TvmdStatus = 2;
/// The controller storage is not aligned to `tvmd_controller_align()`.
pub const TVMD_ERR_ALIGNMENT: TvmdStatus = 3;
/// The handle was never created, or its last `tvmd_create` failed.
pub const TVMD_ERR_NOT_INITIALIZED: TvmdStatus = 4;
/// An enum field (`limits.rotor_model`, `law.gain_schedule`, `law.offset_free`,
/// `map.motor_curve`) has a value this library does not know.
pub const TVMD_ERR_ENUM_VALUE: TvmdStatus = 5;
/// The handle's storage was overwritten: its start says created, but the guard at its end
/// does not hold (a neighbouring buffer overran it), or a count, flag or enum tag the
/// controller keeps holds a value no controller has (a stray write inside it; see
/// `tvmd_check`). Create the controller again.
pub const TVMD_ERR_CORRUPTED: TvmdStatus = 6;

/// [`InputError::NonFinite`]: a NaN or infinite number in the state or reference.
pub const TVMD_ERR_INPUT_NON_FINITE: TvmdStatus = 10;
/// [`InputError::NotRotation`]: an attitude input is not a rotation matrix.
pub const TVMD_ERR_INPUT_NOT_ROTATION: TvmdStatus = 11;
/// [`InputError::OutOfRange`]: a finite input beyond the controller's bound
/// (`Controller::input_limit`).
pub const TVMD_ERR_INPUT_OUT_OF_RANGE: TvmdStatus = 12;
/// [`InputError::Unattainable`]: the only admissible answer to a non-zero force request is
/// zero thrust everywhere (refused rather than a free fall).
pub const TVMD_ERR_INPUT_UNATTAINABLE: TvmdStatus = 13;
/// [`InputError::Overflow`]: a non-finite output although the inputs were in range (a bug).
pub const TVMD_ERR_INPUT_OVERFLOW: TvmdStatus = 14;

/// [`ConfigError::NoAgents`]: no agent, or every agent marked failed.
pub const TVMD_ERR_CONFIG_NO_AGENTS: TvmdStatus = 20;
/// [`ConfigError::TooManyAgents`]: `agent_count` above `TVMD_MAX_AGENTS`.
pub const TVMD_ERR_CONFIG_TOO_MANY_AGENTS: TvmdStatus = 21;
/// [`ConfigError::NonFinite`]: a NaN or infinite configuration number (also a gain that the
/// gain schedule makes overflow).
pub const TVMD_ERR_CONFIG_NON_FINITE: TvmdStatus = 22;
/// [`ConfigError::GimbalLimit`]: `sigma_x` or `sigma_y` outside `(0, pi/2]`.
pub const TVMD_ERR_CONFIG_GIMBAL_LIMIT: TvmdStatus = 23;
/// [`ConfigError::NonPositiveMass`]: an agent mass `<= 0` or a navigator mass `< 0`.
pub const TVMD_ERR_CONFIG_MASS: TvmdStatus = 24;
/// [`ConfigError::NonPositiveThrust`]: `max_thrust` or a rotor constant `<= 0`.
pub const TVMD_ERR_CONFIG_THRUST: TvmdStatus = 25;
/// [`ConfigError::IdleThrust`]: `min_thrust` outside `[0, max_thrust)`.
pub const TVMD_ERR_CONFIG_IDLE_THRUST: TvmdStatus = 26;
/// [`ConfigError::NavigatorInertia`]: not symmetric positive semi-definite.
pub const TVMD_ERR_CONFIG_NAVIGATOR_INERTIA: TvmdStatus = 27;
/// [`ConfigError::AgentInertia`]: an agent inertia not symmetric positive semi-definite.
pub const TVMD_ERR_CONFIG_AGENT_INERTIA: TvmdStatus = 28;
/// [`ConfigError::NotSymmetricPositiveDefinite`]: a gain or the team inertia.
pub const TVMD_ERR_CONFIG_NOT_SPD: TvmdStatus = 29;
/// [`ConfigError::Overflow`]: finite values whose derived quantity overflows `f32`.
pub const TVMD_ERR_CONFIG_OVERFLOW: TvmdStatus = 30;
/// [`ConfigError::RankDeficient`]: the (working) team cannot produce every wrench.
pub const TVMD_ERR_CONFIG_RANK_DEFICIENT: TvmdStatus = 31;
/// [`ConfigError::AgentCount`]: `n_x > n` (not reachable through this API; kept one-to-one).
pub const TVMD_ERR_CONFIG_AGENT_COUNT: TvmdStatus = 32;
/// [`ConfigError::Relaxation`]: the relaxation `s` outside `(0, 1]`.
pub const TVMD_ERR_CONFIG_RELAXATION: TvmdStatus = 33;
/// [`ConfigError::Parameter`]: a gravity, period, rate limit, allocator weight or a number of
/// `law` (natural frequency, damping ratio, observer bandwidth, integral gain, torque bound,
/// planned-rate bandwidth or bound) not positive, or a capped redistribution's 0 rounds.
pub const TVMD_ERR_CONFIG_PARAMETER: TvmdStatus = 34;
/// [`ConfigError::FailureIndex`]: a failure mask bit at or beyond the team's agent count.
pub const TVMD_ERR_CONFIG_FAILURE_INDEX: TvmdStatus = 35;
/// [`ConfigError::UnknownAllocator`]: `allocator` is none of `TVMD_ALLOCATOR_*`.
pub const TVMD_ERR_CONFIG_UNKNOWN_ALLOCATOR: TvmdStatus = 36;
/// [`ConfigError::AllocatorUnavailable`]: the allocator needs a feature this build lacks.
pub const TVMD_ERR_CONFIG_ALLOCATOR_UNAVAILABLE: TvmdStatus = 37;
/// [`ConfigError::UnusedOption`]: an option the chosen allocator does not take.
pub const TVMD_ERR_CONFIG_UNUSED_OPTION: TvmdStatus = 38;
/// [`ConfigError::StageUnavailable`]: a stage this build does not link (the null-space stage;
/// not reachable through this API, whose configuration has none; kept one-to-one).
pub const TVMD_ERR_CONFIG_STAGE_UNAVAILABLE: TvmdStatus = 39;

/// The actuator map's agent count is not the controller's.
pub const TVMD_ERR_MAP_AGENT_COUNT: TvmdStatus = 50;
/// A channel index of the actuator map is at or beyond its kind's channels: motors
/// `TVMD_MOTOR_CHANNELS` (12, PX4's `actuator_motors`), servos `TVMD_SERVO_CHANNELS` (8, PX4's
/// `actuator_servos`).
pub const TVMD_ERR_MAP_CHANNEL_RANGE: TvmdStatus = 51;
/// Two outputs of the actuator map share a channel (motors and servos are counted apart).
pub const TVMD_ERR_MAP_DUPLICATE_CHANNEL: TvmdStatus = 52;
/// A servo's trim, direction or range is unusable: not finite, direction not `+1`/`-1`,
/// range `<= 0`, or `|trim| + sigma / range > 1` (the gimbal's travel would leave `[-1, 1]`).
pub const TVMD_ERR_MAP_SERVO: TvmdStatus = 53;
/// A command given to `tvmd_actuator_outputs` is not finite or outside `E_f`; or an actuator
/// output given to the inverse mapping is not finite, outside its range, or an agent's two
/// motor channels differ.
pub const TVMD_ERR_ACTUATOR_VALUE: TvmdStatus = 54;

/// `tvmd_set_agent_report`: the report's agent is not in the team.
pub const TVMD_ERR_REPORT_AGENT: TvmdStatus = 60;
/// `tvmd_set_agent_report`: the controller was created without fault detection
/// (`fault.mode = TVMD_FAULT_OFF`): nothing would read the report.
pub const TVMD_ERR_REPORT_DETECTION_OFF: TvmdStatus = 61;

/// The code of a core input error.
pub fn input_status(error: &InputError) -> TvmdStatus {
    match error {
        InputError::NonFinite { .. } => TVMD_ERR_INPUT_NON_FINITE,
        InputError::NotRotation { .. } => TVMD_ERR_INPUT_NOT_ROTATION,
        InputError::OutOfRange { .. } => TVMD_ERR_INPUT_OUT_OF_RANGE,
        InputError::Unattainable { .. } => TVMD_ERR_INPUT_UNATTAINABLE,
        InputError::Overflow { .. } => TVMD_ERR_INPUT_OVERFLOW,
    }
}

/// The code of a core configuration error.
pub fn config_status(error: &ConfigError) -> TvmdStatus {
    match error {
        ConfigError::NoAgents => TVMD_ERR_CONFIG_NO_AGENTS,
        ConfigError::TooManyAgents { .. } => TVMD_ERR_CONFIG_TOO_MANY_AGENTS,
        ConfigError::NonFinite { .. } => TVMD_ERR_CONFIG_NON_FINITE,
        ConfigError::GimbalLimit { .. } => TVMD_ERR_CONFIG_GIMBAL_LIMIT,
        ConfigError::NonPositiveMass { .. } => TVMD_ERR_CONFIG_MASS,
        ConfigError::NonPositiveThrust { .. } => TVMD_ERR_CONFIG_THRUST,
        ConfigError::IdleThrust { .. } => TVMD_ERR_CONFIG_IDLE_THRUST,
        ConfigError::NavigatorInertia => TVMD_ERR_CONFIG_NAVIGATOR_INERTIA,
        ConfigError::AgentInertia { .. } => TVMD_ERR_CONFIG_AGENT_INERTIA,
        ConfigError::NotSymmetricPositiveDefinite { .. } => TVMD_ERR_CONFIG_NOT_SPD,
        // A gain that natural frequencies make overflow keeps its documented code (the core
        // names the frequencies since issue 57; the status C callers test is unchanged).
        ConfigError::Overflow {
            field: ConfigField::NaturalFrequency,
            ..
        } => TVMD_ERR_CONFIG_NON_FINITE,
        ConfigError::Overflow { .. } => TVMD_ERR_CONFIG_OVERFLOW,
        ConfigError::RankDeficient { .. } => TVMD_ERR_CONFIG_RANK_DEFICIENT,
        ConfigError::AgentCount { .. } => TVMD_ERR_CONFIG_AGENT_COUNT,
        ConfigError::Relaxation { .. } => TVMD_ERR_CONFIG_RELAXATION,
        ConfigError::Parameter { .. } => TVMD_ERR_CONFIG_PARAMETER,
        ConfigError::FailureIndex { .. } => TVMD_ERR_CONFIG_FAILURE_INDEX,
        ConfigError::UnknownAllocator => TVMD_ERR_CONFIG_UNKNOWN_ALLOCATOR,
        ConfigError::AllocatorUnavailable { .. } => TVMD_ERR_CONFIG_ALLOCATOR_UNAVAILABLE,
        ConfigError::UnusedOption { .. } => TVMD_ERR_CONFIG_UNUSED_OPTION,
        ConfigError::StageUnavailable { .. } => TVMD_ERR_CONFIG_STAGE_UNAVAILABLE,
    }
}

/// Why a configuration could not be converted: an enum value, or a core error.
#[derive(Debug)]
pub(crate) enum ConvertError {
    EnumValue,
    Config(ConfigError),
}

impl ConvertError {
    pub(crate) fn status(&self) -> TvmdStatus {
        match self {
            Self::EnumValue => TVMD_ERR_ENUM_VALUE,
            Self::Config(e) => config_status(e),
        }
    }
}

impl From<ConfigError> for ConvertError {
    fn from(e: ConfigError) -> Self {
        Self::Config(e)
    }
}

/// A short static name of a status code (`"TVMD_OK"`, `"TVMD_ERR_SIZE"`, ...), NUL-terminated,
/// never null; `"TVMD_UNKNOWN_STATUS"` for a value no entry point returns.
#[no_mangle]
pub extern "C" fn tvmd_status_name(status: TvmdStatus) -> *const core::ffi::c_char {
    let name: &'static str = match status {
        TVMD_OK => "TVMD_OK\0",
        TVMD_ERR_NULL_POINTER => "TVMD_ERR_NULL_POINTER\0",
        TVMD_ERR_SIZE => "TVMD_ERR_SIZE\0",
        TVMD_ERR_ALIGNMENT => "TVMD_ERR_ALIGNMENT\0",
        TVMD_ERR_NOT_INITIALIZED => "TVMD_ERR_NOT_INITIALIZED\0",
        TVMD_ERR_ENUM_VALUE => "TVMD_ERR_ENUM_VALUE\0",
        TVMD_ERR_CORRUPTED => "TVMD_ERR_CORRUPTED\0",
        TVMD_ERR_INPUT_NON_FINITE => "TVMD_ERR_INPUT_NON_FINITE\0",
        TVMD_ERR_INPUT_NOT_ROTATION => "TVMD_ERR_INPUT_NOT_ROTATION\0",
        TVMD_ERR_INPUT_OUT_OF_RANGE => "TVMD_ERR_INPUT_OUT_OF_RANGE\0",
        TVMD_ERR_INPUT_UNATTAINABLE => "TVMD_ERR_INPUT_UNATTAINABLE\0",
        TVMD_ERR_INPUT_OVERFLOW => "TVMD_ERR_INPUT_OVERFLOW\0",
        TVMD_ERR_CONFIG_NO_AGENTS => "TVMD_ERR_CONFIG_NO_AGENTS\0",
        TVMD_ERR_CONFIG_TOO_MANY_AGENTS => "TVMD_ERR_CONFIG_TOO_MANY_AGENTS\0",
        TVMD_ERR_CONFIG_NON_FINITE => "TVMD_ERR_CONFIG_NON_FINITE\0",
        TVMD_ERR_CONFIG_GIMBAL_LIMIT => "TVMD_ERR_CONFIG_GIMBAL_LIMIT\0",
        TVMD_ERR_CONFIG_MASS => "TVMD_ERR_CONFIG_MASS\0",
        TVMD_ERR_CONFIG_THRUST => "TVMD_ERR_CONFIG_THRUST\0",
        TVMD_ERR_CONFIG_IDLE_THRUST => "TVMD_ERR_CONFIG_IDLE_THRUST\0",
        TVMD_ERR_CONFIG_NAVIGATOR_INERTIA => "TVMD_ERR_CONFIG_NAVIGATOR_INERTIA\0",
        TVMD_ERR_CONFIG_AGENT_INERTIA => "TVMD_ERR_CONFIG_AGENT_INERTIA\0",
        TVMD_ERR_CONFIG_NOT_SPD => "TVMD_ERR_CONFIG_NOT_SPD\0",
        TVMD_ERR_CONFIG_OVERFLOW => "TVMD_ERR_CONFIG_OVERFLOW\0",
        TVMD_ERR_CONFIG_RANK_DEFICIENT => "TVMD_ERR_CONFIG_RANK_DEFICIENT\0",
        TVMD_ERR_CONFIG_AGENT_COUNT => "TVMD_ERR_CONFIG_AGENT_COUNT\0",
        TVMD_ERR_CONFIG_RELAXATION => "TVMD_ERR_CONFIG_RELAXATION\0",
        TVMD_ERR_CONFIG_PARAMETER => "TVMD_ERR_CONFIG_PARAMETER\0",
        TVMD_ERR_CONFIG_FAILURE_INDEX => "TVMD_ERR_CONFIG_FAILURE_INDEX\0",
        TVMD_ERR_CONFIG_UNKNOWN_ALLOCATOR => "TVMD_ERR_CONFIG_UNKNOWN_ALLOCATOR\0",
        TVMD_ERR_CONFIG_ALLOCATOR_UNAVAILABLE => "TVMD_ERR_CONFIG_ALLOCATOR_UNAVAILABLE\0",
        TVMD_ERR_CONFIG_UNUSED_OPTION => "TVMD_ERR_CONFIG_UNUSED_OPTION\0",
        TVMD_ERR_CONFIG_STAGE_UNAVAILABLE => "TVMD_ERR_CONFIG_STAGE_UNAVAILABLE\0",
        TVMD_ERR_MAP_AGENT_COUNT => "TVMD_ERR_MAP_AGENT_COUNT\0",
        TVMD_ERR_MAP_CHANNEL_RANGE => "TVMD_ERR_MAP_CHANNEL_RANGE\0",
        TVMD_ERR_MAP_DUPLICATE_CHANNEL => "TVMD_ERR_MAP_DUPLICATE_CHANNEL\0",
        TVMD_ERR_MAP_SERVO => "TVMD_ERR_MAP_SERVO\0",
        TVMD_ERR_ACTUATOR_VALUE => "TVMD_ERR_ACTUATOR_VALUE\0",
        TVMD_ERR_REPORT_AGENT => "TVMD_ERR_REPORT_AGENT\0",
        TVMD_ERR_REPORT_DETECTION_OFF => "TVMD_ERR_REPORT_DETECTION_OFF\0",
        _ => "TVMD_UNKNOWN_STATUS\0",
    };
    name.as_ptr().cast()
}
