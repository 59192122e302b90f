//! Scenarios: TOML files (serde) and built-ins.
//!
//! Every field has a default (the paper's simulation, scenario `paper-tilt`), so a file only
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
//! kind = "no-thrust"         # "stuck-gimbal", "no-thrust-stuck-gimbal"
//! controller_informed = true
//!
//! [failure_response]
//! on_hover_loss = "land"     # default "continue"; "land": fall level to the ground when the
//! landing_acceleration = 1.0 # working agents are classified not hover-capable (m/s^2)
//!
//! [disturbances]
//! wind = [0.5, 0.0, 0.0]
//! external_wrench = { force = [0.0, 0.0, 0.0], torque = [0.0, 0.0, 0.1], start = 3.0, end = 4.0 }
//! state_noise = { position = 0.01, velocity = 0.02, attitude = 0.005, angular_velocity = 0.01, seed = 7 }
//!
//! [success]                  # the verdict's bounds (see `SuccessBounds`)
//! max_steady_state_position_error = 0.05
//! # max_settling_time = 6.0
//! ```

use std::f64::consts::PI;
use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::actuators::{ActuatorModel, FailureKind, SaturationLimits};
use crate::log::LogSettings;
use crate::physics::{AgentBody, PhysicsConfig, TeamBody, DEFAULT_COLLIDER_RADIUS};
use crate::reference::ReferenceConfig;
use crate::{SimError, GRAVITY};
use tvmd_core::team::presets::Preset;

mod air;
mod builtin;
mod certified;
mod families;

/// The largest scenario file read (1 MiB; the built-ins are under 3 KiB).
pub const MAX_SCENARIO_BYTES: u64 = 1 << 20;
mod null_space;
mod overrides;
mod plant;
mod success;
mod validate;

pub use air::{Air, Gust, DRAG_AREA_PER_AGENT};
pub use builtin::BUILTIN_NAMES;
pub use families::{FAMILY_NAMES, HOVER_HEIGHT, RELEASE_HEIGHT};
pub use null_space::{
    NullSpaceConfig, NullSpaceKind, DEFAULT_NULL_SPACE_ITERATIONS, NULL_SPACE_OBJECTIVES,
};
pub use overrides::Overrides;
pub use plant::{Payload, PlantError};
pub use success::{SuccessBounds, Verdict};
use validate::invalid;

/// Allocator names this build runs (the core's table, [`tvmd_core::AnyAllocator::NAMES`]); a
/// scenario may also name `"clarabel"` or `"clarabel-sequential"`, which need the `clarabel`
/// feature at run time.
pub const ALLOCATOR_NAMES: &[&str] = tvmd_core::AnyAllocator::<f64, 1>::NAMES;

/// The float type the controller runs in (the physics is always f64).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Precision {
    /// `f64`: `tvmd_core::Controller<f64, ..>` (analysis; the default).
    #[default]
    F64,
    /// `f32`: `tvmd_core::Controller<f32, ..>`, the type a flight controller runs.
    F32,
}

impl Precision {
    /// Every precision, in the order `f64`, `f32`.
    pub const ALL: [Precision; 2] = [Precision::F64, Precision::F32];

    /// The name used in scenarios, on the command line and in summaries: `"f64"` or `"f32"`.
    pub fn as_str(self) -> &'static str {
        match self {
            Precision::F64 => "f64",
            Precision::F32 => "f32",
        }
    }
}

impl std::fmt::Display for Precision {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

impl std::str::FromStr for Precision {
    type Err = SimError;

    /// Parses `"f64"` or `"f32"`; anything else is an invalid `controller_precision`.
    fn from_str(s: &str) -> Result<Self, SimError> {
        match s {
            "f64" => Ok(Precision::F64),
            "f32" => Ok(Precision::F32),
            other => Err(invalid(
                "controller_precision",
                format!("unknown precision `{other}` (known: f64, f32)"),
            )),
        }
    }
}

/// The team: a preset or explicit agents.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct TeamSpec {
    /// A catalogue team (`tvmd_core::team::presets::Preset::name`: `"a3-con"` .. `"t10-inc"`,
    /// `"a4-inc"` the paper's); used when `agents` is absent (default `"a4-inc"`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub preset: Option<String>,
    /// Explicit agents (positions relative to the team centre of mass); excludes `preset`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub agents: Option<Vec<AgentBody>>,
    /// Agent mass for presets (kg); 0.7.
    pub agent_mass: f64,
    /// Grid unit of the presets (m): the half side `a` of the A4 square, `0.5 sqrt(2)/2` by
    /// default (the authors' `GRID_SIZE`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub arm: Option<f64>,
    /// Navigator mass (kg); 0.
    pub navigator_mass: f64,
    /// Navigator inertia (kg m^2, row-major); 0.
    pub navigator_inertia: [[f64; 3]; 3],
    /// Collider radius (m); 0.05.
    pub collider_radius: f64,
}

