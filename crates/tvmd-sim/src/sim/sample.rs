//! What the loop records at each controller tick: [`Sample`].

use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};

use crate::diagnostics::{AllocationDiagnostics, FaultDiagnostics, HoverDiagnostics};
use crate::flight::FlightOutput;
use tvmd_plant::actuators::ActuatorCommand;
use tvmd_plant::math::{from_rows, planned_roll, roll_pitch_yaw, rotation_distance};
use tvmd_plant::physics::PlantState;
use tvmd_plant::reference::ReferenceSample;

/// One recorded sample (at each controller tick, true state).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Sample {
    /// Time (s).
    pub t: f64,
    /// `x` (m).
    pub position: [f64; 3],
    /// `x_dot` (m/s), world frame.
    pub velocity: [f64; 3],
    /// Body rates `Omega` (rad/s), body frame.
    #[serde(default)]
    pub omega: [f64; 3],
    /// The attitude `R` (body to world), by rows.
    #[serde(default)]
    pub rotation: [[f64; 3]; 3],
    /// `x_r` (m).
    pub reference_position: [f64; 3],
    /// Roll, pitch, yaw of `R` (rad).
    pub roll_pitch_yaw: [f64; 3],
    /// Roll, pitch, yaw of `R_r` (rad).
    pub reference_roll_pitch_yaw: [f64; 3],
    /// `phi_r` (rad).
    pub reference_roll: f64,
    /// Roll of the planned `R_d` (rad), if the controller reported it.
    pub planned_roll: Option<f64>,
    /// Roll, pitch, yaw of the planned `R_d` (rad), if reported.
    pub planned_roll_pitch_yaw: Option<[f64; 3]>,
    /// Angle between `R` and the planned `R_d` (rad), if `R_d` was reported.
    pub attitude_error: Option<f64>,
    /// Angle between `R` and the reference `R_r` (rad).
    pub reference_attitude_error: f64,
    /// Planner angle `theta*` (rad), if reported.
    pub theta: Option<f64>,
    /// Allocation error `e_f` (N), if reported.
    pub e_f: Option<f64>,
    /// Moment error `e_tau = ||u_taud - u_tau||` (N m): the desired moment against the
    /// allocated one, if both were reported.
    pub e_tau: Option<f64>,
    /// Thrust efficiency `||u_f|| / sum_i ||f_i||` of the allocated forces, if reported and
    /// some agent thrusts.
    pub thrust_efficiency: Option<f64>,
    /// Number of agents the allocator saturated, if reported.
    pub saturated_agents: Option<usize>,
    /// The null-space stage's smallest normalized margin before and after, if it ran.
    pub null_space_margins: Option<[f64; 2]>,
    /// `V_x`, if reported.
    pub v_x: Option<f64>,
    /// `V_R`, if reported.
    pub v_r: Option<f64>,
    /// The controller skipped this cycle (held its previous commands).
    pub cycle_error: bool,
    /// The hover classification, at the tick a new failure mask was accepted.
    pub hover: Option<HoverDiagnostics>,
    /// The fault detector's report, when the controller runs one.
    #[serde(default)]
    pub fault: Option<FaultDiagnostics>,
    /// Commands returned at this tick.
    pub commands: Vec<ActuatorCommand>,
    /// Actual actuator outputs at this tick (before the new commands act).
    pub actual: Vec<ActuatorCommand>,
    /// True failure flags.
    pub failed: Vec<bool>,
}

/// `[x, y, z]` of a vector.
pub(crate) fn arr(v: &Vector3<f64>) -> [f64; 3] {
    [v.x, v.y, v.z]
}

/// The rows of a matrix.
fn rows(m: &Matrix3<f64>) -> [[f64; 3]; 3] {
    [0, 1, 2].map(|i| [m[(i, 0)], m[(i, 1)], m[(i, 2)]])
}

fn sub3(a: &[f64; 3], b: &[f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn norm3(a: &[f64; 3]) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}

/// The moment part `[tau]` of a wrench `[tau; f]`.
fn head3(w: &[f64; 6]) -> [f64; 3] {
    [w[0], w[1], w[2]]
}

/// `||u_f|| / sum_i ||f_i||` of an allocation: the share of the agents' thrust that acts as the
/// team's force (1 with every agent thrusting along one direction); `None` without forces or
/// with no thrust at all.
fn thrust_efficiency(a: &AllocationDiagnostics) -> Option<f64> {
    let total: f64 = a.forces.iter().map(norm3).sum();
    let useful = norm3(&[a.wrench[3], a.wrench[4], a.wrench[5]]);
    (total > 0.0).then(|| (useful / total).min(1.0))
}

impl Sample {
    /// The sample of a tick: true state `s`, reference `r`, the controller's output, the
    /// actuators' actual outputs and the true failure flags.
    pub fn record(
        t: f64,
        s: &PlantState,
        r: &ReferenceSample,
        out: &FlightOutput,
        actual: Vec<ActuatorCommand>,
        failed: Vec<bool>,
    ) -> Self {
        let d = &out.diagnostics;
        let r_d = d.planner.as_ref().map(|p| from_rows(&p.r_d));
        Self {
            t,
            position: arr(&s.position),
            velocity: arr(&s.velocity),
            omega: arr(&s.omega),
            rotation: rows(&s.rotation),
            reference_position: arr(&r.position),
            roll_pitch_yaw: roll_pitch_yaw(&s.rotation),
            reference_roll_pitch_yaw: roll_pitch_yaw(&r.rotation),
            reference_roll: r.roll,
            planned_roll: r_d.as_ref().map(planned_roll),
            planned_roll_pitch_yaw: r_d.as_ref().map(roll_pitch_yaw),
            attitude_error: r_d.as_ref().map(|m| rotation_distance(&s.rotation, m)),
            reference_attitude_error: rotation_distance(&s.rotation, &r.rotation),
            theta: d.planner.as_ref().map(|p| p.theta),
            e_f: d.allocation.as_ref().map(|a| a.e_f),
            e_tau: d
                .control
                .as_ref()
                .zip(d.allocation.as_ref())
                .map(|(c, a)| norm3(&sub3(&head3(&c.u_d), &head3(&a.wrench)))),
            thrust_efficiency: d.allocation.as_ref().and_then(thrust_efficiency),
            saturated_agents: d
                .allocation
                .as_ref()
                .map(|a| a.saturated.iter().filter(|x| **x).count()),
            null_space_margins: d
                .allocation
                .as_ref()
                .and_then(|a| a.null_space.as_ref())
                .map(|n| n.margin),
            v_x: d.lyapunov.map(|l| l.v_x),
            v_r: d.lyapunov.map(|l| l.v_r),
            cycle_error: d.cycle_error.is_some(),
            hover: d.hover.clone(),
            fault: d.fault,
            commands: out.commands.clone(),
            actual,
            failed,
        }
    }

    /// The body-frame velocity `v = R^T x_dot` (m/s).
    pub fn velocity_body(&self) -> [f64; 3] {
        let r = &self.rotation;
        let v = &self.velocity;
        [0, 1, 2].map(|j| r[0][j] * v[0] + r[1][j] * v[1] + r[2][j] * v[2])
    }

    /// `||x - x_r||` (m).
    pub fn position_error(&self) -> f64 {
        norm3(&sub3(&self.position, &self.reference_position))
    }

    /// Horizontal position error `||(x - x_r)_{x,y}||` (m).
    pub fn horizontal_error(&self) -> f64 {
        let d = sub3(&self.position, &self.reference_position);
        d[0].hypot(d[1])
    }
}
