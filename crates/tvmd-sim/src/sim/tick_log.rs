//! What the loop logs at each controller tick: the messages of one tick (`/state`,
//! `/reference`, the diagnostics channels, `/actuators`, `/tf`), built from the loop's values
//! as the protobuf messages of [`crate::log::proto`]. The loop hands a [`Tick`] (owned values)
//! to the log's writer thread ([`crate::log::writer`]), which builds and writes them there.

use nalgebra::{Matrix3, Vector3};

use crate::actuators::ActuatorCommand;
use crate::diagnostics::{
    AllocationDiagnostics, ControlDiagnostics, HoverDiagnostics, PlannerDiagnostics,
};
use crate::flight::FlightOutput;
use crate::log::proto::{self, Vec3};
use crate::log::{frame_transform, LogChannels, LogMessage};
use crate::math::{from_rows, roll_pitch_yaw, rotation_quaternion};
use crate::physics::PlantState;
use crate::reference::ReferenceSample;

/// The values of one tick to log.
pub struct Tick {
    /// Time (s).
    pub t: f64,
    /// True state.
    pub state: PlantState,
    /// Reference.
    pub reference: ReferenceSample,
    /// The controller's output.
    pub output: FlightOutput,
    /// Actual actuator outputs.
    pub actual: Vec<ActuatorCommand>,
    /// Body-frame forces of the actual outputs.
    pub forces_body: Vec<Vector3<f64>>,
    /// True failure flags.
    pub failed: Vec<bool>,
}

fn v(x: &Vector3<f64>) -> Vec<f64> {
    vec![x.x, x.y, x.z]
}

/// Row-major entries of a 3x3 matrix.
fn rows(m: &Matrix3<f64>) -> Vec<f64> {
    m.transpose().iter().copied().collect()
}

fn command(c: &ActuatorCommand) -> proto::AgentCommand {
    proto::AgentCommand {
        eta_x: c.eta_x,
        eta_y: c.eta_y,
        thrust: c.thrust,
    }
}

fn planner(t: f64, p: &PlannerDiagnostics) -> proto::Planner {
    let r_d = from_rows(&p.r_d);
    proto::Planner {
        t,
        r_d: rows(&r_d),
        planned_roll_pitch_yaw: roll_pitch_yaw(&r_d).to_vec(),
        theta: p.theta,
        t_tf: p.t_tf,
        t_eta: p.t_eta,
        reference_feasible: p.reference_feasible,
        planned_roll: p.planned_roll,
        status: p.status.clone(),
        iterations: p.iterations,
    }
}

fn control(t: f64, c: &ControlDiagnostics) -> proto::Control {
    proto::Control {
        t,
        u_r: c.u_r.to_vec(),
        u_d: c.u_d.to_vec(),
        e_x: c.e_x.to_vec(),
        e_v: c.e_v.to_vec(),
        e_r: c.e_r.to_vec(),
        e_omega: c.e_omega.to_vec(),
        t_tf: c.t_tf,
        t_eta: c.t_eta,
        extra_json: if c.extra.is_null() {
            String::new()
        } else {
            c.extra.to_string()
        },
        ..Default::default()
    }
}

fn allocation(t: f64, a: &AllocationDiagnostics) -> proto::Allocation {
    proto::Allocation {
        t,
        wrench: a.wrench.to_vec(),
        e_f: a.e_f,
        saturated: a.saturated.clone(),
        wrench_error: a.wrench_error,
        rounds: a.rounds,
        fallback: a.fallback,
        forces: a
            .forces
            .iter()
            .map(|f| Vec3::of(&Vector3::from(*f)))
            .collect(),
        rotor_speeds: a.rotor_speeds.clone(),
        null_space: a.null_space.map(|n| proto::NullSpace {
            iterations: n.iterations,
            objective: n.objective.to_vec(),
            margin: n.margin.to_vec(),
            largest_force_change: n.largest_force_change,
            wrench_drift: n.wrench_drift,
        }),
    }
}

