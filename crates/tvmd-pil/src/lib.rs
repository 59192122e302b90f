//! # tvmd-pil
//!
//! Where the tvmd core's cycle runs for the simulator, behind one trait ([`CoreEngine`]): in
//! process ([`CoreController`]), on an emulated Cortex-M4F or Cortex-M7 over a serial link
//! ([`PilCore`], processor in the loop: the PIL firmware `embedded/target-tests`, bin
//! `tvmd-pil`, in QEMU), or recorded cycle by cycle for the firmware's bit-exact replay
//! ([`recording::Recorder`], [`CycleRecording`]). Everything that crosses to the target is a
//! `tvmd-wire` word. The simulator (`tvmd-sim`) drives any engine alike and re-exports this
//! crate as `tvmd_sim::pil`.
//!
//! Modules, in import order: `error`, `engine` (the trait and the in-process core), `frame` (the link's
//! frames), `link` (QEMU and its serial port), `target` ([`PilTarget`], [`PilError`],
//! [`PilCore`]), `recording`.
#![warn(missing_docs)]

pub mod engine;
mod error;
pub mod frame;
mod link;
pub mod recording;
mod target;

pub use engine::{
    BoxedError, CoreController, CoreEngine, CoreOutput, CycleAnswer, FailureAnswer, SkippedCycle,
    MAX_AGENTS,
};
pub use error::{PilError, BUILD_COMMAND, FIRMWARE_ENV};
pub use link::QemuLink;
pub use recording::CycleRecording;
pub use target::{
    firmware_candidates, firmware_path, PilCore, PilTarget, CYCLE_TIMEOUT, START_TIMEOUT,
};
