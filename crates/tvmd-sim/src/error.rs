//! The error type of the simulator's loop and runner.

use tvmd_log::LogError;
use tvmd_plant::PhysicsError;
use tvmd_scenario::ScenarioError;

pub use tvmd_pil::BoxedError;
use tvmd_pil::PilError;

/// Errors of a run: its scenario, its plant, its log, its controller, or the batch around it.
///
/// The lower crates' errors pass through unchanged (their messages are this error's).
#[derive(Debug, thiserror::Error)]
pub enum SimError {
    /// The scenario cannot be found, read, parsed or used.
    #[error(transparent)]
    Scenario(#[from] ScenarioError),
    /// The plant refused a team or a command, or the state diverged.
    #[error(transparent)]
    Physics(#[from] PhysicsError),
    /// A log or an output file failed.
    #[error(transparent)]
    Log(#[from] LogError),
    /// An option of a run request outside its range (`pil`, `null_space`, ...).
    #[error("invalid argument `{name}`: {reason}")]
    InvalidArgument {
        /// The option.
        name: String,
        /// What is wrong.
        reason: String,
    },
    /// The controller returned an error.
    #[error("controller failed at t = {t:.3} s: {source}")]
    Controller {
        /// Simulation time of the failing call.
        t: f64,
        /// The controller's error.
        source: BoxedError,
    },
    /// The processor-in-the-loop link failed (firmware or QEMU missing, timeout, desync); the
    /// source is a `PilError`.
    #[error("processor in the loop: {0}")]
    Pil(#[source] BoxedError),
    /// A batch was interrupted (SIGINT, SIGTERM, Ctrl-C) before this run started.
    #[error("interrupted before this run started")]
    Interrupted,
    /// A run of a batch panicked (a bug in the simulator) or did not finish.
    #[error("internal error in tvmd-sim (please report): {0}")]
    Internal(String),
}

impl SimError {
    /// A scenario field this run cannot use (for example an allocator this build lacks, or a
    /// setting a PIL target cannot run): [`ScenarioError::InvalidScenario`].
    pub fn invalid_field(field: impl Into<String>, reason: impl Into<String>) -> Self {
        SimError::Scenario(ScenarioError::InvalidScenario {
            field: field.into(),
            reason: reason.into(),
        })
    }
}

impl From<PilError> for SimError {
    fn from(e: PilError) -> Self {
        SimError::Pil(Box::new(e))
    }
}
