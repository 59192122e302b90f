//! The simulated plant of tvmd: a thrust-vectoring modular team as **one** rapier3d-f64 rigid
//! body with one compound collider (a small ball at every agent's position `p_i`, the agents'
//! masses point masses there, and the navigator's `m_0` and `J_0` added at the centre), so the
//! body's mass and inertia equal the model's `m_C = m_0 + sum m_i` and
//! `J_C = J_0 - sum m_i [p_i]x [p_i]x` (see [`TeamBody`]). A fixed ground cuboid with contact
//! lets runs start on the ground and land.
//!
//! Modules, in import order: [`math`] (rotations, planned roll, row-major conversions),
//! [`actuators`] (commands, thrust direction (eq. 1), servo and rotor-lag models, failures),
//! [`physics`] (team body, rapier world, [`PlantState`]), [`rk4`] (an independent RK4 of the
//! paper's dynamics, eqs. 2-3, a check on rapier), [`reference`](mod@reference) (the paper's reference
//! trajectory and the other references) and [`turbulence`] (the Dryden field of the air).
//!
//! Conventions: SI units, z up, gravity `g = 9.81 m/s^2` along `-z`; body-frame twist
//! `xi = [Omega; v]` with `x_dot = R v`; [`PlantState::velocity`] is in the world frame.

#![warn(missing_docs)]

pub mod actuators;
mod error;
pub mod math;
pub mod physics;
pub mod reference;
pub mod rk4;
pub mod turbulence;

pub use actuators::{ActuatorBank, ActuatorCommand, ActuatorModel, FailureKind, SaturationLimits};
pub use error::PhysicsError;
pub use physics::{
    AgentBody, ExtraWrench, MassError, PhysicsConfig, PhysicsWorld, PlantState, TeamBody,
    DEFAULT_COLLIDER_RADIUS,
};
pub use reference::{ReferenceConfig, ReferenceSample};
pub use turbulence::Turbulence;

/// Standard gravity used throughout the simulator (m/s^2).
pub const GRAVITY: f64 = 9.81;
