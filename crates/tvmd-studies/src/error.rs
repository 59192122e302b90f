//! The error type of the studies.

use std::path::{Path, PathBuf};

use tvmd_log::LogError;
use tvmd_plant::PhysicsError;
use tvmd_scenario::ScenarioError;
use tvmd_sim::SimError;

/// Errors of a study: its arguments, its flights, its outputs.
///
/// The lower crates' errors pass through unchanged (their messages are this error's).
#[derive(Debug, thiserror::Error)]
pub enum StudyError {
    /// A flight or a batch of the simulator failed.
    #[error(transparent)]
    Sim(#[from] SimError),
    /// A scenario cannot be found, read, parsed or used.
    #[error(transparent)]
    Scenario(#[from] ScenarioError),
    /// A log or an output file failed.
    #[error(transparent)]
    Log(#[from] LogError),
    /// The plant refused a team.
    #[error(transparent)]
    Physics(#[from] PhysicsError),
    /// The team description is not usable.
    #[error("invalid team: {0}")]
    InvalidTeam(String),
    /// An argument of a study outside its range.
    #[error("invalid argument `{name}`: {reason}")]
    InvalidArgument {
        /// The argument.
        name: String,
        /// What is wrong.
        reason: String,
    },
    /// A file could not be read or written: what was being done, the path and the cause.
    #[error("cannot {action} `{}`: {source}", path.display())]
    File {
        /// What was being done (`"write the flights table"`, ...).
        action: &'static str,
        /// The file.
        path: PathBuf,
        /// The cause.
        #[source]
        source: std::io::Error,
    },
    /// A table or an allocation set could not be encoded or decoded as JSON.
    #[error("JSON error: {0}")]
    Json(#[from] serde_json::Error),
    /// An I/O error without a known file.
    #[error("I/O error: {0}")]
    Io(#[from] std::io::Error),
    /// A figure could not be drawn or written.
    #[error("plot error: {0}")]
    Plot(String),
    /// Stopped by a signal (SIGINT, SIGTERM, Ctrl-C in Python) or the caller's flag: what was
    /// finished, and where it was kept, in words.
    #[error("interrupted: {0}")]
    Interrupted(String),
    /// A task of a study panicked (a bug) or did not finish.
    #[error("internal error in tvmd-studies (please report): {0}")]
    Internal(String),
}

impl StudyError {
    /// A `map_err` adapter: the I/O error of `action` on `path`.
    pub fn file<'a>(
        action: &'static str,
        path: &'a Path,
    ) -> impl FnOnce(std::io::Error) -> StudyError + 'a {
        move |source| StudyError::File {
            action,
            path: path.to_path_buf(),
            source,
        }
    }
}
