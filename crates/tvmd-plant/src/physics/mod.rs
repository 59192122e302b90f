//! The team as one rapier rigid body, the ground, and the physics step.
//!
//! # Frames and origin
//! The rapier body's origin is the team centre of mass, frame {C}. Agent positions `p_i` are
//! given in {C}; [`TeamBody::validate`] rejects teams whose mass-weighted positions do not
//! average to the origin, because `J_C = J_0 - sum m_i [p_i]x [p_i]x` is the inertia about the
//! origin and the model puts the origin at the centre of mass.
//!
//! # Ground
//! The ground is a fixed cuboid whose top face lies at `z = -TeamBody::rest_height()`, so a
//! level team resting on the ground has its centre of mass at `z = 0`. This matches the
//! paper's `x_0 = [0.5, -0.5, 0]` "at rest on the ground" and its reference, which starts
//! and ends at `z = 0`. (The contact model is soft: at rest the colliders sink by well under a
//! millimetre; see the landing test.)
//!
//! Files: `team_body` (the agents and the team's mass properties), `state` (the plant's
//! state and the physics settings) and `world` (the rapier world and its step).

mod state;
mod team_body;
mod world;

pub use state::{ExtraWrench, MassError, PhysicsConfig, PlantState};
pub use team_body::{AgentBody, TeamBody, DEFAULT_COLLIDER_RADIUS};
pub use world::PhysicsWorld;

#[cfg(test)]
mod tests;
