//! Exact f32 layouts of what crosses from the simulator to an f32 controller and back: the
//! controller's configuration ([`CoreConfig`]), one cycle's inputs (state and reference) and
//! outputs (the whole [`ControlOutput`], or the recorded subset), as little-endian `u32` words
//! holding `f32` bits, plus the CRC-32 of the PIL frames.
//!
//! Shared by the simulator (`tvmd-sim`) and the firmware in
//! `embedded/target-tests` (the cycle recording and the processor-in-the-loop link), so that
//! both sides encode, decode and build the controller with the same code: only `core` and
//! `tvmd_core`, no allocation.
//!
//! Modules: `words` (the word cursors), `config` (the controller's configuration, with
//! `law`, the law beyond the paper),
//! `cycle` (a cycle's inputs and outputs, the recording's events, failure masks), `fault`
//! (the fault detection's settings and a cycle's fault answer) and
//! `frame` (processor-in-the-loop frames and their CRC-32).

#![no_std]
#![warn(missing_docs)]

mod config;
mod cycle;
mod fault;
mod frame;
mod law;
mod words;

pub use config::CoreConfig;
pub use cycle::*;
pub use fault::*;
pub use frame::*;
pub use law::*;
pub use words::{Reader, Writer};

use tvmd_core::{AnyAllocator, ControlOutput, Controller};

/// Agent capacity of the controller on both sides (the simulator's `MAX_AGENTS`).
pub const AGENTS: usize = 16;

/// The f32 controller both sides build.
pub type WireController = Controller<f32, AGENTS, AnyAllocator<f32, AGENTS>>;

/// The f32 output of one cycle.
pub type WireOutput = ControlOutput<f32, AGENTS>;

/// Words of one cycle's inputs: state (`x`, `R`, `Omega`, `v`: 18) and reference (`x_r`,
/// `v_r`, `a_r`, `R_r`, `Omega_r`, `Omega_dot_r`: 24).
pub const INPUT_WORDS: usize = 42;

/// Longest allocator name carried by a [`CoreConfig`].
pub const ALLOCATOR_NAME_BYTES: usize = 32;

/// Words of a [`CoreConfig`] of `n` agents.
pub const fn config_words(n: usize) -> usize {
    // n, then per agent x, y, z, quarter turns, mass; limits 3; navigator 1 + 9; gains 3 + 3 +
    // 6; relaxation, gravity, period; rate-limit flag + 2; allocator name; the law; fault
    // detection; round-cap flag + 1.
    1 + 5 * n
        + 3
        + 10
        + 12
        + 3
        + 3
        + ALLOCATOR_NAME_BYTES / 4
        + LAW_WORDS
        + FAULT_DETECTION_WORDS
        + 2
}

/// Words of a whole [`ControlOutput`] of `n` agents ([`put_output`]).
pub const fn output_words(n: usize) -> usize {
    // planner 12, projection 5, f_r 3, law 26, allocation 3n + 11, commands 4n, clamp 1.
    12 + 5 + 3 + 26 + 3 * n + 11 + 4 * n + 1
}

/// Words of the recorded subset of one cycle's output ([`put_recorded`]).
pub const fn recorded_words(n: usize) -> usize {
    // commands 4n, e_f, R_d 9, theta, status.
    4 * n + 12
}

/// [`put_recorded`]'s status word of a skipped cycle (a `CycleError`; the commands are the
/// held ones, the rest zero).
pub const STATUS_CYCLE_ERROR: u32 = 0xff;

/// First word of a cycle recording (`"TVRC"`; format in `tvmd_pil::recording`).
pub const RECORDING_MAGIC: u32 = u32::from_le_bytes(*b"TVRC");
/// Format version of a cycle recording (2: the configuration carries the law, [`LAW_WORDS`],
/// and an event may set the landed hold, [`EVENT_LANDED_SET`]; 3: the configuration carries
/// the fault detection, [`FAULT_DETECTION_WORDS`], and the allocator's round cap).
pub const RECORDING_VERSION: u32 = 3;
/// Words of a cycle recording's header (magic, version, agents, cycles, configuration words).
pub const RECORDING_HEADER_WORDS: usize = 5;
/// Recording event flag: a failure mask was set before this cycle.
pub const EVENT_SET: u32 = 1 << 31;
/// Recording event flag: the core refused that mask.
pub const EVENT_REFUSED: u32 = 1 << 30;
/// Recording event flag: `set_landed` was called before this cycle, with
/// [`EVENT_LANDED`] as its argument.
pub const EVENT_LANDED_SET: u32 = 1 << 29;
/// Recording event flag: the landed argument of [`EVENT_LANDED_SET`].
pub const EVENT_LANDED: u32 = 1 << 28;

/// Words of one recorded cycle of `n` agents: event, inputs, recorded outputs.
pub const fn cycle_words(n: usize) -> usize {
    1 + INPUT_WORDS + recorded_words(n)
}
