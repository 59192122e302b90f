//! `tvmd-sim`: run the paper's simulation (and other scenarios) with the tvmd controller, the
//! relaxation study, and plots.
//!
//! ```text
//! tvmd-sim run [SCENARIO|FILE.toml] [--out run.mcap | --no-log] [--plots DIR] [--summary FILE]
//!              [--relaxation S] [--allocator NAME] [--null-space margin|inward-tilt=RAD]
//!              [--precision f64|f32]
//!              [--pil cortex-m4|cortex-m7]
//! tvmd-sim sweep [--relaxations 0.25,0.5,0.75,1.0] [--scenario NAME|FILE] [--plots DIR]
//!                [--allocator NAME] [--precision f64|f32]
//! tvmd-sim plot RUN.mcap [MORE.mcap ...] --out DIR
//! tvmd-sim record-cycles [SCENARIO|FILE.toml] --out FILE [--cycles 1000] [--allocator NAME]
//! tvmd-sim allocation-set [--out benches/data/allocation_set.json] [--seed 16]
//! tvmd-sim allocation-eval [--set benches/data/allocation_set.json] [--allocators A,B]
//!                          [--closed-loop] [--json FILE]
//! tvmd-sim afs TEAM|all [--failed I | --each-failure] [--plots DIR] [--json FILE]
//! tvmd-sim list
//! tvmd-sim show NAME
//! ```
//!
//! SIGINT or SIGTERM during `run` or `sweep` stops the flights at their next controller tick:
//! the MCAP logs are finalised and the summary written with what was simulated (marked
//! `interrupted`), and the exit status is 130. `montecarlo` writes the report of the flights
//! that finished (and says it is partial), `catalogue` the finished flights, `afs` nothing;
//! each exits with 130. A second signal exits at once.
//!
//! Every output path follows one rule (`tvmd_log::paths`): checked before any work, written
//! to a temporary file and renamed into place, every I/O error naming its path.

// The argument docs are clap's help texts (`tvmd-sim --help`), where `<scenario name>` is
// meant literally, not HTML.
#![allow(rustdoc::invalid_html_tags)]

mod args;
mod commands;
mod error;
mod interrupt;
mod progress;

use std::process::ExitCode;

use clap::Parser;

use error::CliError;
use interrupt::INTERRUPTED_STATUS;

// Rapier allocates and frees its solver buffers every step, and a logged run frees each tick's
// records on the log's writer thread: mimalloc keeps that from contending (Cargo.toml).
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

fn main() -> ExitCode {
    let result = commands::dispatch(args::Cli::parse());
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(CliError::Interrupted(m))
        | Err(CliError::Study(tvmd_studies::StudyError::Interrupted(m))) => {
            eprintln!("interrupted: {m}");
            ExitCode::from(INTERRUPTED_STATUS)
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
