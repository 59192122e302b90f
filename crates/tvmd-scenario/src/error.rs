//! The error type of scenarios.

use std::path::{Path, PathBuf};

use tvmd_plant::PhysicsError;

/// Errors of a scenario: it cannot be found, read, parsed or used.
#[derive(Debug, thiserror::Error)]
pub enum ScenarioError {
    /// A scenario field holds a value that parses but is not acceptable.
    #[error("invalid scenario field `{field}`: {reason}")]
    InvalidScenario {
        /// Dotted path of the offending field (e.g. `failures[0].agent`).
        field: String,
        /// What is wrong with it.
        reason: String,
    },
    /// A scenario file could not be parsed; the message names the offending key.
    #[error("cannot parse scenario{}: {message}", .path.as_ref().map(|p| format!(" `{p}`")).unwrap_or_default())]
    ScenarioParse {
        /// File the scenario was read from, if any.
        path: Option<String>,
        /// The parser's message (it names the field and shows the offending line).
        message: String,
    },
    /// No built-in scenario has this name.
    #[error("unknown built-in scenario `{name}` (known: {known})")]
    UnknownScenario {
        /// The requested name.
        name: String,
        /// Comma-separated list of the known names.
        known: String,
    },
    /// A scenario file could not be read: what was being done, the path and the cause.
    #[error("cannot {action} `{}`: {source}", path.display())]
    File {
        /// What was being done (`"read the scenario file"`).
        action: &'static str,
        /// The file.
        path: PathBuf,
        /// The cause.
        #[source]
        source: std::io::Error,
    },
    /// The plant refused a part of the scenario.
    #[error(transparent)]
    Physics(#[from] PhysicsError),
}

impl ScenarioError {
    /// A `map_err` adapter: the I/O error of `action` on `path`.
    pub fn file<'a>(
        action: &'static str,
        path: &'a Path,
    ) -> impl FnOnce(std::io::Error) -> ScenarioError + 'a {
        move |source| ScenarioError::File {
            action,
            path: path.to_path_buf(),
            source,
        }
    }
}

/// A [`ScenarioError::InvalidScenario`] naming `field`.
pub(crate) fn invalid(field: impl Into<String>, reason: impl Into<String>) -> ScenarioError {
    ScenarioError::InvalidScenario {
        field: field.into(),
        reason: reason.into(),
    }
}
