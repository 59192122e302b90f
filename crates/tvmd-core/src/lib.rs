//! # tvmd-core
//!
//! Full-pose tracking control for over-actuated, thrust-vectoring modular team UAVs (TVMD):
//! several agents, each a coaxial rotor on a two-axis gimbal, bolted into one rigid vehicle.
//!
//! The source reads as the method, one room per stage over a small foundation:
//!
//! 1. [`foundation`]: the scalar [`Real`], rotations, the small dense solvers, the typed
//!    errors.
//! 2. [`agent`]: one agent and the team's wrench: the gimbal's thrust direction (eq. 1), the
//!    limits (eqs. 5-6), the admissible set `E_f` (eq. 6), the effectiveness `M(Xi)` (eq. 4),
//!    the inversion to gimbal angles and rotor speeds, the failure mask.
//! 3. [`afs`]: the elliptic-cone approximation of the attainable force space (eqs. 7-8) and
//!    what reads it: the force projection `K_f` (eqs. 10, 13), the attitude planner (eqs. 9,
//!    11), the hover capability of a degraded team.
//! 4. [`law`]: the geometric full-pose control law (eq. 12) and Lyapunov values; beyond the
//!    paper, each optional and off in [`ControllerSettings::paper`]: offset-free tracking
//!    (a disturbance observer or integral action under anti-windup), gains that fit any team
//!    and the planned attitude's rates.
//! 5. [`allocation`]: allocators behind one [`Allocator`] trait, over the admissible sets.
//! 6. [`fault`]: agent faults detected and isolated from the wrench residual, and their
//!    settings.
//! 7. [`team`]: the configuration `Xi` and presets, which builds the stages' inputs.
//! 8. [`controller`]: [`Controller`] composes the stages into one `step` per control period.
//!
//! Imports run one way, down this list: the foundation imports no room, a stage imports only
//! the foundation, [`agent`] and the stages it reads (e.g. [`afs`] reads [`agent`]); no stage
//! imports [`team`]; only [`team`] and [`controller`] compose stages. The stages' modules keep
//! their earlier paths at the crate's root (`tvmd_core::planner`, `tvmd_core::admissible`,
//! ...), re-exported below. See `docs/architecture.md`.
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

pub mod afs;
pub mod agent;
pub mod allocation;
pub mod controller;
pub mod fault;
pub mod foundation;
pub mod law;
pub mod team;

// The earlier paths of the stages' modules (`tvmd_core::planner::...`), kept for users.
pub use afs::{hover, planner, projection};
pub use agent::{admissible, command, effectiveness, failure, gimbal, limits};
pub use fault::detection as fault_detection;
pub use foundation::{error, real, rotation};
pub use law::{
    anti_windup, attitude_rate, disturbance, gain_schedule, integral, natural_gains, offset_free,
};

pub use admissible::AdmissibleSet;
pub use afs::{AttainableForceSpace, EllipticCone, Relaxation, SemiAxes};
pub use allocation::{
    Allocation, AllocationRequest, Allocator, AllocatorOptions, AnyAllocator, CappedRedistribution,
    ExactBoundaryRedistribution, NullSpaceObjective, NullSpaceReport, NullSpaceStage,
    PseudoInverse, RedistributedPseudoInverse, RoundCap, WalkCost, WeightedPseudoInverse,
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
pub use fault::{
    AgentReading, FaultDetector, FaultKind, FaultReport, FaultSource, FaultState, FaultVerdict,
    ReportCheck, ReportError,
};
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
