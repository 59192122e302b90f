//! Rigid-body simulator for thrust-vectoring modular team UAVs (TVMD).
//!
//! The team is simulated as **one** rapier3d-f64 rigid body with one compound collider: a
//! small ball at every agent's position `p_i`, the agents' masses point masses there, and the
//! navigator's `m_0` and `J_0` added at the centre (it has no collider). The body's mass
//! and inertia therefore equal the model's `m_C = m_0 + sum m_i` and
//! `J_C = J_0 - sum m_i [p_i]x [p_i]x` (see [`physics::TeamBody`]). A fixed ground cuboid with
//! contact lets runs start on the ground and land.
//!
//! Modules, in import order (a module uses only modules above it; see
//! `docs/architecture.md`):
//! - [`math`] (rotations, row-major conversions, planned roll), the error type [`SimError`]
//!   [`paths`] (output file names and the checks made before a run starts) and [`pool`] (a
//!   scoped worker pool, results in input order).
//! - [`actuators`]: actuator commands, thrust direction (eq. 1), servo / rotor-lag models and
//!   failures.
//! - [`physics`]: team body, rapier world, the plant's state ([`physics::PlantState`]).
//! - [`rk4`]: an independent RK4 integration of the paper's dynamics (eqs. 2-3), used as a
//!   check on rapier.
//! - [`mod@reference`]: the paper's reference trajectory (stages A/B/C) and a hover reference.
//! - [`scenario`]: TOML scenarios (serde), the built-ins, [`scenario::Scenario::load`] and
//!   run-time [`scenario::Overrides`].
//! - [`diagnostics`]: what a controller reports per period (the diagnostics schema).
//! - [`flight`]: the controller interface [`flight::FlightController`].
//! - [`log`]: MCAP logs (JSON messages, Foxglove `FrameTransform` / `SceneUpdate`).
//! - [`sim`]: the digital control loop ([`sim::Simulation`]), its samples, per-tick log and
//!   summary ([`sim::RunSummary`], [`sim::PaperMetrics`]).
//! - [`control`]: the tvmd controller ([`tvmd_core::Controller`]) as a flight controller, in
//!   f64 or in f32 (the flight configuration; scenario field `controller_precision`).
//! - [`runner`]: runs with the tvmd controller: one ([`runner::run_scenario`]) or a batch on
//!   one worker pool ([`runner::run_many`], [`runner::relaxation_sweep`]).
//! - [`allocation_bench`]: the allocation benchmark set (seeded requests per team, attainable
//!   or certified outside) and the evaluation of every allocator on it and in the closed loop.
//! - [`plot`]: PNG figures (state profile, Lyapunov candidates, relaxation study) from samples
//!   or from an MCAP log.
//! - [`afs_atlas`]: the exact attainable force set of a team, bracketed, against the elliptic
//!   cone, and the certified relaxation `s*` (std only; `docs/afs-atlas.md`).
//!
//! Conventions: SI units, z up, gravity `g = 9.81 m/s^2` along `-z`; body-frame twist
//! `xi = [Omega; v]` with `x_dot = R v`.

#![warn(missing_docs)]

pub mod actuators;
pub mod afs_atlas;
pub mod allocation_bench;
pub mod control;
pub mod diagnostics;
mod error;
pub mod flight;
pub mod log;
pub mod math;
pub mod montecarlo;
pub mod paths;
pub mod physics;
pub mod plot;
pub mod pool;
pub mod reference;
pub mod rk4;
pub mod runner;
pub mod scenario;
pub mod sim;

pub use error::{BoxedError, SimError};

/// Standard gravity used throughout the simulator (m/s^2).
pub const GRAVITY: f64 = 9.81;
