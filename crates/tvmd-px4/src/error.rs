//! The error type of the PX4 bridge.

use tvmd_sim::SimError;

/// Errors of a flight with PX4: its configuration, the links to PX4, PX4 itself, the flight
/// script, the run.
#[derive(Debug, thiserror::Error)]
pub enum Px4Error {
    /// A setting of the flight file or the command line is wrong.
    #[error("invalid `{field}`: {reason}")]
    Config {
        /// The setting (dotted path).
        field: String,
        /// What is wrong.
        reason: String,
    },
    /// The flight file cannot be read or parsed.
    #[error("cannot read the flight file {path}: {reason}")]
    FlightFile {
        /// The file.
        path: String,
        /// Why.
        reason: String,
    },
    /// The simulator port cannot be opened (in use by another simulator, another tvmd-sim, or
    /// PX4's own SIH).
    #[error(
        "cannot listen for PX4 on TCP port {port}: {source} (another simulator running? \
             choose another instance with --instance N: PX4 then connects to 4560 + N)"
    )]
    Bind {
        /// The port.
        port: u16,
        /// The socket error.
        source: std::io::Error,
    },
    /// PX4 never connected to the simulator port.
    #[error(
        "PX4 did not connect to TCP port {port} within {waited:.0} s of wall time (is PX4 \
             SITL running with simulator_mavlink on this port? `PX4_SYS_AUTOSTART=... \
             build/px4_sitl_default/bin/px4` connects to 4560 + its instance)"
    )]
    NeverConnected {
        /// The port.
        port: u16,
        /// Seconds waited.
        waited: f64,
    },
    /// PX4 stopped answering the sensors with actuator controls.
    #[error(
        "PX4 stalled: no HIL_ACTUATOR_CONTROLS for the sensors of t = {t:.3} s within \
             {waited:.1} s of wall time (lockstep waits for PX4; is it stuck or stopped?)"
    )]
    Stalled {
        /// Simulation time of the unanswered sensors (s).
        t: f64,
        /// Seconds waited.
        waited: f64,
    },
    /// PX4 closed the connection.
    #[error("PX4 closed the simulator connection at t = {t:.3} s (PX4 died or was stopped)")]
    Disconnected {
        /// Simulation time (s).
        t: f64,
    },
    /// PX4's build and the bridge's pacing disagree: a lockstep build (`px4_sitl_default`)
    /// needs the lockstep bridge, a build without lockstep (`px4_sitl_nolockstep`) the
    /// real-time one (`--real-time`).
    #[error(
        "PX4 runs {} but the bridge paces {}: {}",
        if *px4_lockstep { "in lockstep" } else { "without lockstep (wall clock)" },
        if *px4_lockstep { "in real time" } else { "in lockstep" },
        if *px4_lockstep {
            "fly a lockstep build (px4_sitl_default) without --real-time"
        } else {
            "fly a build without lockstep (px4_sitl_nolockstep) with --real-time"
        }
    )]
    Pacing {
        /// PX4's controls carry the lockstep flag.
        px4_lockstep: bool,
    },
    /// A socket to PX4 failed.
    #[error("the link to PX4 failed ({what}): {source}")]
    Link {
        /// Which link and operation.
        what: String,
        /// The socket error.
        source: std::io::Error,
    },
    /// The PX4 tree given cannot be used.
    #[error("PX4 tree {path}: {reason}")]
    Px4Tree {
        /// The tree.
        path: String,
        /// What is missing.
        reason: String,
    },
    /// A step of the flight script failed.
    #[error("flight script at t = {t:.3} s: {reason}")]
    Script {
        /// Simulation time (s).
        t: f64,
        /// What failed.
        reason: String,
    },
    /// The simulation or its log failed.
    #[error(transparent)]
    Sim(#[from] SimError),
}
