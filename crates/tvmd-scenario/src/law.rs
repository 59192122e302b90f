//! The control law's settings beyond the paper (`[law]`, `docs/method.md`, "Beyond the paper"):
//! how the gains fit the team, the offset-free action and the planned attitude's rates.
//!
//! A scenario that names no `[law]` flies [`LawConfig::default`], the law that flies: natural
//! gains, the disturbance observer and the planned rates. The paper's scenarios name
//! [`LawConfig::paper`] (`law = "paper"`), which is the paper's cycle bit for bit.
//!
//! ```toml
//! law = "paper"                 # or "offset-free" (the default); or a table:
//!
//! [law]
//! gains = "paper"               # the [gains] table as given; "team-scaled"; or natural gains:
//! # gains = { natural = { position_frequency = [1.5, 1.5, 1.5], position_damping = [1.0, 1.0, 1.0],
//! #                       attitude_frequency = [6.0, 6.0, 6.0], attitude_damping = [0.6, 0.6, 0.6] } }
//! offset_free = { kind = "observer", force_bandwidth = 10.0, torque_bandwidth = 10.0, max_torque = 5.0 }
//! # offset_free = { kind = "integral", k_x = [1.0, 1.0, 1.0], k_r = [0.5, 0.5, 0.5], max_torque = 5.0 }
//! # offset_free = "off"
//! attitude_rate = { bandwidth = 20.0, max_rate = 5.0 }   # or "off"
//! ```

use serde::{Deserialize, Serialize};

use crate::checks::check_pos;
use crate::name_or::NameOr;
use crate::ScenarioError;

/// The names `law` may hold as a string: `"paper"` ([`LawConfig::paper`]) and `"offset-free"`
/// ([`LawConfig::default`]).
pub const LAW_NAMES: &[&str] = &["paper", "offset-free"];

/// The defaults of `"offset-free"`, defined once in the core
/// (`tvmd_core::ControllerSettings::offset_free_law`).
pub use tvmd_core::controller::{
    ATTITUDE_DAMPING, ATTITUDE_FREQUENCY, ATTITUDE_RATE_BANDWIDTH, ATTITUDE_RATE_MAX,
    DAMPING_RATIO, OBSERVER_BANDWIDTH, OFFSET_FREE_MAX_TORQUE, POSITION_FREQUENCY,
};

/// The control law's settings: gains, offset-free action, planned rates. In TOML a table, or
/// one of the names [`LAW_NAMES`].
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "LawInput")]
pub struct LawConfig {
    /// How the gains of eq. (12) are made ([`GainScheduleConfig`]).
    pub gains: GainScheduleConfig,
    /// The offset-free action ([`OffsetFreeConfig`]).
    pub offset_free: OffsetFreeConfig,
    /// The planned attitude's rates ([`AttitudeRateConfig`]).
    pub attitude_rate: AttitudeRateConfig,
}

impl Default for LawConfig {
    /// The law that flies (`"offset-free"`): natural gains ([`NaturalGainsConfig::default`]),
    /// the disturbance observer ([`OffsetFreeConfig::observer`]) and the planned rates
    /// ([`AttitudeRateConfig::filter`]).
    fn default() -> Self {
        Self {
            gains: GainScheduleConfig::Natural(NaturalGainsConfig::default()),
            offset_free: OffsetFreeConfig::observer(),
            attitude_rate: AttitudeRateConfig::filter(),
        }
    }
}

impl LawConfig {
    /// The paper's law (`"paper"`): the `[gains]` as given, no offset-free action, the
    /// reference's attitude rates. Bit for bit the paper's cycle.
    pub fn paper() -> Self {
        Self {
            gains: GainScheduleConfig::Paper,
            offset_free: OffsetFreeConfig::Off,
            attitude_rate: AttitudeRateConfig::Off,
        }
    }

    /// Whether this is [`LawConfig::paper`].
    pub fn is_paper(&self) -> bool {
        *self == Self::paper()
    }

    /// The law named `name` (one of [`LAW_NAMES`]).
    pub fn named(name: &str) -> Result<Self, String> {
        match name {
            "paper" => Ok(Self::paper()),
            "offset-free" => Ok(Self::default()),
            other => Err(format!(
                "unknown law `{other}` (known: {}, or a table)",
                LAW_NAMES.join(", ")
            )),
        }
    }

