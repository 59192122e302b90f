//! The scenario's optional null-space stage (`null_space`, `docs/method.md`, "Null-space
//! stage"): after the allocator, forces move inside `null(M)` toward an objective.
//!
//! ```toml
//! null_space = "margin"                                   # or "inward-tilt=0.1" (rad)
//! # null_space = { objective = "inward-tilt", tilt = 0.1, iterations = 8 }
//! ```

use std::fmt;
use std::str::FromStr;

use serde::{Deserialize, Serialize};
use tvmd_core::{NullSpaceObjective, NullSpaceStage, Real};

use crate::error::invalid;
use crate::name_or::NameOr;
use crate::ScenarioError;

/// Default iteration cap of the stage.
pub const DEFAULT_NULL_SPACE_ITERATIONS: u32 = 8;

/// The objective names: `"margin"`, `"inward-tilt"`.
pub const NULL_SPACE_OBJECTIVES: &[&str] = &["margin", "inward-tilt"];

/// Which objective the stage ascends.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum NullSpaceKind {
    /// Margin to every agent's admissible boundary ([`NullSpaceObjective::Margin`]).
    Margin,
    /// Thrust tilted toward the team's centre by `tilt` rad ([`NullSpaceObjective::InwardTilt`]).
    InwardTilt,
}

/// The stage's settings: objective, tilt (rad; only and always for `inward-tilt`) and
/// iteration cap (`1..=64`, default 8). In TOML a table, or the string form of [`FromStr`].
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, try_from = "NullSpaceInput")]
pub struct NullSpaceConfig {
    /// The objective.
    pub objective: NullSpaceKind,
    /// Inward tilt (rad), `|tilt| < pi/2`; `inward-tilt` only.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tilt: Option<f64>,
    /// Iteration cap.
    pub iterations: u32,
}

/// What TOML may hold: the string form or a table.
type NullSpaceInput = NameOr<NullSpaceTable>;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct NullSpaceTable {
    objective: String,
    tilt: Option<f64>,
    iterations: Option<u32>,
}

impl TryFrom<NullSpaceInput> for NullSpaceConfig {
    type Error = String;

    fn try_from(input: NullSpaceInput) -> Result<Self, String> {
        match input {
            NameOr::Name(s) => s.parse(),
            NameOr::Table(t) => Ok(Self {
                objective: kind(&t.objective)?,
                tilt: t.tilt,
                iterations: t.iterations.unwrap_or(DEFAULT_NULL_SPACE_ITERATIONS),
            }),
        }
    }
}

fn kind(name: &str) -> Result<NullSpaceKind, String> {
    match name {
        "margin" => Ok(NullSpaceKind::Margin),
        "inward-tilt" => Ok(NullSpaceKind::InwardTilt),
        other => Err(format!(
            "unknown null-space objective `{other}` (known: {})",
            NULL_SPACE_OBJECTIVES.join(", ")
        )),
    }
}

impl FromStr for NullSpaceConfig {
    type Err = String;

    /// `"margin"` or `"inward-tilt=<rad>"`, with the default iteration cap.
    fn from_str(s: &str) -> Result<Self, String> {
        let (name, tilt) = match s.split_once('=') {
            Some((name, angle)) => {
                let angle: f64 = angle
                    .trim()
                    .parse()
                    .map_err(|_| format!("tilt `{angle}` is not a number (rad)"))?;
                (name.trim(), Some(angle))
            }
            None => (s.trim(), None),
        };
        Ok(Self {
            objective: kind(name)?,
            tilt,
            iterations: DEFAULT_NULL_SPACE_ITERATIONS,
        })
    }
}

impl fmt::Display for NullSpaceConfig {
    /// The string form (`margin`, `inward-tilt=0.1`), plus `/<iterations>` when not the default.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match (self.objective, self.tilt) {
            (NullSpaceKind::InwardTilt, Some(t)) => write!(f, "inward-tilt={t}")?,
            (NullSpaceKind::InwardTilt, None) => f.write_str("inward-tilt")?,
            (NullSpaceKind::Margin, _) => f.write_str("margin")?,
        }
        if self.iterations != DEFAULT_NULL_SPACE_ITERATIONS {
            write!(f, "/{}", self.iterations)?;
        }
        Ok(())
    }
}

