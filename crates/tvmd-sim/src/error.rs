//! Error type of the simulator.

/// Boxed error returned by a flight controller.
pub type BoxedError = Box<dyn std::error::Error + Send + Sync + 'static>;

impl SimError {
    /// A `map_err` adapter: the I/O error of `action` on `path`.
    pub fn file<'a>(
        action: &'static str,
        path: &'a std::path::Path,
    ) -> impl FnOnce(std::io::Error) -> SimError + 'a {
        move |source| SimError::File {
            action,
            path: path.to_path_buf(),
            source,
        }
    }

    /// A `map_err` adapter for the Foxglove SDK's errors (kept as text: the SDK's error type
    /// is not part of this crate's API).
    pub fn foxglove(e: foxglove::FoxgloveError) -> SimError {
        SimError::Foxglove(e.to_string())
    }
}

/// Errors of the simulator.
#[derive(Debug, thiserror::Error)]
pub enum SimError {
    /// The team description is not usable (for example its centre of mass is not at the origin).
    #[error("invalid team: {0}")]
    InvalidTeam(String),
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
    /// The controller returned an error.
    #[error("controller failed at t = {t:.3} s: {source}")]
    Controller {
        /// Simulation time of the failing call.
        t: f64,
        /// The controller's error.
        source: BoxedError,
    },
    /// The controller returned commands that cannot be applied.
    #[error("invalid controller output at t = {t:.3} s: {reason}")]
    InvalidCommand {
        /// Simulation time of the call.
        t: f64,
        /// What is wrong with the output.
        reason: String,
    },
    /// The simulated state became non-finite or left the physics' valid range
    /// (`sim::MAX_POSITION`, `sim::MAX_SPEED`, `sim::MAX_BODY_RATE`).
    #[error("simulation diverged at t = {t:.3} s: {what}")]
    Diverged {
        /// Simulation time.
        t: f64,
        /// Which quantity, and its value.
        what: String,
    },
    /// An I/O error without a known file.
    #[error("I/O error: {0}")]
    Io(#[from] std::io::Error),
    /// A file could not be read or written: what was being done, the path and the cause.
    #[error("cannot {action} `{}`: {source}", path.display())]
    File {
        /// What was being done (`"read the scenario file"`, `"write the MCAP log"`, ...).
        action: &'static str,
        /// The file.
        path: std::path::PathBuf,
        /// The cause.
        #[source]
        source: std::io::Error,
    },
    /// An argument of an analysis (the AFS atlas) outside its range.
    #[error("invalid argument `{name}`: {reason}")]
    InvalidArgument {
        /// The argument.
        name: String,
        /// What is wrong.
        reason: String,
    },
    /// Output paths that would overwrite each other or an input.
    #[error("output path clash: {0}")]
    PathClash(String),
    /// A batch was interrupted (SIGINT, SIGTERM, Ctrl-C) before this run started.
    #[error("interrupted before this run started")]
    Interrupted,
    /// An MCAP error while writing a log.
    #[error("MCAP error: {0}")]
    Mcap(#[from] mcap::McapError),
    /// An error of the Foxglove SDK while writing a log (its MCAP sink or live server).
    #[error("Foxglove SDK error: {0}")]
    Foxglove(String),
    /// A JSON serialization error while writing a log.
    #[error("JSON error: {0}")]
    Json(#[from] serde_json::Error),
    /// A figure could not be drawn or written.
    #[error("plot error: {0}")]
    Plot(String),
    /// An MCAP log could not be read back (missing channel, malformed message).
    #[error("cannot read log: {0}")]
    LogRead(String),
    /// The log was already finished.
    #[error("the MCAP log is already finished")]
    LogFinished,
    /// The processor-in-the-loop link failed (firmware or QEMU missing, timeout, desync).
    #[error("processor in the loop: {0}")]
    Pil(#[from] crate::control::pil::PilError),
    /// A run of a batch panicked (a bug in the simulator) or did not finish.
    #[error("internal error in tvmd-sim (please report): {0}")]
    Internal(String),
}
