//! The scenario document: every part, its defaults, loading and validation.

use std::path::Path;

use serde::{Deserialize, Serialize};
use tvmd_core::RoundCap;
use tvmd_plant::actuators::{ActuatorModel, SaturationLimits};
use tvmd_plant::{PhysicsConfig, ReferenceConfig, TeamBody, GRAVITY};

use crate::error::invalid;
use crate::{
    AgentReports, CommandLinks, Disturbances, Failure, FailureResponse, FaultDetectionConfig,
    GainsConfig, LawConfig, LimitsConfig, LogSettings, NullSpaceConfig, Payload, PlantError,
    Precision, ScenarioError, SuccessBounds, TeamSpec,
};

/// The largest scenario file read (1 MiB; the built-ins are under 3 KiB).
pub const MAX_SCENARIO_BYTES: u64 = 1 << 20;

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
    /// ground (the ground lies at `z = -rest height`, see `tvmd_plant::physics`).
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
    /// Round cap of the exact-boundary redistribution's walk per control period
    /// (`ExactBoundaryRedistribution::with_round_cap`: the best forces found so far, inside
    /// `E_f`, with their true `e_f`), the flight option that bounds its worst case
    /// (`docs/allocation-benchmark.md`): a number of rounds, or `"uncapped"` for the walk's own
    /// `2 n + 4`; absent, the core's default of [`tvmd_core::allocation::DEFAULT_MAX_ROUNDS`]
    /// rounds (the paper's scenarios name `"uncapped"`, the walk they were first flown with).
    /// Refused with any other allocator.
    #[serde(
        default,
        with = "crate::controller::round_cap",
        skip_serializing_if = "Option::is_none"
    )]
    pub allocator_max_rounds: Option<RoundCap>,
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
    /// Controller gains (used as `law.gains` says: as given by `"paper"`, scaled by
    /// `"team-scaled"`, not at all by natural gains).
    pub gains: GainsConfig,
    /// The control law's settings beyond the paper (`[law]`, [`LawConfig`]): natural gains,
    /// the disturbance observer and the planned rates by default; `law = "paper"` for the
    /// paper's law, bit for bit.
    pub law: LawConfig,
    /// Reference trajectory.
    pub reference: ReferenceConfig,
    /// Actuator model (ideal by default).
    pub actuators: ActuatorModel,
    /// Agent failures.
    pub failures: Vec<Failure>,
    /// What to do when a failure leaves a team that cannot hold hover.
    pub failure_response: FailureResponse,
    /// Agent fault detection in the controller (`[fault_detection]`,
    /// [`FaultDetectionConfig`]); none by default.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fault_detection: Option<FaultDetectionConfig>,
    /// Disturbances.
    pub disturbances: Disturbances,
    /// Each agent's command link (`[links]`, [`CommandLinks`]); none by default: commands are
    /// applied as they are sent.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub links: Option<CommandLinks>,
    /// The agents' own reports (`[reports]`, [`AgentReports`]); none by default.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reports: Option<AgentReports>,
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
            description: "The paper's manoeuvre (A4-Inc, ascent, roll tilt to an infeasible pi/3, \
                          descent; s = 0.5) flown with the offset-free law"
                .into(),
            duration: 16.0,
            controller_period: 0.01,
            initial_position: [0.5, -0.5, 0.0],
            initial_attitude: [0.0; 3],
            relaxation: 0.5,
            allocator: tvmd_core::AnyAllocator::<f64, 1>::DEFAULT_NAME.into(),
            allocator_max_rounds: None,
            controller_rate_limits: None,
            null_space: None,
            controller_precision: Precision::F64,
            physics: PhysicsConfig::default(),
            team: TeamSpec::default(),
            limits: LimitsConfig::default(),
            gains: GainsConfig::default(),
            law: LawConfig::default(),
            reference: ReferenceConfig::default(),
            actuators: ActuatorModel::default(),
            failures: Vec::new(),
            failure_response: FailureResponse::default(),
            fault_detection: None,
            disturbances: Disturbances::default(),
            links: None,
            reports: None,
            plant: PlantError::nominal(),
            payloads: Vec::new(),
            log: LogSettings::default(),
            success: SuccessBounds::default(),
        }
    }
}

