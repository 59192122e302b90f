//! The digital control loop of the tvmd simulator: the plant ([`tvmd_plant`]) at its rate, a
//! flight controller at its own with zero-order hold, the scenario's actuators, failures,
//! disturbances and noise, one sample per controller tick, the run's summary and verdict, and
//! the runner of one run or a batch.
//!
//! Modules, in import order (a module uses only modules above it):
//! - [`error`] ([`SimError`], [`BoxedError`]) and [`pool`] (a scoped worker pool, results in
//!   input order);
//! - [`diagnostics`]: what a controller reports per period (the diagnostics schema, crate
//!   `tvmd-log`'s, re-exported);
//! - [`flight`]: the controller interface [`FlightController`];
//! - [`control`]: the tvmd controller ([`tvmd_core::Controller`]) as a flight controller, in
//!   f64 or f32, in process or on a processor in the loop (the engines, the PIL link and the
//!   cycle recorder are crate `tvmd-pil`, re-exported as [`pil`]), and its allocation stage as
//!   the wrench action of a stepped simulation ([`WrenchAllocation`]);
//! - [`sink`]: the loop's listener [`TickSink`] and what it hands over per tick;
//! - [`sim`]: the loop ([`Simulation`]: run to its end with a controller, or stepped one
//!   controller period at a time with commands or a body wrench, [`Observation`],
//!   [`Stepped`]), its samples, the summary ([`RunSummary`], [`PaperMetrics`]) and the verdict
//!   ([`Verdict`]);
//! - [`tick_log`]: a run's MCAP log as a [`TickSink`] ([`McapSink`]);
//! - [`runner`]: runs with the tvmd controller: one ([`run_scenario`]) or a batch on one
//!   worker pool ([`run_many`], [`relaxation_sweep`]);
//! - [`request`]: one run as the command line and Python ask for it ([`RunRequest`]: the
//!   scenario, its overrides, the target, the log; one parser of its string options).
//!
//! The scenario is data ([`tvmd_scenario`]), the log a listener ([`tvmd_log`]), the studies
//! above this crate (`tvmd-studies`). Conventions: SI units, z up, gravity `g = 9.81 m/s^2`
//! along `-z`; body-frame twist `xi = [Omega; v]` with `x_dot = R v`.

#![warn(missing_docs)]

pub mod control;
pub mod error;
pub mod flight;
pub mod load;
pub mod pool;
pub mod request;
pub mod runner;
pub mod sim;
pub mod sink;
pub mod tick_log;

pub use control::pil::{self, PilError, PilTarget};
pub use control::recording::{self, CycleRecording};
pub use control::{AnyTvmdController, TvmdController, WrenchAllocation, MAX_AGENTS};
pub use error::{BoxedError, SimError};
pub use flight::{AgentReport, FlightController, FlightInput, FlightOutput};
pub use load::{load_run, LoadedRun};
pub use request::{RunRequest, ScenarioSource};
pub use runner::{relaxation_sweep, run_many, run_scenario, RunSpec};
pub use sim::links::LinkStats;
pub use sim::{
    FaultEvent, FaultSummary, FlightDifference, Observation, PaperMetrics, RunResult, RunSummary,
    Sample, SampleRetention, SimOptions, Simulation, Stepped, Verdict,
};
pub use sink::{LoggedTick, SceneRecord, Tick, TickSink};
pub use tick_log::McapSink;
pub use tvmd_log::diagnostics::{self, Diagnostics};
pub use tvmd_plant::GRAVITY;
