//! The error type of the plant.

/// Errors of the plant: a team, a setting or a command it cannot simulate, or a state it cannot
/// represent.
#[derive(Debug, thiserror::Error)]
pub enum PhysicsError {
    /// The team description is not usable (for example its centre of mass is not at the origin).
    #[error("invalid team: {0}")]
    InvalidTeam(String),
    /// A setting of the plant holds a value that is not acceptable.
    #[error("invalid scenario field `{field}`: {reason}")]
    InvalidScenario {
        /// Dotted path of the offending field (e.g. `physics.dt`).
        field: String,
        /// What is wrong with it.
        reason: String,
    },
    /// Commands that cannot be applied.
    #[error("invalid controller output at t = {t:.3} s: {reason}")]
    InvalidCommand {
        /// Simulation time of the call.
        t: f64,
        /// What is wrong with the output.
        reason: String,
    },
    /// The simulated state became non-finite or left the physics' valid range.
    #[error("simulation diverged at t = {t:.3} s: {what}")]
    Diverged {
        /// Simulation time.
        t: f64,
        /// Which quantity, and its value.
        what: String,
    },
}