impl Default for TeamSpec {
    fn default() -> Self {
        Self {
            preset: None,
            agents: None,
            agent_mass: 0.7,
            arm: None,
            navigator_mass: 0.0,
            navigator_inertia: [[0.0; 3]; 3],
            collider_radius: DEFAULT_COLLIDER_RADIUS,
        }
    }
}

impl TeamSpec {
    /// Resolves the preset or the explicit agents into a validated [`TeamBody`].
    pub fn team_body(&self) -> Result<TeamBody, SimError> {
        let invalid = |field: &str, reason: String| SimError::InvalidScenario {
            field: field.into(),
            reason,
        };
        let mut body = match (&self.preset, &self.agents) {
            (Some(_), Some(_)) => {
                return Err(invalid(
                    "team.agents",
                    "give either `team.preset` or `team.agents`, not both".into(),
                ))
            }
            (None, Some(agents)) => TeamBody {
                agents: agents.clone(),
                navigator_mass: 0.0,
                navigator_inertia: [[0.0; 3]; 3],
                collider_radius: DEFAULT_COLLIDER_RADIUS,
            },
            (preset, None) => {
                let name = preset.as_deref().unwrap_or("a4-inc");
                let Some(preset) = Preset::from_name(name) else {
                    let known: Vec<&str> = Preset::ALL.iter().map(|p| p.name()).collect();
                    return Err(invalid(
                        "team.preset",
                        format!("unknown preset `{name}` (known: {})", known.join(", ")),
                    ));
                };
                let unit = self.arm.unwrap_or_else(TeamBody::paper_arm);
                TeamBody::preset(preset, unit, self.agent_mass)
                    .map_err(|e| invalid("team", e.to_string()))?
            }
        };
        body.navigator_mass = self.navigator_mass;
        body.navigator_inertia = self.navigator_inertia;
        body.collider_radius = self.collider_radius;
        body.validate()
            .map_err(|e| invalid("team", e.to_string()))?;
        Ok(body)
    }
}

/// Gimbal and thrust limits (eq. 6).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct LimitsConfig {
    /// `sigma_x` (rad); `pi/6`.
    pub sigma_x: f64,
    /// `sigma_y` (rad); `pi/4`.
    pub sigma_y: f64,
    /// `sigma_Tf`, maximum thrust of one agent (N); default `2 m_i g` of the heaviest agent.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_thrust: Option<f64>,
}

impl Default for LimitsConfig {
    fn default() -> Self {
        Self {
            sigma_x: PI / 6.0,
            sigma_y: PI / 4.0,
            max_thrust: None,
        }
    }
}

/// Controller gains (diagonals), not scaled by mass or inertia.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct GainsConfig {
    /// `K_x`; `[0.4, 0.4, 1]`.
    pub k_x: [f64; 3],
    /// `K_R`; `[12, 12, 1]`.
    pub k_r: [f64; 3],
    /// `K_xi = diag(K_Omega, K_v)`; `[8, 8, 1.5, 0.8, 0.8, 2]`.
    pub k_xi: [f64; 6],
}

impl Default for GainsConfig {
    fn default() -> Self {
        Self {
            k_x: [0.4, 0.4, 1.0],
            k_r: [12.0, 12.0, 1.0],
            k_xi: [8.0, 8.0, 1.5, 0.8, 0.8, 2.0],
        }
    }
}

/// An agent failure.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Failure {
    /// Agent index (0-based).
    pub agent: usize,
    /// Failure time (s).
    pub time: f64,
    /// What fails.
    pub kind: FailureKind,
    /// Whether the controller is told (through the `failed` flags); default true.
    #[serde(default = "default_true")]
    pub controller_informed: bool,
}

fn default_true() -> bool {
    true
}

/// What the controller does when an accepted failure mask leaves a team that cannot hold hover
/// with a margin ([`tvmd_core::Controller::set_failures`]'s classification).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum OnHoverLoss {
    /// Keep flying the scenario's reference (the default; the classification is only logged).
    #[default]
    Continue,
    /// Replace the reference by a level descent at the current `x`, `y` to the rest height
    /// `z = 0` at the downward acceleration `landing_acceleration`, then idle the rotors.
    Land,
}

