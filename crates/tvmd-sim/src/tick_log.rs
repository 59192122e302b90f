//! A run's MCAP log as the loop's [`TickSink`] ([`McapSink`]): the messages of one tick
//! (`/state`, `/reference`, the diagnostics channels, `/actuators`, `/tf`, and `/scene` every
//! `scene_period`), built from the loop's values as the protobuf messages of
//! [`tvmd_log::proto`]. Each tick's owned values ([`LoggedTick`]) are collected in a
//! [`TickBatch`] and handed in batches to the log's writer thread ([`tvmd_log::writer`]), which
//! builds and writes the messages there.

use nalgebra::{Matrix3, Vector3};

use crate::diagnostics::{
    AllocationDiagnostics, ControlDiagnostics, FaultDiagnostics, HoverDiagnostics,
    PlannerDiagnostics,
};
use crate::sink::{LoggedTick, Tick, TickSink};
use crate::SimError;
use tvmd_log::proto::{self, Vec3};
use tvmd_log::scene::team_scene;
use tvmd_log::RunLog;
use tvmd_log::{frame_transform, LogChannels, LogMessage};
use tvmd_plant::actuators::ActuatorCommand;
use tvmd_plant::math::{from_rows, roll_pitch_yaw, rotation_quaternion};

/// Ticks a batch holds before it goes to the writer thread when nobody watches live: 0.5 s of a
/// 100 Hz flight. Handing over every tick woke the writer 1,600 times in a 16 s flight; each
/// wake-up is a futex call and a context switch on both threads, which cost the loop more than
/// the physics (`paper-tilt` with its log: 54 ms against 31 ms without, 2-core VM).
pub const BATCH_TICKS: usize = 50;

impl LoggedTick {
    /// Writes the tick's messages, the scene last.
    pub fn write(self, log: &mut LogChannels) {
        let t = self.tick.t;
        let scene = self
            .scene
            .map(|s| team_scene(t, &s.team, &s.forces_body, &self.tick.failed, s.max_thrust));
        self.tick.write(log, self.heavy);
        if let Some(scene) = scene {
            log.write(t, &scene);
        }
    }
}

/// The ticks not yet handed to the log's writer thread. A live log gets every tick at once (the
/// viewer watches at the simulation's pace); a file-only log gets them [`BATCH_TICKS`] at a time.
pub struct TickBatch {
    ticks: Vec<LoggedTick>,
    size: usize,
}

impl TickBatch {
    /// A batch sized for `log`: one tick when it serves a live view, else [`BATCH_TICKS`].
    pub fn for_log(log: &RunLog) -> Self {
        let size = if log.live().is_some() { 1 } else { BATCH_TICKS };
        Self {
            ticks: Vec::with_capacity(size),
            size,
        }
    }

    /// Adds a tick; hands the batch to `log` when it is full.
    pub fn push(&mut self, log: &mut RunLog, tick: LoggedTick) -> Result<(), SimError> {
        self.ticks.push(tick);
        if self.ticks.len() >= self.size {
            self.flush(log)?;
        }
        Ok(())
    }

    /// Hands every pending tick to `log` (nothing to do when none is pending).
    pub fn flush(&mut self, log: &mut RunLog) -> Result<(), SimError> {
        if self.ticks.is_empty() {
            return Ok(());
        }
        let ticks = std::mem::replace(&mut self.ticks, Vec::with_capacity(self.size));
        Ok(log.submit(move |w| ticks.into_iter().for_each(|t| t.write(w)))?)
    }

    /// Ticks pending.
    pub fn len(&self) -> usize {
        self.ticks.len()
    }

    /// True if no tick is pending.
    pub fn is_empty(&self) -> bool {
        self.ticks.is_empty()
    }
}

/// A run's MCAP log (and live view) as the loop's [`TickSink`].
pub struct McapSink<'a> {
    log: &'a mut RunLog,
    batch: TickBatch,
}

impl<'a> McapSink<'a> {
    /// The sink writing to `log`.
    pub fn new(log: &'a mut RunLog) -> Self {
        let batch = TickBatch::for_log(log);
        Self { log, batch }
    }
}

