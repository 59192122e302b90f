//! Conversions at the boundary between the simulator (f64) and the core controller (f32 or
//! f64): state and reference in, commands and diagnostics out. Nothing else crosses precisions;
//! the rounding in ([`CoreFloat`]) is the scenario configuration's
//! ([`tvmd_scenario::core_float`]).

use nalgebra::{Matrix3, Vector3};

use crate::flight::AgentReport;
use tvmd_plant::actuators::ActuatorCommand;
use tvmd_plant::physics::PlantState;
use tvmd_plant::reference::ReferenceSample;
pub use tvmd_scenario::core_float::CoreFloat;
use tvmd_scenario::core_float::{matrix_to_core, to_core, vector_to_core};

/// `x` in f64 (exact).
pub fn to_sim<T: CoreFloat>(x: T) -> f64 {
    x.into()
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

/// The core's reading of a simulated report. The simulator's Gaussian noise can take a stopped
/// rotor's thrust below zero, which no speed sensor reports (an ESC's rpm is at least 0): that
/// thrust is read as 0. Errors: a non-finite value ([`tvmd_core::ReportError`]).
pub fn core_reading<T: CoreFloat>(
    r: &AgentReport,
) -> Result<tvmd_core::AgentReading<T>, tvmd_core::ReportError> {
    tvmd_core::AgentReading::new(
        to_core(if r.thrust < 0.0 { 0.0 } else { r.thrust }),
        to_core(r.eta_x),
        to_core(r.eta_y),
        to_core(r.age),
    )
}

/// The simulator's actuator command of a core command.
pub fn sim_command<T: CoreFloat>(c: &tvmd_core::AgentCommand<T>) -> ActuatorCommand {
    ActuatorCommand {
        eta_x: c.eta_x.into(),
        eta_y: c.eta_y.into(),
        thrust: c.thrust.into(),
    }
}