impl Scenario {
    /// Parses and validates a scenario from TOML text.
    pub fn from_toml_str(text: &str) -> Result<Self, ScenarioError> {
        let parse_error = |message: String| ScenarioError::ScenarioParse {
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
    /// [`MAX_SCENARIO_BYTES`], so that a device or FIFO is refused before it is opened. A file
    /// without `name` takes its file name without the extension (`mine.toml` runs as `mine`).
    /// Errors: [`ScenarioError::File`] naming the path (missing, unreadable, not a regular file, too
    /// large, not UTF-8), then as [`Scenario::from_toml_str`].
    pub fn from_file(path: impl AsRef<Path>) -> Result<Self, ScenarioError> {
        use std::io::Read;
        const ACTION: &str = "read the scenario file";
        let path = path.as_ref();
        let refuse = |reason: String| ScenarioError::File {
            action: ACTION,
            path: path.to_path_buf(),
            source: std::io::Error::new(std::io::ErrorKind::InvalidInput, reason),
        };
        let meta = std::fs::metadata(path).map_err(ScenarioError::file(ACTION, path))?;
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
            .map_err(ScenarioError::file(ACTION, path))?;
        if text.len() as u64 > MAX_SCENARIO_BYTES {
            return Err(refuse(format!(
                "grew beyond {MAX_SCENARIO_BYTES} bytes while read"
            )));
        }
        let mut scenario = Self::from_toml_str(&text).map_err(|e| match e {
            ScenarioError::ScenarioParse { message, .. } => ScenarioError::ScenarioParse {
                path: Some(path.display().to_string()),
                message,
            },
            other => other,
        })?;
        // A file that names no scenario is its own run, not the default's (whose log and
        // summary it would replace): it takes the file's name.
        let named = text
            .parse::<toml::Table>()
            .is_ok_and(|t| t.contains_key("name"));
        if let (false, Some(stem)) = (named, path.file_stem()) {
            scenario.name = stem.to_string_lossy().into_owned();
        }
        Ok(scenario)
    }

    /// The scenario named by a command-line or Python argument: a TOML file if `name_or_path`
    /// ends in `.toml` or names an existing file, else a built-in (see [`crate::BUILTIN_NAMES`]).
    /// Errors: [`ScenarioError::File`] for a file that cannot be read, [`ScenarioError::ScenarioParse`] /
    /// [`ScenarioError::InvalidScenario`] naming the field, [`ScenarioError::UnknownScenario`].
    pub fn load(name_or_path: &str) -> Result<Self, ScenarioError> {
        let path = Path::new(name_or_path);
        if name_or_path.ends_with(".toml") || path.is_file() {
            Self::from_file(path)
        } else {
            Self::builtin(name_or_path)
        }
    }

    /// Serialises the scenario as TOML (the format [`Scenario::from_toml_str`] reads).
    pub fn to_toml_string(&self) -> Result<String, ScenarioError> {
        toml::to_string(self).map_err(|e| ScenarioError::ScenarioParse {
            path: None,
            message: e.to_string(),
        })
    }

    /// The team body of this scenario.
    pub fn team_body(&self) -> Result<TeamBody, ScenarioError> {
        self.team.team_body()
    }

    /// `sigma_Tf`: the configured maximum thrust, or `2 m_i g` of the heaviest agent.
    pub fn max_thrust(&self) -> Result<f64, ScenarioError> {
        if let Some(t) = self.limits.max_thrust {
            return Ok(t);
        }
        let team = self.team_body()?;
        let m = team.agents.iter().map(|a| a.mass).fold(0.0, f64::max);
        Ok(2.0 * m * GRAVITY)
    }

    /// The actuator limits of this scenario (for an actuator model that saturates).
    pub fn actuator_limits(&self) -> Result<SaturationLimits, ScenarioError> {
        Ok(SaturationLimits {
            sigma_x: self.limits.sigma_x,
            sigma_y: self.limits.sigma_y,
            max_thrust: self.max_thrust()?,
        })
    }

    /// Number of physics steps per controller period.
    pub fn steps_per_control(&self) -> Result<usize, ScenarioError> {
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