    /// The name of this law: `"paper"`, `"offset-free"` (the default) or `"custom"` (any other
    /// table).
    pub fn name(&self) -> &'static str {
        if self.is_paper() {
            "paper"
        } else if *self == Self::default() {
            "offset-free"
        } else {
            "custom"
        }
    }

    /// Range checks, each error naming the field (`law.gains.natural.position_frequency[1]`).
    pub fn validate(&self) -> Result<(), ScenarioError> {
        if let GainScheduleConfig::Natural(n) = &self.gains {
            for (name, values) in [
                ("position_frequency", n.position_frequency),
                ("position_damping", n.position_damping),
                ("attitude_frequency", n.attitude_frequency),
                ("attitude_damping", n.attitude_damping),
            ] {
                for (i, v) in values.iter().enumerate() {
                    check_pos(&format!("law.gains.natural.{name}[{i}]"), *v)?;
                }
            }
        }
        match self.offset_free {
            OffsetFreeConfig::Off => {}
            OffsetFreeConfig::Observer {
                force_bandwidth,
                torque_bandwidth,
                max_torque,
            } => {
                check_pos("law.offset_free.force_bandwidth", force_bandwidth)?;
                check_pos("law.offset_free.torque_bandwidth", torque_bandwidth)?;
                check_pos("law.offset_free.max_torque", max_torque)?;
            }
            OffsetFreeConfig::Integral {
                k_x,
                k_r,
                max_torque,
            } => {
                for (name, values) in [("k_x", k_x), ("k_r", k_r)] {
                    for (i, v) in values.iter().enumerate() {
                        check_pos(&format!("law.offset_free.{name}[{i}]"), *v)?;
                    }
                }
                check_pos("law.offset_free.max_torque", max_torque)?;
            }
        }
        if let AttitudeRateConfig::Filter {
            bandwidth,
            max_rate,
        } = self.attitude_rate
        {
            check_pos("law.attitude_rate.bandwidth", bandwidth)?;
            check_pos("law.attitude_rate.max_rate", max_rate)?;
        }
        Ok(())
    }
}

/// How the gains of eq. (12) are made for the team (`tvmd_core::GainSchedule`). In TOML
/// `"paper"`, `"team-scaled"` or `{ natural = { .. } }`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum GainScheduleConfig {
    /// The scenario's `[gains]` as given (the paper's reading).
    Paper,
    /// The `[gains]` multiplied by the team's mass and inertia (the authors' MATLAB).
    TeamScaled,
    /// Gains from closed-loop natural frequencies and damping ratios; `[gains]` is not used.
    Natural(NaturalGainsConfig),
}

/// Natural frequencies (rad/s) and damping ratios per axis (`tvmd_core::NaturalGains`):
/// position `x, y, z` in `{I}`, attitude roll, pitch, yaw in `{C}`; each finite and `> 0`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct NaturalGainsConfig {
    /// Position frequencies; 1.5 rad/s.
    pub position_frequency: [f64; 3],
    /// Position damping ratios; 1.
    pub position_damping: [f64; 3],
    /// Attitude frequencies; 6 rad/s.
    pub attitude_frequency: [f64; 3],
    /// Attitude damping ratios; 0.6 (1 until issue 61).
    pub attitude_damping: [f64; 3],
}

impl Default for NaturalGainsConfig {
    fn default() -> Self {
        Self {
            position_frequency: [POSITION_FREQUENCY; 3],
            position_damping: [DAMPING_RATIO; 3],
            attitude_frequency: [ATTITUDE_FREQUENCY; 3],
            attitude_damping: [ATTITUDE_DAMPING; 3],
        }
    }
}

