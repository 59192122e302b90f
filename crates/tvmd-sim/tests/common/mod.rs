//! Test-only controllers.
#![allow(dead_code)]

use nalgebra::{DMatrix, DVector, Matrix3, Vector3};
use tvmd_plant::actuators::ActuatorCommand;
use tvmd_plant::physics::TeamBody;
use tvmd_sim::diagnostics::{Diagnostics, LyapunovDiagnostics};
use tvmd_sim::flight::{FlightController, FlightInput, FlightOutput};
use tvmd_sim::GRAVITY;

type BoxedError = Box<dyn std::error::Error + Send + Sync>;

/// A PD hover controller: collective thrust along body z from a PD law on the height,
/// roll/pitch torques from a PD law towards `R_r`, split over the agents' vertical thrusts with
/// a pseudo-inverse (gimbals stay at zero, so yaw and horizontal position are not controlled).
pub struct PdHover {
    pub mass: f64,
    pub kp: f64,
    pub kd: f64,
    pub kr: f64,
    pub kw: f64,
    /// Thrust is cut (zero commands) from this time on.
    pub cut_at: Option<f64>,
    alloc: DMatrix<f64>,
}

impl PdHover {
    pub fn new(team: &TeamBody) -> Self {
        let n = team.len();
        // Rows: total thrust, roll torque (sum y_i T_i), pitch torque (-sum x_i T_i).
        let mut a = DMatrix::zeros(3, n);
        for (i, ag) in team.agents.iter().enumerate() {
            a[(0, i)] = 1.0;
            a[(1, i)] = ag.position[1];
            a[(2, i)] = -ag.position[0];
        }
        let alloc = a.pseudo_inverse(1e-12).expect("pseudo-inverse");
        Self {
            mass: team.mass(),
            kp: 4.0,
            kd: 4.0,
            kr: 6.0,
            kw: 3.0,
            cut_at: None,
            alloc,
        }
    }

    fn vee_error(rd: &Matrix3<f64>, r: &Matrix3<f64>) -> Vector3<f64> {
        let m = 0.5 * (rd.transpose() * r - r.transpose() * rd);
        Vector3::new(m[(2, 1)], m[(0, 2)], m[(1, 0)])
    }
}

impl FlightController for PdHover {
    fn step(&mut self, input: &FlightInput<'_>) -> Result<FlightOutput, BoxedError> {
        let FlightInput {
            t,
            state: s,
            reference: r,
            failed,
            ..
        } = *input;
        let n = self.alloc.nrows();
        if self.cut_at.is_some_and(|c| t >= c) {
            return Ok(FlightOutput {
                commands: vec![ActuatorCommand::default(); n],
                ..Default::default()
            });
        }
        let ex = s.position - r.position;
        let ev = s.velocity - r.velocity;
        let f = self.mass * (r.acceleration - self.kp * ex - self.kd * ev + GRAVITY * Vector3::z());
        let thrust = f.dot(&(s.rotation * Vector3::z())).max(0.0);
        let er = Self::vee_error(&r.rotation, &s.rotation);
        let tau = -self.kr * er - self.kw * s.omega;
        let t_i = &self.alloc * DVector::from_vec(vec![thrust, tau.x, tau.y]);
        let commands = (0..n)
            .map(|i| ActuatorCommand {
                eta_x: 0.0,
                eta_y: 0.0,
                thrust: if failed.get(i).copied().unwrap_or(false) {
                    0.0
                } else {
                    t_i[i].max(0.0)
                },
            })
            .collect();
        let diagnostics = Diagnostics {
            lyapunov: Some(LyapunovDiagnostics {
                v_x: self.kp * ex.norm_squared() + ev.norm_squared(),
                v_r: er.norm_squared() + s.omega.norm_squared(),
            }),
            ..Default::default()
        };
        Ok(FlightOutput {
            commands,
            diagnostics,
        })
    }
}

/// Zero thrust always.
pub fn zero_thrust(n: usize) -> impl FnMut(&FlightInput<'_>) -> Result<FlightOutput, BoxedError> {
    move |_| {
        Ok(FlightOutput {
            commands: vec![ActuatorCommand::default(); n],
            ..Default::default()
        })
    }
}