fn hover(t: f64, h: &HoverDiagnostics) -> proto::Hover {
    proto::Hover {
        t,
        capable: h.capable,
        margin: h.margin,
        limiting_agent: h.limiting_agent.and_then(|i| u32::try_from(i).ok()),
        limit: h.limit.clone(),
        landing: h.landing,
    }
}

/// Writes the message `build` makes unless its kind is thinned on this tick: a heavy kind
/// ([`crate::log::LogKind::is_heavy`], the one list of them) is written only on `heavy` ticks, and is not
/// even built otherwise.
fn write_thinned<M: LogMessage>(
    log: &mut LogChannels,
    t: f64,
    heavy: bool,
    build: impl FnOnce() -> M,
) {
    if heavy || !M::KIND.is_heavy() {
        log.write(t, &build());
    }
}

impl Tick {
    /// Writes the tick's messages (everything but `/scene`); the heavy topics
    /// ([`crate::log::LogKind::is_heavy`]) only when `heavy`.
    pub fn write(self, log: &mut LogChannels, heavy: bool) {
        let (t, s, r) = (self.t, &self.state, &self.reference);
        let q = rotation_quaternion(&s.rotation);
        log.write(
            t,
            &proto::State {
                t,
                position: v(&s.position),
                velocity: v(&s.velocity),
                velocity_body: v(&s.velocity_body()),
                orientation: Some(proto::Quat {
                    x: q.i,
                    y: q.j,
                    z: q.k,
                    w: q.w,
                }),
                rotation: rows(&s.rotation),
                roll_pitch_yaw: roll_pitch_yaw(&s.rotation).to_vec(),
                omega: v(&s.omega),
            },
        );
        log.write(
            t,
            &proto::Reference {
                t,
                position: v(&r.position),
                velocity: v(&r.velocity),
                acceleration: v(&r.acceleration),
                rotation: rows(&r.rotation),
                omega: v(&r.omega),
                roll: r.roll,
                roll_rate: r.roll_rate,
                roll_pitch_yaw: roll_pitch_yaw(&r.rotation).to_vec(),
            },
        );
        let d = &self.output.diagnostics;
        if let Some(p) = &d.planner {
            write_thinned(log, t, heavy, || planner(t, p));
        }
        if let Some(c) = &d.control {
            write_thinned(log, t, heavy, || control(t, c));
        }
        if let Some(a) = &d.allocation {
            write_thinned(log, t, heavy, || allocation(t, a));
        }
        write_thinned(log, t, heavy, || proto::Actuators {
            t,
            commanded: self.output.commands.iter().map(command).collect(),
            actual: self.actual.iter().map(command).collect(),
            failed: self.failed.to_vec(),
            forces_body: self.forces_body.iter().map(Vec3::of).collect(),
        });
        if d.cycle_error.is_some() || d.failure_note.is_some() {
            // A skipped cycle has no law output: say why on the control channel, every time
            // (never thinned).
            log.write(
                t,
                &proto::Control {
                    t,
                    cycle_error: d.cycle_error.clone().unwrap_or_default(),
                    failure_note: d.failure_note.clone().unwrap_or_default(),
                    ..Default::default()
                },
            );
        }
        if let Some(l) = &d.lyapunov {
            log.write(
                t,
                &proto::Lyapunov {
                    t,
                    v_x: l.v_x,
                    v_r: l.v_r,
                },
            );
        }
        if let Some(h) = &d.hover {
            log.write(t, &hover(t, h));
        }
        log.write(t, &frame_transform(t, &s.position, &s.rotation));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matrices_are_logged_row_major() {
        let m = Matrix3::new(1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0);
        assert_eq!(rows(&m), [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0]);
    }

    #[test]
    fn a_missing_limiting_agent_stays_absent() {
        let h = HoverDiagnostics {
            capable: false,
            margin: -1.0,
            limiting_agent: None,
            limit: "thrust".into(),
            landing: true,
        };
        assert_eq!(hover(0.0, &h).limiting_agent, None);
        let h = HoverDiagnostics {
            limiting_agent: Some(2),
            ..h
        };
        assert_eq!(hover(0.0, &h).limiting_agent, Some(2));
    }
}
