//! Studies over the tvmd simulator, each a folder:
//! - [`afs_atlas`]: the exact attainable force set of a team, bracketed, against the elliptic
//!   cone, and the certified relaxation `s*` (the book's chapter "AFS atlas");
//! - [`montecarlo`]: flights drawn from distributions of model error, wind and noise, their
//!   table, groups and box plots, and the catalogue of teams;
//! - [`allocation_bench`]: the allocation benchmark set (seeded requests per team, attainable
//!   or certified outside) and every allocator evaluated on it and in the closed loop;
//! - [`plot`]: the paper's figures (state profile, Lyapunov candidates, relaxation study) from
//!   a run's samples or its MCAP log.

#![warn(missing_docs)]

pub mod afs_atlas;
pub mod allocation_bench;
mod error;
pub mod montecarlo;
pub mod plot;

pub use error::StudyError;
pub use montecarlo::catalogue;
pub use plot::{PlotPoint, PlotSeries, PLOT_SAMPLES};
