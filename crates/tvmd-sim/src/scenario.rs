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
//! allocator = "redistributed-pseudo-inverse"   # "pseudo-inverse", "clarabel", ...
//! # controller_rate_limits = [6.0, 6.0]       # gimbal rates the controller respects (rad/s)
//!
//! [physics]
//! dt = 0.001
//!
//! [team]
//! preset = "a4-inc"          # or: agents = [{ position = [..], mass = 0.7, quarter_turns = 1 }, ..]
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
//! [disturbances]
//! wind = [0.5, 0.0, 0.0]
//! external_wrench = { force = [0.0, 0.0, 0.0], torque = [0.0, 0.0, 0.1], start = 3.0, end = 4.0 }
//! state_noise = { position = 0.01, velocity = 0.02, attitude = 0.005, angular_velocity = 0.01, seed = 7 }
//! ```

use std::f64::consts::PI;
use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::actuators::{ActuatorLimits, ActuatorModel, FailureKind};
use crate::physics::{AgentBody, PhysicsConfig, TeamBody, DEFAULT_COLLIDER_RADIUS};
use crate::reference::{PaperTilt, ReferenceConfig};
use crate::{SimError, GRAVITY};

/// Names of the built-in scenarios, for [`Scenario::builtin`].
pub const BUILTIN_NAMES: &[&str] = &[
    "paper-tilt",
    "relaxation-0.25",
    "relaxation-0.5",
    "relaxation-0.75",
    "relaxation-1.0",
    "paper-tilt-sigma-y-pi6",
    "a4-con",
    "a4-inc",
    "agent-failure",
    "a6-agent-failure",
];

/// Allocator names this build runs (the core's table, [`tvmd_core::AnyAllocator::NAMES`]); a
/// scenario may also name `"clarabel"`, which needs the `clarabel` feature at run time.
pub const ALLOCATOR_NAMES: &[&str] = tvmd_core::AnyAllocator::<f64, 1>::NAMES;

/// The team: a preset or explicit agents.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct TeamSpec {
    /// `"a4-inc"` or `"a4-con"`; used when `agents` is absent (default `"a4-inc"`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub preset: Option<String>,
    /// Explicit agents (positions relative to the team centre of mass); excludes `preset`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub agents: Option<Vec<AgentBody>>,
    /// Agent mass for presets (kg); 0.7.
    pub agent_mass: f64,
    /// Half side `a` of the A4 square for presets (m); default `0.5 sqrt(2)/2`.
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
                let a = self.arm.unwrap_or_else(TeamBody::paper_arm);
                let turns = match preset.as_deref().unwrap_or("a4-inc") {
                    "a4-inc" => [1, 1, 0, 0],
                    "a4-con" => [0, 0, 0, 0],
                    other => {
                        return Err(invalid(
                            "team.preset",
                            format!("unknown preset `{other}` (known: a4-inc, a4-con)"),
                        ))
                    }
                };
                TeamBody::a4(a, self.agent_mass, turns)
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
pub struct Limits {
    /// `sigma_x` (rad); `pi/6`.
    pub sigma_x: f64,
    /// `sigma_y` (rad); `pi/4`.
    pub sigma_y: f64,
    /// `sigma_Tf`, maximum thrust of one agent (N); default `2 m_i g` of the heaviest agent.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_thrust: Option<f64>,
}

impl Default for Limits {
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
pub struct Gains {
    /// `K_x`; `[0.4, 0.4, 1]`.
    pub k_x: [f64; 3],
    /// `K_R`; `[12, 12, 1]`.
    pub k_r: [f64; 3],
    /// `K_xi = diag(K_Omega, K_v)`; `[8, 8, 1.5, 0.8, 0.8, 2]`.
    pub k_xi: [f64; 6],
}

impl Default for Gains {
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
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Disturbances {
    /// Constant wind force through the centre of mass, world frame (N).
    pub wind: [f64; 3],
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
    /// Planner relaxation `s` in `(0, 1]`; 0.5.
    pub relaxation: f64,
    /// Allocator name, interpreted by the controller; `"redistributed-pseudo-inverse"`
    /// (also `"pseudo-inverse"`, `"weighted-pseudo-inverse"` with unit weights, and
    /// `"clarabel"` with the `clarabel` feature).
    pub allocator: String,
    /// Gimbal rate limits `[eta_x, eta_y]` (rad/s) the *controller* respects (rate-constrained
    /// allocation); none by default. Independent of `actuators.servo.rate_limit`, which is the
    /// plant's: give both to model a servo the controller knows about.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub controller_rate_limits: Option<[f64; 2]>,
    /// Physics settings (step, gravity, ground, friction).
    pub physics: PhysicsConfig,
    /// The team.
    pub team: TeamSpec,
    /// Gimbal and thrust limits.
    pub limits: Limits,
    /// Controller gains.
    pub gains: Gains,
    /// Reference trajectory.
    pub reference: ReferenceConfig,
    /// Actuator model (ideal by default).
    pub actuators: ActuatorModel,
    /// Agent failures.
    pub failures: Vec<Failure>,
    /// Disturbances.
    pub disturbances: Disturbances,
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
            relaxation: 0.5,
            allocator: "redistributed-pseudo-inverse".into(),
            controller_rate_limits: None,
            physics: PhysicsConfig::default(),
            team: TeamSpec::default(),
            limits: Limits::default(),
            gains: Gains::default(),
            reference: ReferenceConfig::default(),
            actuators: ActuatorModel::default(),
            failures: Vec::new(),
            disturbances: Disturbances::default(),
        }
    }
}