/// The offset-free action (`tvmd_core::OffsetFree`). In TOML `"off"` or a table with `kind`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "OffsetFreeInput", into = "OffsetFreeInput")]
pub enum OffsetFreeConfig {
    /// None: the paper's law.
    Off,
    /// The disturbance observer (`kind = "observer"`).
    Observer {
        /// `L_f` (rad/s); 10.
        force_bandwidth: f64,
        /// `L_tau` (rad/s); 10.
        torque_bandwidth: f64,
        /// Bound of the torque estimate (N m); 5.
        max_torque: f64,
    },
    /// Integral action on `e_x`, `e_R` (`kind = "integral"`), gains in N/(m s) and
    /// N m/(rad s), not scaled by the team.
    Integral {
        /// `K_Ix` per axis; required.
        k_x: [f64; 3],
        /// `K_IR` per axis; required.
        k_r: [f64; 3],
        /// Bound of the torque term (N m); 5.
        max_torque: f64,
    },
}

impl OffsetFreeConfig {
    /// The observer with the default bandwidths and torque bound.
    pub fn observer() -> Self {
        Self::Observer {
            force_bandwidth: OBSERVER_BANDWIDTH,
            torque_bandwidth: OBSERVER_BANDWIDTH,
            max_torque: OFFSET_FREE_MAX_TORQUE,
        }
    }
}

/// The planned-rate filter (`tvmd_core::AttitudeRateFilter`). In TOML `"off"` or
/// `{ bandwidth, max_rate }`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "AttitudeRateInput", into = "AttitudeRateInput")]
pub enum AttitudeRateConfig {
    /// The reference's `Omega_d`, `Omega_d_dot` (the paper).
    Off,
    /// The planned attitude's rates.
    Filter {
        /// Bandwidth `w` (rad/s); 20.
        bandwidth: f64,
        /// Rate bound (rad/s); 5.
        max_rate: f64,
    },
}

impl AttitudeRateConfig {
    /// The filter with the default bandwidth and rate bound.
    pub fn filter() -> Self {
        Self::Filter {
            bandwidth: ATTITUDE_RATE_BANDWIDTH,
            max_rate: ATTITUDE_RATE_MAX,
        }
    }
}

impl std::str::FromStr for LawConfig {
    type Err = String;

    /// One of [`LAW_NAMES`] (the command line's `--law`).
    fn from_str(s: &str) -> Result<Self, String> {
        Self::named(s.trim())
    }
}

// What TOML may hold. Tables are read with every field optional, so that a missing or
// misplaced field is named in the error.

type LawInput = NameOr<LawTable>;
type OffsetFreeInput = NameOr<OffsetFreeTable>;
type AttitudeRateInput = NameOr<AttitudeRateTable>;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct LawTable {
    gains: Option<GainScheduleConfig>,
    offset_free: Option<OffsetFreeConfig>,
    attitude_rate: Option<AttitudeRateConfig>,
}

impl TryFrom<LawInput> for LawConfig {
    type Error = String;

    fn try_from(input: LawInput) -> Result<Self, String> {
        match input {
            NameOr::Name(name) => Self::named(&name),
            NameOr::Table(t) => {
                let d = Self::default();
                Ok(Self {
                    gains: t.gains.unwrap_or(d.gains),
                    offset_free: t.offset_free.unwrap_or(d.offset_free),
                    attitude_rate: t.attitude_rate.unwrap_or(d.attitude_rate),
                })
            }
        }
    }
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct OffsetFreeTable {
    kind: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    force_bandwidth: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    torque_bandwidth: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    k_x: Option<[f64; 3]>,
    #[serde(skip_serializing_if = "Option::is_none")]
    k_r: Option<[f64; 3]>,
    #[serde(skip_serializing_if = "Option::is_none")]
    max_torque: Option<f64>,
}

const OFFSET_FREE_KINDS: &str = "off, observer, integral";

impl TryFrom<OffsetFreeInput> for OffsetFreeConfig {
    type Error = String;

