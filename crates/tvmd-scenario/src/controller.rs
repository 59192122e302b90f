//! The controller's part of a scenario: its precision, gains and allocator names.

use serde::{Deserialize, Serialize};

use crate::error::invalid;
use crate::ScenarioError;

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
    type Err = ScenarioError;

    /// Parses `"f64"` or `"f32"`; anything else is an invalid `controller_precision`.
    fn from_str(s: &str) -> Result<Self, ScenarioError> {
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

/// The word of `tvmd_core::RoundCap::Uncapped` in a scenario file's `allocator_max_rounds` and
/// in Python's `max_rounds=`.
pub const ROUND_CAP_UNCAPPED: &str = "uncapped";

/// `allocator_max_rounds` in a scenario file: a number of rounds (`0`: the walk's start alone)
/// or [`ROUND_CAP_UNCAPPED`]; absent, the core's default cap
/// ([`tvmd_core::allocation::DEFAULT_MAX_ROUNDS`]).
pub(crate) mod round_cap {
    use serde::{Deserialize, Deserializer, Serialize, Serializer};
    use tvmd_core::RoundCap;

    use super::ROUND_CAP_UNCAPPED as UNCAPPED;

    #[derive(Serialize, Deserialize)]
    #[serde(untagged)]
    enum Input {
        Rounds(u32),
        Word(String),
    }

    /// Writes `Some(cap)` as a number or `"uncapped"` (`None`, the default, is skipped by the
    /// field).
    pub fn serialize<S: Serializer>(cap: &Option<RoundCap>, s: S) -> Result<S::Ok, S::Error> {
        match cap {
            Some(RoundCap::Rounds(k)) => Input::Rounds(*k).serialize(s),
            Some(RoundCap::Uncapped) => Input::Word(UNCAPPED.into()).serialize(s),
            None => s.serialize_none(),
        }
    }

    /// Reads a number of rounds or `"uncapped"`.
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Option<RoundCap>, D::Error> {
        match Input::deserialize(d)? {
            Input::Rounds(k) => Ok(Some(RoundCap::Rounds(k))),
            Input::Word(w) if w == UNCAPPED => Ok(Some(RoundCap::Uncapped)),
            Input::Word(w) => Err(serde::de::Error::custom(format!(
                "expected a number of rounds (0 or more) or \"{UNCAPPED}\", got \"{w}\""
            ))),
        }
    }
}