fn invalid(field: impl Into<String>, reason: impl Into<String>) -> SimError {
    SimError::InvalidScenario {
        field: field.into(),
        reason: reason.into(),
    }
}

fn check_pos(field: &str, v: f64) -> Result<(), SimError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(invalid(field, format!("must be finite and > 0, got {v}")))
    }
}

fn check_nonneg(field: &str, v: &[f64]) -> Result<(), SimError> {
    match v.iter().find(|x| !(x.is_finite() && **x >= 0.0)) {
        None => Ok(()),
        Some(x) => Err(invalid(field, format!("must be finite and >= 0, got {x}"))),
    }
}

fn check_finite(field: &str, v: &[f64]) -> Result<(), SimError> {
    if v.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(invalid(field, "must be finite"))
    }
}

impl Scenario {
    /// Parses and validates a scenario from TOML text.
    pub fn from_toml_str(text: &str) -> Result<Self, SimError> {
        let parse_error = |message: String| SimError::ScenarioParse {
            path: None,
            message,
        };
        let de = toml::Deserializer::parse(text).map_err(|e| parse_error(e.to_string()))?;
        // serde_path_to_error adds the dotted key path (e.g. `physics.dt`) to the message;
        // toml's own message shows the offending line.
        let s: Scenario = serde_path_to_error::deserialize(de).map_err(|e| {
            let path = e.path().to_string();
            let inner = e.into_inner().to_string();
            if path.is_empty() || path == "." {
                parse_error(inner)
            } else {
                parse_error(format!("field `{path}`: {inner}"))
            }
        })?;
        s.validate()?;
        Ok(s)
    }