    fn try_from(input: OffsetFreeInput) -> Result<Self, String> {
        let t = match input {
            NameOr::Name(w) if w == "off" => return Ok(Self::Off),
            NameOr::Name(w) => {
                return Err(format!(
                    "unknown offset-free action `{w}` (known: \"off\" or a table with kind = \
                     \"observer\" or \"integral\")"
                ))
            }
            NameOr::Table(t) => t,
        };
        let not_for = |field: &str, present: bool| {
            if present {
                Err(format!(
                    "`{field}` is not a setting of kind = \"{}\"",
                    t.kind
                ))
            } else {
                Ok(())
            }
        };
        let max_torque = t.max_torque.unwrap_or(OFFSET_FREE_MAX_TORQUE);
        match t.kind.as_str() {
            "off" => {
                not_for("force_bandwidth", t.force_bandwidth.is_some())?;
                not_for("torque_bandwidth", t.torque_bandwidth.is_some())?;
                not_for("k_x", t.k_x.is_some())?;
                not_for("k_r", t.k_r.is_some())?;
                not_for("max_torque", t.max_torque.is_some())?;
                Ok(Self::Off)
            }
            "observer" => {
                not_for("k_x", t.k_x.is_some())?;
                not_for("k_r", t.k_r.is_some())?;
                Ok(Self::Observer {
                    force_bandwidth: t.force_bandwidth.unwrap_or(OBSERVER_BANDWIDTH),
                    torque_bandwidth: t.torque_bandwidth.unwrap_or(OBSERVER_BANDWIDTH),
                    max_torque,
                })
            }
            "integral" => {
                not_for("force_bandwidth", t.force_bandwidth.is_some())?;
                not_for("torque_bandwidth", t.torque_bandwidth.is_some())?;
                let need = |field: &str, v: Option<[f64; 3]>| {
                    v.ok_or_else(|| format!("kind = \"integral\" needs `{field}` (3 gains)"))
                };
                Ok(Self::Integral {
                    k_x: need("k_x", t.k_x)?,
                    k_r: need("k_r", t.k_r)?,
                    max_torque,
                })
            }
            other => Err(format!(
                "unknown offset-free kind `{other}` (known: {OFFSET_FREE_KINDS})"
            )),
        }
    }
}

impl From<OffsetFreeConfig> for OffsetFreeInput {
    fn from(c: OffsetFreeConfig) -> Self {
        let table = |kind: &str| OffsetFreeTable {
            kind: kind.into(),
            force_bandwidth: None,
            torque_bandwidth: None,
            k_x: None,
            k_r: None,
            max_torque: None,
        };
        match c {
            OffsetFreeConfig::Off => NameOr::Name("off".into()),
            OffsetFreeConfig::Observer {
                force_bandwidth,
                torque_bandwidth,
                max_torque,
            } => NameOr::Table(OffsetFreeTable {
                force_bandwidth: Some(force_bandwidth),
                torque_bandwidth: Some(torque_bandwidth),
                max_torque: Some(max_torque),
                ..table("observer")
            }),
            OffsetFreeConfig::Integral {
                k_x,
                k_r,
                max_torque,
            } => NameOr::Table(OffsetFreeTable {
                k_x: Some(k_x),
                k_r: Some(k_r),
                max_torque: Some(max_torque),
                ..table("integral")
            }),
        }
    }
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct AttitudeRateTable {
    bandwidth: Option<f64>,
    max_rate: Option<f64>,
}

impl TryFrom<AttitudeRateInput> for AttitudeRateConfig {
    type Error = String;

    fn try_from(input: AttitudeRateInput) -> Result<Self, String> {
        match input {
            NameOr::Name(w) if w == "off" => Ok(Self::Off),
            NameOr::Name(w) => Err(format!(
                "unknown attitude-rate setting `{w}` (known: \"off\" or a table with \
                 bandwidth and max_rate)"
            )),
            NameOr::Table(t) => Ok(Self::Filter {
                bandwidth: t.bandwidth.unwrap_or(ATTITUDE_RATE_BANDWIDTH),
                max_rate: t.max_rate.unwrap_or(ATTITUDE_RATE_MAX),
            }),
        }
    }
}

impl From<AttitudeRateConfig> for AttitudeRateInput {
    fn from(c: AttitudeRateConfig) -> Self {
        match c {
            AttitudeRateConfig::Off => NameOr::Name("off".into()),
            AttitudeRateConfig::Filter {
                bandwidth,
                max_rate,
            } => NameOr::Table(AttitudeRateTable {
                bandwidth: Some(bandwidth),
                max_rate: Some(max_rate),
            }),
        }
    }
}
