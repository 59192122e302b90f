//! The error type of the studies.

use std::path::Path;

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
    /// An argument of a study outside its range.
    #[error("invalid argument `{name}`: {reason}")]
    InvalidArgument {
        /// The argument.
        name: String,
        /// What is wrong.
        reason: String,
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
        move |source| {
            StudyError::Log(LogError::File {
                action,
                path: path.to_path_buf(),
                source,
            })
        }
    }

    /// A team (or a failure set, an allocator for it) the study cannot use:
    /// [`PhysicsError::InvalidTeam`].
    pub fn invalid_team(reason: impl Into<String>) -> StudyError {
        StudyError::Physics(PhysicsError::InvalidTeam(reason.into()))
    }
}
