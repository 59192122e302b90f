//! # tvmd-py
//!
//! Python bindings of [`tvmd_core`] (PyO3 + rust-numpy), built by maturin into the extension
//! module `tvmd._tvmd` of the Python package `tvmd` (see `pyproject.toml` and
//! `python/tvmd/__init__.py`, which re-exports everything listed in `python/tvmd/_tvmd.pyi`).
//!
//! The bindings are thin: they convert types at the boundary and call the core; there is no
//! control logic here. Conventions:
//!
//! - `f64` throughout, fixed capacity [`CAPACITY`] = 64 agents (`TeamConfig<f64, 64>`).
//! - Inputs: NumPy arrays of any real dtype, nested lists or Python numbers (read as float64);
//!   outputs: fresh float64 (or bool / int64) NumPy arrays.
//! - Wrong shapes raise `ValueError` (wrong dtypes `TypeError`) naming the argument and the
//!   expected shape; NaN/inf inputs raise `ValueError`; the core's `ConfigError` / `InputError`
//!   become `tvmd.ConfigError` / `tvmd.InputError` (both `ValueError`s) with the core's message.
//!   No code path panics (the crate denies `unwrap`, `expect`, `panic!` and indexing).
//!
//! Layout: one Rust module per core area ([`team`], [`afs`], [`planner`], [`law`],
//! [`allocation`], [`controller`]), each with a `register` function called by the module
//! initializer. The simulator `tvmd-sim` is the submodule `_tvmd.sim` ([`sim`], added with
//! `m.add_submodule`), re-exported by `python/tvmd/sim.py` so that `import tvmd.sim` works
//! (stubs in `python/tvmd/sim.pyi`).
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
mod controller;
mod convert;
mod errors;
mod law;
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
    Ok(())
}