/// The scenario's response to a hover-capability loss (`[failure_response]`).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct FailureResponse {
    /// `"continue"` (default) or `"land"`.
    pub on_hover_loss: OnHoverLoss,
    /// Downward acceleration of the landing reference (m/s^2); 1.0. The reference falls from
    /// where the loss was classified to `z = 0` (asking the agents for `m_C (g - a)`, which
    /// leaves a margin of about `a / g` for the attitude), touching down at `sqrt(2 a z_0)`
    /// (1.7 m/s from 1.5 m). Measured on `agent-failure` (A4-Inc minus one), largest tilt
    /// after the failure in f64 / f32: 0.5 m/s^2: 0.000 / 0.000 rad; 1.0: 0.000 / 0.017;
    /// 1.5: 0.001 / 0.027; 2.5: 0.000 / 0.001.
    pub landing_acceleration: f64,
}

impl Default for FailureResponse {
    fn default() -> Self {
        Self {
            on_hover_loss: OnHoverLoss::Continue,
            landing_acceleration: 1.0,
        }
    }
}

/// A constant external wrench over a time window.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExternalWrenchSpec {
    /// Force through the centre of mass, world frame (N).
    #[serde(default)]
    pub force: [f64; 3],
    /// Torque, body frame (N m).
    #[serde(default)]
    pub torque: [f64; 3],
    /// Start time (s); 0.
    #[serde(default)]
    pub start: f64,
    /// End time (s); none = until the end.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub end: Option<f64>,
}

impl ExternalWrenchSpec {
    /// True if the wrench acts at time `t`.
    pub fn active(&self, t: f64) -> bool {
        t >= self.start && self.end.is_none_or(|e| t < e)
    }
}

/// Gaussian noise on the state fed back to the controller (standard deviations).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct StateNoise {
    /// Position noise per axis (m).
    pub position: f64,
    /// World-frame velocity noise per axis (m/s).
    pub velocity: f64,
    /// Attitude noise: rotation vector per axis (rad), applied as `R exp([n]x)`.
    pub attitude: f64,
    /// Body angular-velocity noise per axis (rad/s).
    pub angular_velocity: f64,
    /// Seed of the random generator (ChaCha8).
    pub seed: u64,
}

impl Default for StateNoise {
    fn default() -> Self {
        Self {
            position: 0.0,
            velocity: 0.0,
            attitude: 0.0,
            angular_velocity: 0.0,
            seed: 1,
        }
    }
}

/// Optional disturbances.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Disturbances {
    /// Constant force through the centre of mass, world frame (N): wind as a force, with no
    /// drag model (see `air` for wind as air velocity).
    pub wind: [f64; 3],
    /// Wind as air velocity (steady plus gusts) through the team's drag.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub air: Option<Air>,
    /// External wrench.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub external_wrench: Option<ExternalWrenchSpec>,
    /// Noise on the fed-back state.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub state_noise: Option<StateNoise>,
}