    /// Reads, parses and validates a scenario file.
    pub fn from_file(path: impl AsRef<Path>) -> Result<Self, SimError> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path)?;
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
    /// Errors: [`SimError::Io`] for a file that cannot be read, [`SimError::ScenarioParse`] /
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

    /// A built-in scenario by name (see [`BUILTIN_NAMES`]).
    pub fn builtin(name: &str) -> Result<Self, SimError> {
        let mut s = Scenario::default();
        let with = |mut s: Scenario, description: &str| {
            s.name = name.to_string();
            s.description = description.to_string();
            s
        };
        Ok(match name {
            "paper-tilt" => s,
            "relaxation-0.25" | "relaxation-0.5" | "relaxation-0.75" | "relaxation-1.0" => {
                s.relaxation = match name {
                    "relaxation-0.25" => 0.25,
                    "relaxation-0.5" => 0.5,
                    "relaxation-0.75" => 0.75,
                    _ => 1.0,
                };
                let d = format!("Relaxation study: paper-tilt with s = {}", s.relaxation);
                with(s, &d)
            }
            "paper-tilt-sigma-y-pi6" => {
                s.limits.sigma_y = PI / 6.0;
                with(
                    s,
                    "paper-tilt with sigma_y = pi/6: the planned roll saturates at exactly pi/12",
                )
            }
            "a4-con" => {
                s.team.preset = Some("a4-con".into());
                with(s, "paper-tilt flown by the consistent team A4-Con")
            }
            "a4-inc" => {
                s.team.preset = Some("a4-inc".into());
                with(
                    s,
                    "paper-tilt flown by the inconsistent team A4-Inc (the paper's)",
                )
            }
            "agent-failure" => {
                s.initial_position = [0.0, 0.0, 0.0];
                s.reference = ReferenceConfig::PaperTilt(PaperTilt {
                    roll_peak: 0.0,
                    ..PaperTilt::default()
                });
                s.failures = vec![Failure {
                    agent: 0,
                    time: 5.0,
                    kind: FailureKind::NoThrust,
                    controller_informed: true,
                }];
                with(
                    s,
                    "A4-Inc ascends and hovers at 1.5 m; agent 0 loses its thrust at t = 5 s \
                     (controller informed); descent at 12 s",
                )
            }
            "a6-agent-failure" => {
                s.initial_position = [0.0, 0.0, 0.0];
                s.reference = ReferenceConfig::PaperTilt(PaperTilt {
                    roll_peak: 0.0,
                    ..PaperTilt::default()
                });
                s.team.agents = Some(TeamBody::ring(6, 0.5, 0.7, true).agents);
                s.failures = vec![Failure {
                    agent: 0,
                    time: 5.0,
                    kind: FailureKind::NoThrust,
                    controller_informed: true,
                }];
                with(
                    s,
                    "A6-Inc ring (radius 0.5 m, alternate quarter turns) ascends and hovers at \
                     1.5 m; agent 0 loses its thrust at t = 5 s (controller informed); descent \
                     at 12 s",
                )
            }
            other => {
                return Err(SimError::UnknownScenario {
                    name: other.to_string(),
                    known: BUILTIN_NAMES.join(", "),
                })
            }
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
    pub fn actuator_limits(&self) -> Result<ActuatorLimits, SimError> {
        Ok(ActuatorLimits {
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

    /// Checks values that parse but make no sense; errors name the field.
    pub fn validate(&self) -> Result<(), SimError> {
        check_pos("duration", self.duration)?;
        check_pos("physics.dt", self.physics.dt)?;
        check_pos("controller_period", self.controller_period)?;
        self.steps_per_control()?;
        check_nonneg("physics.gravity", &[self.physics.gravity])?;
        check_nonneg("physics.friction", &[self.physics.friction])?;
        check_finite("initial_position", &self.initial_position)?;
        if !(self.relaxation > 0.0 && self.relaxation <= 1.0) {
            return Err(invalid(
                "relaxation",
                format!("must be in (0, 1], got {}", self.relaxation),
            ));
        }
        for (f, v) in [
            ("limits.sigma_x", self.limits.sigma_x),
            ("limits.sigma_y", self.limits.sigma_y),
        ] {
            if !(v > 0.0 && v <= PI) {
                return Err(invalid(f, format!("must be in (0, pi], got {v}")));
            }
        }
        if let Some(t) = self.limits.max_thrust {
            check_pos("limits.max_thrust", t)?;
        }
        if !ALLOCATOR_NAMES.contains(&self.allocator.as_str())
            && self.allocator != tvmd_core::allocation::CLARABEL
        {
            return Err(invalid(
                "allocator",
                format!(
                    "unknown allocator `{}` (known: {})",
                    self.allocator,
                    ALLOCATOR_NAMES.join(", ")
                ),
            ));
        }
        if let Some([x, y]) = self.controller_rate_limits {
            check_pos("controller_rate_limits[0]", x)?;
            check_pos("controller_rate_limits[1]", y)?;
        }
        check_nonneg("gains.k_x", &self.gains.k_x)?;
        check_nonneg("gains.k_r", &self.gains.k_r)?;
        check_nonneg("gains.k_xi", &self.gains.k_xi)?;
        let team = self.team_body()?;
        match &self.reference {
            ReferenceConfig::PaperTilt(p) => {
                check_finite("reference.ascent_height", &[p.ascent_height])?;
                check_finite("reference.roll_peak", &[p.roll_peak])?;
                for (f, w) in [
                    ("reference.ascent", p.ascent),
                    ("reference.tilt", p.tilt),
                    ("reference.descent", p.descent),
                ] {
                    check_finite(f, &w)?;
                    if w[1] < w[0] {
                        return Err(invalid(f, "end before start"));
                    }
                }
            }
            ReferenceConfig::Hover { position, roll } => {
                check_finite("reference.position", position)?;
                check_finite("reference.roll", &[*roll])?;
            }
        }
        if let Some(s) = &self.actuators.servo {
            check_pos("actuators.servo.natural_frequency", s.natural_frequency)?;
            check_nonneg("actuators.servo.damping_ratio", &[s.damping_ratio])?;
            check_pos("actuators.servo.rate_limit", s.rate_limit)?;
        }
        if let Some(l) = &self.actuators.rotor_lag {
            check_pos("actuators.rotor_lag.time_constant", l.time_constant)?;
        }
        if let Some(l) = &self.actuators.limits {
            check_pos("actuators.limits.sigma_x", l.sigma_x)?;
            check_pos("actuators.limits.sigma_y", l.sigma_y)?;
            check_pos("actuators.limits.max_thrust", l.max_thrust)?;
        }
        for (i, f) in self.failures.iter().enumerate() {
            if f.agent >= team.len() {
                return Err(invalid(
                    format!("failures[{i}].agent"),
                    format!(
                        "agent {} does not exist (the team has {})",
                        f.agent,
                        team.len()
                    ),
                ));
            }
            check_nonneg(&format!("failures[{i}].time"), &[f.time])?;
        }
        check_finite("disturbances.wind", &self.disturbances.wind)?;
        if let Some(w) = &self.disturbances.external_wrench {
            check_finite("disturbances.external_wrench.force", &w.force)?;
            check_finite("disturbances.external_wrench.torque", &w.torque)?;
            check_finite("disturbances.external_wrench.start", &[w.start])?;
            if let Some(e) = w.end {
                check_finite("disturbances.external_wrench.end", &[e])?;
            }
        }
        if let Some(n) = &self.disturbances.state_noise {
            check_nonneg(
                "disturbances.state_noise",
                &[n.position, n.velocity, n.attitude, n.angular_velocity],
            )?;
        }
        Ok(())
    }
}

/// Fields of a scenario replaced at run time; `None` keeps the scenario's value.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Overrides {
    /// Planner relaxation `s` in `(0, 1]`.
    pub relaxation: Option<f64>,
    /// Allocator name (one of [`crate::scenario::ALLOCATOR_NAMES`]).
    pub allocator: Option<String>,
}

impl Overrides {
    /// True if nothing is overridden.
    pub fn is_empty(&self) -> bool {
        self.relaxation.is_none() && self.allocator.is_none()
    }

    /// Applies the overrides to `scenario` and validates the result; errors name the field.
    pub fn apply(&self, scenario: &mut Scenario) -> Result<(), SimError> {
        if let Some(s) = self.relaxation {
            scenario.relaxation = s;
        }
        if let Some(a) = &self.allocator {
            scenario.allocator.clone_from(a);
        }
        scenario.validate()
    }
}

impl Scenario {
    /// This scenario with `overrides` applied, validated.
    pub fn with_overrides(mut self, overrides: &Overrides) -> Result<Self, SimError> {
        overrides.apply(&mut self)?;
        Ok(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn builtins_validate_and_round_trip() {
        for name in BUILTIN_NAMES {
            let s = Scenario::builtin(name).unwrap();
            s.validate().unwrap();
            assert_eq!(&s.name, name);
            let text = s.to_toml_string().unwrap();
            let back = Scenario::from_toml_str(&text).unwrap();
            assert_eq!(back, s, "round trip of {name}:\n{text}");
        }
        assert!(matches!(
            Scenario::builtin("nope"),
            Err(SimError::UnknownScenario { .. })
        ));
    }

    #[test]
    fn empty_file_is_paper_tilt() {
        let s = Scenario::from_toml_str("").unwrap();
        assert_eq!(s, Scenario::default());
        assert_eq!(s.steps_per_control().unwrap(), 10);
        assert!((s.max_thrust().unwrap() - 2.0 * 0.7 * 9.81).abs() < 1e-12);
    }

    #[test]
    fn wrong_type_names_the_field() {
        let e = Scenario::from_toml_str("relaxation = \"half\"\n").unwrap_err();
        let msg = e.to_string();
        assert!(msg.contains("relaxation"), "{msg}");
        let e = Scenario::from_toml_str("[gains]\nk_x = [1.0, 2.0]\n").unwrap_err();
        assert!(e.to_string().contains("k_x"), "{e}");
        let e =
            Scenario::from_toml_str("[[failures]]\nagent = 0\ntime = 1.0\nkind = \"explode\"\n")
                .unwrap_err();
        assert!(e.to_string().contains("kind"), "{e}");
    }

    #[test]
    fn unknown_key_is_rejected_by_name() {
        let e = Scenario::from_toml_str("relaxaton = 0.5\n").unwrap_err();
        assert!(e.to_string().contains("relaxaton"), "{e}");
        let e = Scenario::from_toml_str("[physics]\nstep = 0.001\n").unwrap_err();
        assert!(e.to_string().contains("step"), "{e}");
        let e = Scenario::from_toml_str("[physics]\ndt = \"x\"\n").unwrap_err();
        assert!(e.to_string().contains("physics.dt"), "{e}");
    }

    #[test]
    fn bad_values_name_the_field() {
        let e = Scenario::from_toml_str("relaxation = 1.5\n").unwrap_err();
        assert!(
            matches!(&e, SimError::InvalidScenario { field, .. } if field == "relaxation"),
            "{e}"
        );
        let e = Scenario::from_toml_str("controller_period = 0.0125\n").unwrap_err();
        assert!(e.to_string().contains("controller_period"), "{e}");
        let e =
            Scenario::from_toml_str("[[failures]]\nagent = 7\ntime = 1.0\nkind = \"no-thrust\"\n")
                .unwrap_err();
        assert!(e.to_string().contains("failures[0].agent"), "{e}");
    }

    #[test]
    fn full_example_parses() {
        let text = r#"
name = "custom"
duration = 3.0
controller_period = 0.005
relaxation = 1.0
[physics]
dt = 0.0005
[team]
agents = [
  { position = [0.3, 0.0, 0.0], mass = 0.5, quarter_turns = 0 },
  { position = [-0.3, 0.0, 0.0], mass = 0.5, quarter_turns = 3 },
]
navigator_mass = 0.2
[limits]
max_thrust = 12.0
[reference]
kind = "hover"
position = [0.0, 0.0, 1.0]
[actuators]
servo = { natural_frequency = 40.0, damping_ratio = 0.8, rate_limit = 6.0 }
rotor_lag = { time_constant = 0.03 }
[[failures]]
agent = 1
time = 2.0
kind = "stuck-gimbal"
controller_informed = false
[disturbances]
wind = [0.5, 0.0, 0.0]
external_wrench = { torque = [0.0, 0.0, 0.1], start = 1.0, end = 2.0 }
state_noise = { position = 0.01, seed = 7 }
"#;
        let s = Scenario::from_toml_str(text).unwrap();
        assert_eq!(s.steps_per_control().unwrap(), 10);
        assert_eq!(s.team_body().unwrap().len(), 2);
        assert_eq!(s.failures[0].kind, FailureKind::StuckGimbal);
        assert!(!s.failures[0].controller_informed);
        assert_eq!(s.disturbances.state_noise.unwrap().seed, 7);
        assert_eq!(s.max_thrust().unwrap(), 12.0);
        assert!(matches!(s.reference, ReferenceConfig::Hover { .. }));
    }

    #[test]
    fn overrides_replace_and_validate() {
        let o = Overrides {
            relaxation: Some(1.0),
            allocator: Some("pseudo-inverse".into()),
        };
        let s = Scenario::default().with_overrides(&o).unwrap();
        assert_eq!(s.relaxation, 1.0);
        assert_eq!(s.allocator, "pseudo-inverse");
        assert_eq!(
            Scenario::default()
                .with_overrides(&Overrides::default())
                .unwrap(),
            Scenario::default()
        );
        let bad = Overrides {
            relaxation: Some(1.5),
            ..Overrides::default()
        };
        let e = Scenario::default().with_overrides(&bad).unwrap_err();
        assert!(
            matches!(&e, SimError::InvalidScenario { field, .. } if field == "relaxation"),
            "{e}"
        );
        let bad = Overrides {
            allocator: Some("magic".into()),
            ..Overrides::default()
        };
        let e = Scenario::default().with_overrides(&bad).unwrap_err();
        assert!(
            matches!(&e, SimError::InvalidScenario { field, .. } if field == "allocator"),
            "{e}"
        );
    }

    #[test]
    fn load_takes_a_builtin_name_or_a_file() {
        assert_eq!(
            Scenario::load("a4-con").unwrap(),
            Scenario::builtin("a4-con").unwrap()
        );
        assert!(matches!(
            Scenario::load("nope"),
            Err(SimError::UnknownScenario { .. })
        ));
        assert!(matches!(
            Scenario::load("missing-file.toml"),
            Err(SimError::Io(_))
        ));
        let dir = std::env::temp_dir().join(format!("tvmd-sim-load-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        // A file without the .toml suffix is still a file.
        let path = dir.join("scenario");
        std::fs::write(&path, "name = \"from-file\"\nrelaxation = 1.0\n").unwrap();
        let s = Scenario::load(path.to_str().unwrap()).unwrap();
        assert_eq!((s.name.as_str(), s.relaxation), ("from-file", 1.0));
        std::fs::write(&path, "[physics]\ndt = -1.0\n").unwrap();
        let e = Scenario::load(path.to_str().unwrap()).unwrap_err();
        assert!(
            e.to_string()
                .contains("invalid scenario field `physics.dt`"),
            "{e}"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
