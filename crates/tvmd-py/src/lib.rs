//! Python bindings of [`tvmd_core`] and `tvmd-sim` (PyO3 + rust-numpy): the extension module
//! `tvmd._tvmd`, one Rust module per core area, each with a `register` function called from
//! here, the one registration point; the simulator is the submodule `_tvmd.sim`. The bindings
//! only convert types at the boundary ([`convert`], the one conversion layer; [`errors`], the
//! one error mapping) and call the core. The Python API is documented in the stubs
//! `python/tvmd/_tvmd.pyi` and `sim.pyi`.
//!
//! Modules import one way (no circle; `a <- b` reads "b imports a"): `errors` and `record`
//! import no module of the crate, nor does `interrupt` (Ctrl-C for long calls), `convert` only `errors`, and every other module imports
//! those three as it needs; above them, `afs <- planner`, `afs, law, team_data <- team <- allocation`,
//! `afs, allocation, law, planner <- step_output`,
//! `afs, allocation, controller_args, law, planner, step_output, team <- controller`, and for the simulator
//! `sim_result <- runs <- sim, executor, stepping <- sim_batch` (`stepping` also imports `law`
//! and `replay`, which imports no module of the crate); `atlas` and `montecarlo` import only `convert`, `errors` and
//! `interrupt`. This file imports every module and no module imports it.
#![deny(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    clippy::indexing_slicing,
    clippy::unreachable,
    clippy::todo,
    clippy::unimplemented
)]

use pyo3::prelude::*;
use pyo3::types::PyTuple;

mod afs;
mod allocation;
mod atlas;
mod controller;
mod controller_args;
mod convert;
mod errors;
mod executor;
mod interrupt;
mod law;
mod montecarlo;
mod planner;
mod record;
mod replay;
mod runs;
mod sim;
mod sim_batch;
mod sim_result;
mod step_output;
mod step_state;
mod stepping;
mod team;
mod team_data;

use convert::CAPACITY;

/// The Python extension module `tvmd._tvmd`.
#[pymodule]
fn _tvmd(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("CAPACITY", CAPACITY)?;
    m.add("GRAVITY", tvmd_core::presets::GRAVITY)?;
    m.add("HAS_CLARABEL", cfg!(feature = "clarabel"))?;
    m.add("ALLOCATORS", PyTuple::new(py, allocation::ALLOCATORS)?)?;
    errors::register(m)?;
    team::register(m)?;
    afs::register(m)?;
    planner::register(m)?;
    law::register(m)?;
    allocation::register(m)?;
    controller::register(m)?;
    step_output::register(m)?;
    atlas::register(m)?;
    // The submodule `tvmd._tvmd.sim`.
    let sim = PyModule::new(py, "tvmd.sim")?;
    sim::register(&sim)?;
    sim_result::register(&sim)?;
    executor::register(&sim)?;
    stepping::register(&sim)?;
    sim_batch::register(&sim)?;
    montecarlo::register(&sim)?;
    m.add_submodule(&sim)
}