/// A simulation scenario.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Scenario {
    /// Name.
    pub name: String,
    /// Free text.
    pub description: String,
    /// Simulated duration (s); 16.
    pub duration: f64,
    /// Controller period (s), zero-order hold; 0.01. Must be a multiple of `physics.dt`.
    pub controller_period: f64,
    /// Initial position of the centre of mass (m); `[0.5, -0.5, 0]`, i.e. resting on the
    /// ground (the ground lies at `z = -rest height`, see [`crate::physics`]).
    pub initial_position: [f64; 3],
    /// Initial attitude as roll, pitch, yaw (rad, ZYX: `R = R_z(yaw) R_y(pitch) R_x(roll)`);
    /// level. Away from level the team must start in the air (no agent below the ground).
    pub initial_attitude: [f64; 3],
    /// Planner relaxation `s` in `(0, 1]`; 0.5. In TOML also `"certified"`: the AFS atlas's
    /// `s*` of the team ([`Scenario::certified_relaxation`]), resolved when the file is read.
    pub relaxation: f64,
    /// Allocator name, interpreted by the controller; `"exact-boundary-redistribution"`
    /// (the core's default; also `"redistributed-pseudo-inverse"`, the paper's,
    /// `"pseudo-inverse"`, `"weighted-pseudo-inverse"` with unit weights, and `"clarabel"`,
    /// `"clarabel-sequential"` with the `clarabel` feature).
    pub allocator: String,
    /// Gimbal rate limits `[eta_x, eta_y]` (rad/s) the *controller* respects (rate-constrained
    /// allocation); none by default. Independent of `actuators.servo.rate_limit`, which is the
    /// plant's: give both to model a servo the controller knows about.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub controller_rate_limits: Option<[f64; 2]>,
    /// Optional null-space stage after the allocator (`"margin"`, `"inward-tilt=<rad>"`, or a
    /// table, see [`NullSpaceConfig`]); none by default.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub null_space: Option<NullSpaceConfig>,
    /// The float type the controller runs in, `"f64"` (default) or `"f32"` (the flight
    /// configuration: `tvmd_core::Controller<f32, ..>`). The physics stays f64.
    pub controller_precision: Precision,
    /// Physics settings (step, gravity, ground, friction).
    pub physics: PhysicsConfig,
    /// The team.
    pub team: TeamSpec,
    /// Gimbal and thrust limits.
    pub limits: LimitsConfig,
    /// Controller gains.
    pub gains: GainsConfig,
    /// Reference trajectory.
    pub reference: ReferenceConfig,
    /// Actuator model (ideal by default).
    pub actuators: ActuatorModel,
    /// Agent failures.
    pub failures: Vec<Failure>,
    /// What to do when a failure leaves a team that cannot hold hover.
    pub failure_response: FailureResponse,
    /// Disturbances.
    pub disturbances: Disturbances,
    /// Model error: how the flown team differs from the controller's model of it.
    #[serde(skip_serializing_if = "PlantError::is_nominal")]
    pub plant: PlantError,
    /// Payloads that attach during the flight.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub payloads: Vec<Payload>,
    /// What the run's log keeps (`[log]`: `decimation`, `scene_period`).
    pub log: LogSettings,
    /// The bounds of a successful flight (`[success]`), judged in the summary's verdict.
    pub success: SuccessBounds,
}

impl Default for Scenario {
    fn default() -> Self {
        Self {
            name: "paper-tilt".into(),
            description: "The paper's simulation: A4-Inc, ascent, roll tilt to an infeasible \
                          pi/3, descent; s = 0.5"
                .into(),
            duration: 16.0,
            controller_period: 0.01,
            initial_position: [0.5, -0.5, 0.0],
            initial_attitude: [0.0; 3],
            relaxation: 0.5,
            allocator: tvmd_core::AnyAllocator::<f64, 1>::DEFAULT_NAME.into(),
            controller_rate_limits: None,
            null_space: None,
            controller_precision: Precision::F64,
            physics: PhysicsConfig::default(),
            team: TeamSpec::default(),
            limits: LimitsConfig::default(),
            gains: GainsConfig::default(),
            reference: ReferenceConfig::default(),
            actuators: ActuatorModel::default(),
            failures: Vec::new(),
            failure_response: FailureResponse::default(),
            disturbances: Disturbances::default(),
            plant: PlantError::nominal(),
            payloads: Vec::new(),
            log: LogSettings::default(),
            success: SuccessBounds::default(),
        }
    }
}

impl Scenario {
    /// Parses and validates a scenario from TOML text.
    pub fn from_toml_str(text: &str) -> Result<Self, SimError> {
        let parse_error = |message: String| SimError::ScenarioParse {
            path: None,
            message,
        };
        // Two readings serde's derive cannot express: `relaxation = "certified"` (the atlas's
        // s* of the team, resolved once the team is known) and a `[reference]` table without
        // `kind` (the paper's tilt, as every other field defaults).
        let mut certified = false;
        let rewritten;
        let text = match text.parse::<toml::Table>() {
            Ok(mut table) => {
                let mut changed = false;
                if table.get("relaxation").and_then(toml::Value::as_str) == Some("certified") {
                    table.remove("relaxation");
                    certified = true;
                    changed = true;
                }
                if let Some(toml::Value::Table(reference)) = table.get_mut("reference") {
                    if !reference.contains_key("kind") {
                        reference.insert("kind".into(), "paper-tilt".into());
                        changed = true;
                    }
                }
                if changed {
                    rewritten = toml::to_string(&table).map_err(|e| parse_error(e.to_string()))?;
                    rewritten.as_str()
                } else {
                    text
                }
            }
            Err(_) => text,
        };
        let de = toml::Deserializer::parse(text).map_err(|e| parse_error(e.to_string()))?;
        // serde_path_to_error adds the dotted key path (e.g. `physics.dt`) to the message;
        // toml's own message shows the offending line.
        let mut s: Scenario = serde_path_to_error::deserialize(de).map_err(|e| {
            let path = e.path().to_string();
            let inner = e.into_inner().to_string();
            if path.is_empty() || path == "." {
                parse_error(inner)
            } else {
                parse_error(format!("field `{path}`: {inner}"))
            }
        })?;
        if certified {
            s.relaxation = s.certified_relaxation()?;
        }
        s.validate()?;
        Ok(s)
    }

