//! # tvmd
//!
//! Full-pose tracking control for over-actuated, thrust-vectoring modular team UAVs (TVMD),
//! after Chu, Fang and Lian, *Attainable Force Approximation and Full-Pose Tracking Control of
//! an Over-Actuated Thrust-Vectoring Modular Team UAV*.
//!
//! This root crate re-exports the workspace's crates:
//! - [`core`]: the `no_std` control core (AFS approximation, attitude planner, control law,
//!   allocation).
#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub use tvmd_core as core;
