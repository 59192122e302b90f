//! The error type of the command line.

use tvmd_log::LogError;
use tvmd_scenario::ScenarioError;
use tvmd_sim::SimError;
use tvmd_studies::StudyError;

/// Errors of the command line: the libraries' errors as they are, and a stop by a signal.
#[derive(Debug, thiserror::Error)]
pub enum CliError {
    /// A run or a batch failed.
    #[error(transparent)]
    Sim(#[from] SimError),
    /// A study failed.
    #[error(transparent)]
    Study(#[from] StudyError),
    /// A scenario cannot be found, read, parsed or used.
    #[error(transparent)]
    Scenario(#[from] ScenarioError),
    /// A log or an output file failed.
    #[error(transparent)]
    Log(#[from] LogError),
    /// A summary could not be encoded as JSON.
    #[error("JSON error: {0}")]
    Json(#[from] serde_json::Error),
    /// An I/O error without a known file.
    #[error("I/O error: {0}")]
    Io(#[from] std::io::Error),
    /// Anything else, as a sentence.
    #[error("{0}")]
    Other(String),
    /// Stopped by a signal; what was simulated has been written.
    #[error("{0}")]
    Interrupted(String),
}
