//! What the loop logs at each controller tick: the MCAP messages of one tick (`/state`,
//! `/reference`, the diagnostics channels, `/actuators`, `/tf`), built from the loop's values.

use nalgebra::Vector3;
use serde::Serialize;

use crate::actuators::ActuatorCommand;
use crate::diagnostics::PlannerDiagnostics;
use crate::flight::FlightOutput;
use crate::log::{ActuatorsMsg, LogKind, McapLog, Quat, ReferenceMsg, StateMsg};
use crate::math::{from_rows, roll_pitch_yaw, to_rows};
use crate::physics::PlantState;
use crate::reference::ReferenceSample;
use crate::sim::sample::arr;
use crate::SimError;

/// The values of one tick to log.
pub struct Tick<'a> {
    /// Time (s).
    pub t: f64,
    /// True state.
    pub state: &'a PlantState,
    /// Reference.
    pub reference: &'a ReferenceSample,
    /// The controller's output.
    pub output: &'a FlightOutput,
    /// Actual actuator outputs.
    pub actual: Vec<ActuatorCommand>,
    /// Body-frame forces of the actual outputs.
    pub forces_body: Vec<Vector3<f64>>,
    /// True failure flags.
    pub failed: &'a [bool],
}

/// `/planner`: the diagnostics and the roll, pitch, yaw of `R_d`.
#[derive(Serialize)]
struct PlannerMsg<'a> {
    #[serde(flatten)]
    p: &'a PlannerDiagnostics,
    planned_roll_pitch_yaw: [f64; 3],
}

impl Tick<'_> {
    /// Writes the tick's messages (everything but `/scene`).
    pub fn write(self, log: &mut McapLog) -> Result<(), SimError> {
        let (t, s, r) = (self.t, self.state, self.reference);
        log.write(
            LogKind::State,
            t,
            &StateMsg {
                t,
                position: arr(&s.position),
                velocity: arr(&s.velocity),
                velocity_body: arr(&s.velocity_body()),
                orientation: Quat::from_matrix(&s.rotation),
                rotation: to_rows(&s.rotation),
                roll_pitch_yaw: roll_pitch_yaw(&s.rotation),
                omega: arr(&s.omega),
            },
        )?;
        log.write(
            LogKind::Reference,
            t,
            &ReferenceMsg {
                t,
                position: arr(&r.position),
                velocity: arr(&r.velocity),
                acceleration: arr(&r.acceleration),
                rotation: to_rows(&r.rotation),
                omega: arr(&r.omega),
                roll: r.roll,
                roll_rate: r.roll_rate,
            },
        )?;
        let d = &self.output.diagnostics;
        if let Some(p) = &d.planner {
            let planned_roll_pitch_yaw = roll_pitch_yaw(&from_rows(&p.r_d));
            log.write(
                LogKind::Planner,
                t,
                &PlannerMsg {
                    p,
                    planned_roll_pitch_yaw,
                },
            )?;
        }
        if let Some(c) = &d.control {
            log.write(LogKind::Control, t, c)?;
        }
        if d.cycle_error.is_some() || d.failure_note.is_some() {
            // A skipped cycle has no law output: log why on the control channel.
            log.write(
                LogKind::Control,
                t,
                &serde_json::json!({"extra": {
                    "cycle_error": d.cycle_error, "failure_note": d.failure_note}}),
            )?;
        }
        if let Some(a) = &d.allocation {
            log.write(LogKind::Allocation, t, a)?;
        }
        if let Some(l) = &d.lyapunov {
            log.write(LogKind::Lyapunov, t, l)?;
        }
        if let Some(h) = &d.hover {
            log.write(LogKind::Hover, t, h)?;
        }
        log.write(
            LogKind::Actuators,
            t,
            &ActuatorsMsg {
                t,
                commanded: self.output.commands.clone(),
                actual: self.actual,
                failed: self.failed.to_vec(),
                forces_body: self.forces_body.iter().map(arr).collect(),
            },
        )?;
        log.write_frame_transform(t, &s.position, &s.rotation)
    }
}
