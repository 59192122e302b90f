//! The error type of the logs and of output files.

use std::path::{Path, PathBuf};

/// Errors of a log or an output file.
#[derive(Debug, thiserror::Error)]
pub enum LogError {
    /// A file could not be read or written: what was being done, the path and the cause.
    #[error("cannot {action} `{}`: {source}", path.display())]
    File {
        /// What was being done (`"write the MCAP log"`, ...).
        action: &'static str,
        /// The file.
        path: PathBuf,
        /// The cause.
        #[source]
        source: std::io::Error,
    },
    /// Output paths that would overwrite each other or an input.
    #[error("output path clash: {0}")]
    PathClash(String),
    /// An argument (a live-view option, a log path) outside its range.
    #[error("invalid argument `{name}`: {reason}")]
    InvalidArgument {
        /// The argument.
        name: String,
        /// What is wrong.
        reason: String,
    },
    /// An MCAP error while writing or reading a log.
    #[error("MCAP error: {0}")]
    Mcap(#[from] mcap::McapError),
    /// An error of the Foxglove SDK while writing a log (its MCAP sink or live server).
    #[error("Foxglove SDK error: {0}")]
    Foxglove(String),
    /// An MCAP log could not be read back (missing channel, malformed message).
    #[error("cannot read log: {0}")]
    LogRead(String),
    /// An I/O error without a known file.
    #[error("I/O error: {0}")]
    Io(#[from] std::io::Error),
    /// The log was already finished.
    #[error("the MCAP log is already finished")]
    LogFinished,
}

impl LogError {
    /// A `map_err` adapter: the I/O error of `action` on `path`.
    pub fn file<'a>(
        action: &'static str,
        path: &'a Path,
    ) -> impl FnOnce(std::io::Error) -> LogError + 'a {
        move |source| LogError::File {
            action,
            path: path.to_path_buf(),
            source,
        }
    }

    /// A `map_err` adapter for the Foxglove SDK's errors (kept as text: the SDK's error type
    /// is not part of this crate's API).
    pub fn foxglove(e: foxglove::FoxgloveError) -> LogError {
        LogError::Foxglove(e.to_string())
    }
}
