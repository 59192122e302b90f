//! Python bindings of [`tvmd_core`] and `tvmd-sim` (PyO3 + rust-numpy): the extension module
//! `tvmd._tvmd`, one Rust module per core area, each with a `register` function; the simulator
//! is the submodule `_tvmd.sim`. The bindings only convert types at the boundary and call the
//! core. The Python API is documented in the stubs `python/tvmd/_tvmd.pyi` and `sim.pyi`.
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
mod convert;
mod errors;
mod executor;
mod law;
mod montecarlo;
mod planner;
mod record;
mod sim;
mod team;

/// Agent capacity of the bindings: `TeamConfig<f64, 64>`.
pub const CAPACITY: usize = 64;

/// The Python extension module `tvmd._tvmd`.
#[pymodule]
fn _tvmd(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("CAPACITY", CAPACITY)?;
    m.add("GRAVITY", tvmd_core::team::presets::GRAVITY)?;
    m.add("HAS_CLARABEL", cfg!(feature = "clarabel"))?;
    m.add("ALLOCATORS", PyTuple::new(py, allocation::ALLOCATORS)?)?;
    errors::register(m)?;
    team::register(m)?;
    afs::register(m)?;
    planner::register(m)?;
    law::register(m)?;
    allocation::register(m)?;
    controller::register(m)?;
    sim::register(m)?;
    atlas::register(m)?;
    Ok(())
}