impl TickSink for McapSink<'_> {
    fn tick(&mut self, tick: LoggedTick) -> Result<(), SimError> {
        self.batch.push(self.log, tick)
    }

    fn flush(&mut self) -> Result<(), SimError> {
        self.batch.flush(self.log)
    }

    fn pace(&mut self, t: f64) {
        self.log.pace(t);
    }
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

fn fault(t: f64, f: &FaultDiagnostics) -> proto::Fault {
    proto::Fault {
        t,
        statistic: f.statistic,
        threshold: f.threshold,
        verdict: kebab(&f.verdict),
        agent: f.agent.and_then(|i| u32::try_from(i).ok()),
        kind: f.kind.as_ref().map(kebab).unwrap_or_default(),
        efficiency: f.efficiency,
        masked: f.masked.and_then(|i| u32::try_from(i).ok()),
        periods: f.periods,
        source: f.source.as_ref().map(kebab).unwrap_or_default(),
    }
}

/// The kebab-case name serde gives a unit variant (`"partial-loss"`).
fn kebab<V: serde::Serialize>(v: &V) -> String {
    match serde_json::to_value(v) {
        Ok(serde_json::Value::String(s)) => s,
        _ => String::new(),
    }
}

/// Writes the message `build` makes unless its kind is thinned on this tick: a heavy kind
/// ([`tvmd_log::LogKind::is_heavy`], the one list of them) is written only on `heavy` ticks, and is not
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
    /// ([`tvmd_log::LogKind::is_heavy`]) only when `heavy`.
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
        if let Some(f) = &d.fault {
            log.write(t, &fault(t, f));
        }
        log.write(t, &frame_transform(t, &s.position, &s.rotation));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::flight::FlightOutput;
    use tvmd_plant::PlantState;

    fn logged_tick(t: f64) -> LoggedTick {
        let state = PlantState::at_rest(Vector3::new(0.0, 0.0, 1.0));
        LoggedTick {
            tick: Tick {
                t,
                state,
                reference: tvmd_plant::reference::ReferenceSample {
                    t,
                    position: state.position,
                    velocity: Vector3::zeros(),
                    acceleration: Vector3::zeros(),
                    rotation: Matrix3::identity(),
                    omega: Vector3::zeros(),
                    omega_dot: Vector3::zeros(),
                    roll: 0.0,
                    roll_rate: 0.0,
                },
                output: FlightOutput::default(),
                actual: Vec::new(),
                forces_body: Vec::new(),
                failed: Vec::new(),
            },
            heavy: true,
            scene: None,
        }
    }

    /// A file log gets the ticks [`BATCH_TICKS`] at a time and the rest at the flush; every tick
    /// pushed is written by `finish`, in order.
    #[test]
    fn a_batch_holds_ticks_until_full_or_flushed() {
        let mut log = RunLog::new();
        let mut batch = TickBatch::for_log(&log);
        for k in 0..BATCH_TICKS - 1 {
            batch.push(&mut log, logged_tick(k as f64)).unwrap();
        }
        assert_eq!(batch.len(), BATCH_TICKS - 1);
        batch.push(&mut log, logged_tick(1e3)).unwrap();
        assert!(batch.is_empty(), "a full batch goes to the writer");
        batch.push(&mut log, logged_tick(2e3)).unwrap();
        batch.flush(&mut log).unwrap();
        assert!(batch.is_empty());
        batch.flush(&mut log).unwrap();
        log.finish().unwrap();
        // Each of these ticks writes /state, /reference, /actuators and /tf.
        assert_eq!(log.message_count(), 4 * (BATCH_TICKS as u64 + 1));
    }

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
            refused: None,
        };
        assert_eq!(hover(0.0, &h).limiting_agent, None);
        let h = HoverDiagnostics {
            limiting_agent: Some(2),
            ..h
        };
        assert_eq!(hover(0.0, &h).limiting_agent, Some(2));
    }
}