    /// Reads, parses and validates a scenario file: a regular file (after links) of at most
    /// [`MAX_SCENARIO_BYTES`], so that a device or FIFO is refused before it is opened.
    /// Errors: [`SimError::File`] naming the path (missing, unreadable, not a regular file, too
    /// large, not UTF-8), then as [`Scenario::from_toml_str`].
    pub fn from_file(path: impl AsRef<Path>) -> Result<Self, SimError> {
        use std::io::Read;
        const ACTION: &str = "read the scenario file";
        let path = path.as_ref();
        let refuse = |reason: String| SimError::File {
            action: ACTION,
            path: path.to_path_buf(),
            source: std::io::Error::new(std::io::ErrorKind::InvalidInput, reason),
        };
        let meta = std::fs::metadata(path).map_err(SimError::file(ACTION, path))?;
        if !meta.is_file() {
            return Err(refuse(
                "not a regular file (a directory, device or FIFO)".into(),
            ));
        }
        if meta.len() > MAX_SCENARIO_BYTES {
            return Err(refuse(format!(
                "{} bytes, more than the {MAX_SCENARIO_BYTES} a scenario may have",
                meta.len()
            )));
        }
        let mut text = String::new();
        std::fs::File::open(path)
            .and_then(|f| f.take(MAX_SCENARIO_BYTES + 1).read_to_string(&mut text))
            .map_err(SimError::file(ACTION, path))?;
        if text.len() as u64 > MAX_SCENARIO_BYTES {
            return Err(refuse(format!(
                "grew beyond {MAX_SCENARIO_BYTES} bytes while read"
            )));
        }
        Self::from_toml_str(&text).map_err(|e| match e {
            SimError::ScenarioParse { message, .. } => SimError::ScenarioParse {
                path: Some(path.display().to_string()),
                message,
            },
            other => other,
        })
    }

    /// The scenario named by a command-line or Python argument: a TOML file if `name_or_path`
    /// ends in `.toml` or names an existing file, else a built-in (see [`BUILTIN_NAMES`]).
    /// Errors: [`SimError::File`] for a file that cannot be read, [`SimError::ScenarioParse`] /
    /// [`SimError::InvalidScenario`] naming the field, [`SimError::UnknownScenario`].
    pub fn load(name_or_path: &str) -> Result<Self, SimError> {
        let path = Path::new(name_or_path);
        if name_or_path.ends_with(".toml") || path.is_file() {
            Self::from_file(path)
        } else {
            Self::builtin(name_or_path)
        }
    }

    /// Serialises the scenario as TOML (the format [`Scenario::from_toml_str`] reads).
    pub fn to_toml_string(&self) -> Result<String, SimError> {
        toml::to_string(self).map_err(|e| SimError::ScenarioParse {
            path: None,
            message: e.to_string(),
        })
    }

    /// The team body of this scenario.
    pub fn team_body(&self) -> Result<TeamBody, SimError> {
        self.team.team_body()
    }

    /// `sigma_Tf`: the configured maximum thrust, or `2 m_i g` of the heaviest agent.
    pub fn max_thrust(&self) -> Result<f64, SimError> {
        if let Some(t) = self.limits.max_thrust {
            return Ok(t);
        }
        let team = self.team_body()?;
        let m = team.agents.iter().map(|a| a.mass).fold(0.0, f64::max);
        Ok(2.0 * m * GRAVITY)
    }

    /// The actuator limits of this scenario (for an actuator model that saturates).
    pub fn actuator_limits(&self) -> Result<SaturationLimits, SimError> {
        Ok(SaturationLimits {
            sigma_x: self.limits.sigma_x,
            sigma_y: self.limits.sigma_y,
            max_thrust: self.max_thrust()?,
        })
    }

    /// Number of physics steps per controller period.
    pub fn steps_per_control(&self) -> Result<usize, SimError> {
        let ratio = self.controller_period / self.physics.dt;
        let n = ratio.round();
        if !(n >= 1.0 && (ratio - n).abs() <= 1e-6 * n) {
            return Err(invalid(
                "controller_period",
                format!(
                    "must be a positive integer multiple of physics.dt = {} s, got {} s",
                    self.physics.dt, self.controller_period
                ),
            ));
        }
        Ok(n as usize)
    }
}

#[cfg(test)]
mod tests;
