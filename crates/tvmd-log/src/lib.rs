//! Run logs through the official Foxglove SDK (`foxglove`): every channel protobuf-encoded with
//! its schema in the file, written to an MCAP file, served live over Foxglove's WebSocket
//! protocol, or both.
//!
//! | topic | schema | content |
//! |---|---|---|
//! | `/state` | `tvmd.State` | true state of the team |
//! | `/reference` | `tvmd.Reference` | reference trajectory |
//! | `/planner` | `tvmd.Planner` | attitude planner diagnostics |
//! | `/control` | `tvmd.Control` | control-law diagnostics, or why a cycle was skipped |
//! | `/allocation` | `tvmd.Allocation` | allocation diagnostics (`e_f`) |
//! | `/actuators` | `tvmd.Actuators` | commanded and actual agent commands, failures |
//! | `/lyapunov` | `tvmd.Lyapunov` | `V_x`, `V_R` |
//! | `/hover` | `tvmd.Hover` | hover classification when the failure mask changes |
//! | `/fault` | `tvmd.Fault` | fault detector: statistic, threshold, verdict, isolated agent |
//! | `/tf` | `foxglove.FrameTransform` | pose of frame `team` in frame `world` |
//! | `/scene` | `foxglove.SceneUpdate` | one entity per agent (cube at `p_i`, thrust arrow) |
//!
//! The `tvmd.*` messages are declared in [`proto`], the values a controller reports for them in
//! [`diagnostics`]; the `foxglove.*` ones are the SDK's.
//! The scenario's `[log]` table (`tvmd_scenario::LogSettings`) thins the heavy topics. A metadata record
//! [`METADATA_SCENARIO`] may hold the scenario of the run, [`METADATA_RESULT`] its summary; [`read`]
//! reads a log back.
//!
//! Every message carries the simulation time `t` (s) as its MCAP log and publish time (ns).
//! Each [`RunLog`] logs through its own `foxglove::Context`, so runs in parallel never share a
//! sink, and builds and writes its messages on its own thread ([`writer`]), in the order they
//! were handed to it. The file is finalised by [`RunLog::finish`] and, if that was not called (an error or
//! a panic unwound the caller), by `Drop`, so it is never left truncated.
//!
//! Output files follow one rule ([`paths`]): checked before any work, written to a temporary
//! file in the same directory and renamed into place where the format allows.

#![warn(missing_docs)]

mod channels;
mod convert;
pub mod diagnostics;
mod error;
mod kind;
pub mod live;
pub mod paths;
pub mod proto;
pub mod read;
mod run_log;
pub mod scene;
pub mod writer;

pub use channels::{LogChannels, LogMessage};
pub use convert::{fg_quaternion, fg_vector, frame_transform, nanos, timestamp};
pub use error::LogError;
pub use kind::LogKind;
pub use live::{LiveOptions, LiveServer};
pub use read::{read_log_file, read_run, read_run_bytes, LoggedRun, TickMessages};
pub use run_log::RunLog;
pub use writer::{LogJob, QUEUE_JOBS};

/// Name of the metadata record holding the scenario of a run: keys `name`, `relaxation`,
/// `allocator`, `controller_precision` and `toml` (the whole scenario as TOML).
pub const METADATA_SCENARIO: &str = "tvmd.scenario";

/// Name of the metadata record holding the outcome of a run, written when the flight ends:
/// keys `summary` and `paper_metrics` (tvmd-sim's `RunSummary` and `PaperMetrics` as JSON).
/// [`read_run`] gives it back with the ticks.
pub const METADATA_RESULT: &str = "tvmd.result";
