//! Scenarios: TOML files (serde) and built-ins.
//!
//! Every field has a default (the paper's manoeuvre, scenario `paper-tilt`, but flown with the
//! offset-free law of `[law]`; the built-in `paper-tilt` names `law = "paper"`), so a file only
//! states what differs. Unknown keys are rejected, and parse errors name the offending key
//! (the message shows the key and its line). Semantic checks ([`Scenario::validate`]) name the
//! field by its dotted path.
//!
//! ```toml
//! name = "my-run"
//! duration = 16.0
//! controller_period = 0.01
//! initial_position = [0.5, -0.5, 0.0]
//! relaxation = 0.5
//! allocator = "exact-boundary-redistribution" # "redistributed-pseudo-inverse", "clarabel", ...
//! # allocator_max_rounds = 2                    # cap on its walk per period (default 2; "uncapped")
//! controller_precision = "f64"               # or "f32": the flight configuration
//! # controller_rate_limits = [6.0, 6.0]       # gimbal rates the controller respects (rad/s)
//! # null_space = "margin"                     # null-space stage after the allocator
//!
//! [physics]
//! dt = 0.001
//!
//! [team]
//! preset = "a4-inc"          # any of a3-con .. a10-inc, t10-con, t10-inc; or: agents = [{ position = [..], mass = 0.7, quarter_turns = 1 }, ..]
//!
//! [limits]
//! sigma_x = 0.5235987755982988
//! sigma_y = 0.7853981633974483
//! # max_thrust defaults to 2 m_i g
//!
//! [gains]
//! k_x = [0.4, 0.4, 1.0]
//! k_r = [12.0, 12.0, 1.0]
//! k_xi = [8.0, 8.0, 1.5, 0.8, 0.8, 2.0]
//!
//! [law]                      # the law beyond the paper; this is the default (law = "paper":
//!                            # the [gains] as given, no offset-free action, the reference's rates)
//! gains = { natural = { position_frequency = [1.5, 1.5, 1.5], attitude_frequency = [6.0, 6.0, 6.0] } }
//! offset_free = { kind = "observer", force_bandwidth = 10.0, torque_bandwidth = 10.0, max_torque = 5.0 }
//! attitude_rate = { bandwidth = 20.0, max_rate = 5.0 }
//!
//! [reference]
//! kind = "paper-tilt"        # or "hover" with position = [..] and roll = ..
//! ascent_height = 1.5
//!
//! [actuators]
//! servo = { natural_frequency = 40.0, damping_ratio = 0.8, rate_limit = 6.0 }
//! rotor_lag = { time_constant = 0.03 }
//!
//! [[failures]]
//! agent = 0
//! time = 5.0
//! kind = "no-thrust"         # "stuck-gimbal", "no-thrust-stuck-gimbal", "half-thrust", "link-loss"
//! controller_informed = true
//! informed_after = 0.0        # s; told this long after the failure (telemetry or detector latency)
//!
//! [failure_response]
//! on_hover_loss = "land"     # default "continue"; "land": fall level to the ground when the
//! landing_acceleration = 1.0 # working agents are classified not hover-capable (m/s^2)
//!
//! [disturbances]
//! wind = [0.5, 0.0, 0.0]
//! external_wrench = { force = [0.0, 0.0, 0.0], torque = [0.0, 0.0, 0.1], start = 3.0, end = 4.0 }
//! state_noise = { position = 0.01, velocity = 0.02, attitude = 0.005, angular_velocity = 0.01, seed = 7 }
//! feedback_latency = 1       # the controller sees the state of one period before (default 0)
//!
//! [links]                    # each agent's command link (none by default: commands applied as sent)
//! latency = 0.02             # s
//! jitter = 0.005             # s, uniform extra delay
//! loss = 0.05                # independent losses
//! burst_start = 0.01         # bursts of losses (mean burst_length commands)
//! burst_length = 5.0
//! hold = 0.1                 # s an agent holds its last command without one, then:
//! failsafe = "idle"          # rotor stopped, gimbal level; or "hold"
//!
//! [reports]                  # the agents' own reports (rotor speed as thrust, gimbal angles)
//! rate = 100.0               # Hz
//! latency = 0.02             # s
//! thrust_noise = 0.05        # N
//! angle_noise = 0.005        # rad
//! loss = 0.0
//! dead_esc = "silent"        # or "zero"
//! # lying = [2]              # agents that report their command whatever they do
//!
//! [success]                  # the verdict's bounds (see `SuccessBounds`)
//! max_steady_state_position_error = 0.05
//! # max_settling_time = 6.0
//! ```
//!
//! Files: [`Scenario`] and its parts (team, controller, failures, disturbances, log, success
//! bounds), the built-ins ([`BUILTIN_NAMES`], derived from the families [`FAMILY_NAMES`]),
//! validation, [`Overrides`] and the optional null-space stage.

#![warn(missing_docs)]

mod air;
mod builtin;
mod certified;
mod checks;
mod controller;
pub mod core_config;
pub mod core_float;
mod disturbances;
mod error;
mod experiment;
mod failures;
mod families;
mod fault_detection;
mod law;
mod links;
mod log_settings;
mod name_or;
mod null_space;
mod overrides;
mod plant;
mod report_check;
mod reports;
mod scenario;
mod success;
mod team;
mod validate;

pub use air::{Air, Gust, DRAG_AREA_PER_AGENT};
pub use builtin::{BUILTIN_NAMES, RELAXATION_LANDING_SPOT};
pub use controller::{GainsConfig, Precision, ALLOCATOR_NAMES, ROUND_CAP_UNCAPPED};
pub use disturbances::{Disturbances, ExternalWrenchSpec, StateNoise, MAX_FEEDBACK_LATENCY};
pub use error::ScenarioError;
pub use failures::{Failure, FailureResponse, OnHoverLoss};
pub use families::{FAMILY_NAMES, HOVER_HEIGHT, RELEASE_HEIGHT};
pub use fault_detection::{
    FaultDetectionConfig, FaultResponseConfig, FAULT_MODEL_ERROR, FAULT_PERSISTENCE,
    FAULT_THRESHOLD,
};
pub use law::{
    AttitudeRateConfig, GainScheduleConfig, LawConfig, NaturalGainsConfig, OffsetFreeConfig,
    LAW_NAMES,
};
pub use links::{CommandLinks, LinkFailsafe, MAX_LINK_DELAY};
pub use log_settings::LogSettings;
pub use null_space::{
    NullSpaceConfig, NullSpaceKind, DEFAULT_NULL_SPACE_ITERATIONS, NULL_SPACE_OBJECTIVES,
};
pub use overrides::Overrides;
pub use plant::{Payload, PlantError};
pub use report_check::ReportCheckConfig;
pub use reports::{AgentReports, DeadEsc};
pub use scenario::{Scenario, MAX_SCENARIO_BYTES};
pub use success::SuccessBounds;
pub use team::{LimitsConfig, TeamSpec};

#[cfg(test)]
mod tests;