impl NullSpaceConfig {
    /// Checks the settings; errors name `null_space.*`.
    pub fn validate(&self) -> Result<(), ScenarioError> {
        self.stage::<f64>().map(|_| ())
    }

    /// The core's stage in `T`.
    pub fn stage<T: Real>(&self) -> Result<NullSpaceStage<T>, ScenarioError> {
        let objective = match (self.objective, self.tilt) {
            (NullSpaceKind::Margin, None) => NullSpaceObjective::Margin,
            (NullSpaceKind::Margin, Some(_)) => {
                return Err(invalid(
                    "null_space.tilt",
                    "only the `inward-tilt` objective takes a tilt",
                ))
            }
            (NullSpaceKind::InwardTilt, None) => {
                return Err(invalid(
                    "null_space.tilt",
                    "the `inward-tilt` objective needs a tilt (rad), e.g. `inward-tilt=0.1`",
                ))
            }
            (NullSpaceKind::InwardTilt, Some(t)) => {
                if !(t.is_finite() && t.abs() < std::f64::consts::FRAC_PI_2) {
                    return Err(invalid(
                        "null_space.tilt",
                        format!("must be finite with |tilt| < pi/2 rad, got {t}"),
                    ));
                }
                NullSpaceObjective::InwardTilt {
                    angle: nalgebra_convert(t),
                }
            }
        };
        NullSpaceStage::new(objective, self.iterations).map_err(|_| {
            invalid(
                "null_space.iterations",
                format!(
                    "must be in 1..={}, got {}",
                    tvmd_core::allocation::MAX_NULL_SPACE_ITERATIONS,
                    self.iterations
                ),
            )
        })
    }
}

fn nalgebra_convert<T: Real>(x: f64) -> T {
    tvmd_core::nalgebra::convert(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn string_and_table_forms_parse_and_bad_ones_name_the_field() {
        let m: NullSpaceConfig = "margin".parse().unwrap();
        assert_eq!(m.objective, NullSpaceKind::Margin);
        assert!(m.validate().is_ok());
        let t: NullSpaceConfig = "inward-tilt=0.15".parse().unwrap();
        assert_eq!(t.tilt, Some(0.15));
        assert_eq!(t.to_string(), "inward-tilt=0.15");
        assert!("sideways".parse::<NullSpaceConfig>().is_err());
        let field = |c: NullSpaceConfig| match c.validate() {
            Err(ScenarioError::InvalidScenario { field, .. }) => field,
            other => panic!("{other:?}"),
        };
        assert_eq!(
            field("inward-tilt".parse().unwrap()),
            "null_space.tilt".to_string()
        );
        assert_eq!(field("inward-tilt=2.0".parse().unwrap()), "null_space.tilt");
        let zero = NullSpaceConfig { iterations: 0, ..m };
        assert_eq!(field(zero), "null_space.iterations");
        assert!(t.stage::<f32>().is_ok());
    }

    #[test]
    fn a_bad_table_names_its_key() {
        #[derive(Debug, Deserialize)]
        struct Doc {
            #[allow(dead_code)]
            null_space: NullSpaceConfig,
        }
        let e = toml::from_str::<Doc>("null_space = { objective = \"margin\", tilts = 0.1 }")
            .unwrap_err();
        assert!(e.to_string().contains("tilts"), "{e}");
        let e = toml::from_str::<Doc>("null_space = { objective = \"sideways\" }").unwrap_err();
        assert!(e.to_string().contains("sideways"), "{e}");
        let doc: Doc = toml::from_str("null_space = \"inward-tilt=0.1\"").unwrap();
        assert_eq!(doc.null_space.tilt, Some(0.1));
    }
}
