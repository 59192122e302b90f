//! The plant's state and the physics settings.

use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};

use crate::GRAVITY;

/// Rigid-body state of the team: position and velocity of the centre of mass and attitude.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlantState {
    /// Position `x` of the centre of mass in the world frame (m).
    pub position: Vector3<f64>,
    /// Attitude `R` (body to world).
    pub rotation: Matrix3<f64>,
    /// Velocity `x_dot` of the centre of mass in the world frame (m/s).
    pub velocity: Vector3<f64>,
    /// Body-frame angular velocity `Omega` (rad/s).
    pub omega: Vector3<f64>,
}

impl PlantState {
    /// At rest at `position` with identity attitude.
    pub fn at_rest(position: Vector3<f64>) -> Self {
        Self {
            position,
            rotation: Matrix3::identity(),
            velocity: Vector3::zeros(),
            omega: Vector3::zeros(),
        }
    }

    /// Body-frame linear velocity `v = R^T x_dot` (the twist's translational part).
    pub fn velocity_body(&self) -> Vector3<f64> {
        self.rotation.transpose() * self.velocity
    }

    /// True if every component is finite.
    pub fn is_finite(&self) -> bool {
        self.position.iter().all(|c| c.is_finite())
            && self.rotation.iter().all(|c| c.is_finite())
            && self.velocity.iter().all(|c| c.is_finite())
            && self.omega.iter().all(|c| c.is_finite())
    }
}

/// Physics settings.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PhysicsConfig {
    /// Physics step (s); default 1 ms.
    pub dt: f64,
    /// Gravity magnitude (m/s^2) along `-z`; default 9.81.
    pub gravity: f64,
    /// Whether the ground exists; default true.
    pub ground: bool,
    /// Friction coefficient of the colliders (ground and team); default 1.0.
    pub friction: f64,
    /// Number of rapier solver iterations (substeps) per step; default 1. More substeps
    /// make the free flight's symplectic-Euler integration finer (its position error is
    /// about `dt / (2 n)` times the velocity change) but re-solve every ground contact each
    /// time: 4 cost `paper-tilt` about 50% more instructions than 1, for reproduction metrics
    /// that differ by at most 3.4e-5 m (BENCHMARKS.md). The number is the same in the air and
    /// on the ground: switching it near the ground made flights differ at touchdown by far
    /// more than that.
    pub solver_iterations: usize,
}

impl Default for PhysicsConfig {
    fn default() -> Self {
        Self {
            dt: 1e-3,
            gravity: GRAVITY,
            ground: true,
            friction: 1.0,
            solver_iterations: 1,
        }
    }
}

/// A wrench applied on top of the agents' thrusts during one physics step.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ExtraWrench {
    /// Force through the centre of mass, in the world frame (N), e.g. wind.
    pub force_world: Vector3<f64>,
    /// Torque in the world frame (N m).
    pub torque_world: Vector3<f64>,
    /// Force through the centre of mass, in the body frame (N).
    pub force_body: Vector3<f64>,
    /// Torque in the body frame (N m).
    pub torque_body: Vector3<f64>,
}

/// How the flown body's mass differs from its team description (the mass part of a model
/// error): mass and inertia scales and the centre of mass's offset from the body origin.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MassError {
    /// Mass over the team's `m_C`.
    pub mass_scale: f64,
    /// Inertia about the centre of mass over the team's `J`.
    pub inertia_scale: f64,
    /// Centre of mass in the body frame (m), against the team's (the body origin).
    pub com_offset: Vector3<f64>,
}

impl Default for MassError {
    fn default() -> Self {
        Self {
            mass_scale: 1.0,
            inertia_scale: 1.0,
            com_offset: Vector3::zeros(),
        }
    }
}

impl MassError {
    pub(crate) fn is_nominal(&self) -> bool {
        *self == Self::default()
    }
}
