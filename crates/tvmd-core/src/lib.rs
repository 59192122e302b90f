//! # tvmd-core
//!
//! Full-pose tracking control for over-actuated, thrust-vectoring modular team UAVs (TVMD):
//! several agents, each a coaxial rotor on a two-axis gimbal, bolted into one rigid vehicle.
//!
//! Pipeline of one control period, each stage a pure function of explicit inputs:
//!
//! 1. [`team`]: the configuration `Xi` and presets, over [`limits`] and [`failure`] masks
//!    ([`rotation`] holds the shared rotations).
//! 2. [`effectiveness`]: `M(Xi)`, the wrench the agents produce (eq. 4).
//! 3. [`afs`]: the elliptic-cone approximation of the attainable force space (eqs. 7-8).
//! 4. [`projection`]: the force projection `K_f` (eqs. 12-13).
//! 5. [`planner`]: the bisection attitude planner (eqs. 9-11).
//! 6. [`law`]: the geometric full-pose control law (eq. 12) and Lyapunov values.
//! 7. [`allocation`]: allocators behind one [`Allocator`] trait, over [`admissible`] sets.
//! 8. [`command`]: inversion to gimbal angles and rotor speeds inside `E_f` (eq. 6), via
//!    [`gimbal`] (eq. 1).
//!
//! [`Controller`] composes them into one `step` per control period; [`hover`] classifies a
//! degraded team when its failure mask is set (can the working agents hold hover, and with
//! what margin).
//!
//! Beyond the paper, each optional and off in [`ControllerSettings::paper`]: offset-free
//! tracking ([`offset_free`]: a [`disturbance`] observer or [`integral`] action, under
//! [`anti_windup`]), gains that fit any team ([`gain_schedule`], [`natural_gains`]) and the
//! planned attitude's rates ([`attitude_rate`]); agent faults detected and isolated from the
//! wrench residual ([`fault`]).
//!
//! Imports run one way: the leaves ([`real`], [`rotation`], [`error`], [`limits`],
//! [`failure`], [`gimbal`]) import no stage; a stage imports only leaves and earlier stages
//! (e.g. [`projection`] and [`planner`] import [`afs`]; [`allocation`] imports [`admissible`]
//! and [`effectiveness`]); no stage imports [`team`]; only [`team`] and [`controller`] compose
//! stages. See `docs/architecture.md`.
//!
//! `no_std`, no allocator, generic over [`Real`] (`f32` or `f64`), fixed capacity `N` agents.
#![no_std]
#![deny(missing_docs)]
#![deny(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    clippy::indexing_slicing,
    clippy::unreachable,
    clippy::todo,
    clippy::unimplemented
)]

#[cfg(feature = "std")]
extern crate std;

/// The nalgebra version the API uses, re-exported so users match it.
pub use nalgebra;

pub mod admissible;
pub mod afs;
pub mod allocation;
pub mod anti_windup;
pub mod attitude_rate;
pub mod command;
pub mod controller;
mod definite;
pub mod disturbance;
pub mod effectiveness;
pub mod error;
pub mod failure;
pub mod fault;
pub mod fault_detection;
pub mod gain_schedule;
pub mod gimbal;
pub mod hover;
pub mod integral;
pub mod law;
pub mod limits;
mod linalg;
pub mod natural_gains;
pub mod offset_free;
pub mod planner;
pub mod projection;
pub mod real;
pub mod rotation;
pub mod team;

pub use admissible::AdmissibleSet;
pub use afs::{AttainableForceSpace, EllipticCone, Relaxation, SemiAxes};
pub use allocation::{
    Allocation, AllocationRequest, Allocator, AllocatorOptions, AnyAllocator,
    ExactBoundaryRedistribution, NullSpaceObjective, NullSpaceReport, NullSpaceStage,
    PseudoInverse, RedistributedPseudoInverse, WalkCost, WeightedPseudoInverse,
};
#[cfg(feature = "clarabel")]
pub use allocation::{ClarabelAllocator, SequentialConvexAllocator};
pub use anti_windup::Saturation;
pub use attitude_rate::{AttitudeRateFilter, PlannedRates};
pub use command::AgentCommand;
pub use controller::{
    AllocationStage, ControlOutput, Controller, ControllerSettings, CycleError, LawStage,
};
pub use controller::{FaultDetection, FaultMasking, FaultResponse};
pub use disturbance::DisturbanceObserver;
pub use effectiveness::Effectiveness;
pub use error::{ConfigError, ConfigField, InputError};
pub use failure::FailureMask;
pub use fault::{FaultDetector, FaultKind, FaultReport, FaultState, FaultVerdict};
pub use gain_schedule::GainSchedule;
pub use gimbal::GimbalCommand;
pub use hover::{HoverCapability, HoverLimit};
pub use integral::IntegralAction;
pub use law::{AttitudeLaw, Gains, LawOutput, Reference, RigidState};
pub use limits::{AgentLimits, RateLimits};
pub use natural_gains::NaturalGains;
pub use offset_free::{Compensation, OffsetFree};
pub use planner::{AttitudePlanner, PlannerOutput, PlannerStatus};
pub use projection::{project_force, project_force_in, ForceProjection};
pub use real::Real;
pub use team::presets::{self, Preset};
pub use team::{AgentSpec, Arrangement, Navigator, TeamConfig};
