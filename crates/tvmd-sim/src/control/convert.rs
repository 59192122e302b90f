//! Conversions at the boundary between the simulator (f64) and the core controller (f32 or
//! f64): state and reference in, commands and diagnostics out. Nothing else crosses precisions.

use nalgebra::{Matrix3, Vector3};
use tvmd_core::Real;

use tvmd_plant::actuators::ActuatorCommand;
use tvmd_plant::physics::PlantState;
use tvmd_plant::reference::ReferenceSample;
use tvmd_scenario::Precision;

/// A float type the core controller runs in: `f32` (the flight configuration) or `f64`.
///
/// `Into<f64>` makes the way out exact; the way in (`f64 -> T`) rounds to nearest, and a
/// finite `f64` beyond `T`'s range becomes infinite, which the core rejects as a non-finite
/// input (a [`tvmd_core::CycleError`] holding the previous commands), never a NaN.
pub trait CoreFloat: Real + Into<f64> {
    /// The scenario's name for this type.
    const PRECISION: Precision;
}

impl CoreFloat for f32 {
    const PRECISION: Precision = Precision::F32;
}

impl CoreFloat for f64 {
    const PRECISION: Precision = Precision::F64;
}

/// `x` rounded to `T`.
pub fn to_core<T: CoreFloat>(x: f64) -> T {
    nalgebra::convert(x)
}

/// `x` in f64 (exact).
pub fn to_sim<T: CoreFloat>(x: T) -> f64 {
    x.into()
}

/// A vector rounded to `T`.
pub fn vector_to_core<T: CoreFloat>(v: &Vector3<f64>) -> Vector3<T> {
    v.map(to_core)
}

/// A matrix rounded to `T`.
pub fn matrix_to_core<T: CoreFloat>(m: &Matrix3<f64>) -> Matrix3<T> {
    m.map(to_core)
}

/// A core vector as an f64 array.
pub fn vector_to_sim<T: CoreFloat>(v: &Vector3<T>) -> [f64; 3] {
    [v.x.into(), v.y.into(), v.z.into()]
}

/// A core matrix in f64.
pub fn matrix_to_sim<T: CoreFloat>(m: &Matrix3<T>) -> Matrix3<f64> {
    m.map(Into::into)
}

/// A core array in f64.
pub fn array_to_sim<T: CoreFloat, const K: usize>(a: [T; K]) -> [f64; K] {
    a.map(Into::into)
}

/// The core's state: `v = R^T x_dot` (body frame, computed in f64), `Omega` as is.
pub fn core_state<T: CoreFloat>(s: &PlantState) -> tvmd_core::RigidState<T> {
    tvmd_core::RigidState {
        position: vector_to_core(&s.position),
        attitude: matrix_to_core(&s.rotation),
        angular_velocity: vector_to_core(&s.omega),
        velocity: vector_to_core(&s.velocity_body()),
    }
}

/// The core's reference.
pub fn core_reference<T: CoreFloat>(r: &ReferenceSample) -> tvmd_core::Reference<T> {
    tvmd_core::Reference {
        position: vector_to_core(&r.position),
        velocity: vector_to_core(&r.velocity),
        acceleration: vector_to_core(&r.acceleration),
        attitude: matrix_to_core(&r.rotation),
        angular_velocity: vector_to_core(&r.omega),
        angular_acceleration: vector_to_core(&r.omega_dot),
    }
}

/// The simulator's actuator command of a core command.
pub fn sim_command<T: CoreFloat>(c: &tvmd_core::AgentCommand<T>) -> ActuatorCommand {
    ActuatorCommand {
        eta_x: c.eta_x.into(),
        eta_y: c.eta_y.into(),
        thrust: c.thrust.into(),
    }
}
