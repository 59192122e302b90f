//! A small rigid-body plant for closed-loop tests: RK4 of `m x_ddot = R u_f - m g e_3 + d_f`,
//! `J Omega_dot = u_tau - Omega x J Omega + d_tau`, `R_dot = R [Omega]x` (attitude as a unit
//! quaternion, renormalised each step), driven by the controller's allocated wrench `M f` held
//! over the control period (zero-order hold), 10 RK4 steps per period.
#![allow(dead_code)]

use tvmd_core::allocation::Allocator;
use tvmd_core::nalgebra::{Matrix3, Quaternion, UnitQuaternion, Vector3, Vector6};
use tvmd_core::{Controller, Reference, RigidState};

/// The true plant, which the controller's model may get wrong.
#[derive(Clone, Copy, Debug)]
pub struct Truth {
    pub mass: f64,
    pub inertia: Matrix3<f64>,
    pub gravity: f64,
    /// Constant disturbance force in `{I}` (N).
    pub force: Vector3<f64>,
    /// Constant disturbance torque in the body frame (N m).
    pub torque: Vector3<f64>,
}

#[derive(Clone, Copy, Debug)]
pub struct Body {
    pub x: Vector3<f64>,
    /// World-frame velocity.
    pub v: Vector3<f64>,
    pub q: UnitQuaternion<f64>,
    pub w: Vector3<f64>,
}

impl Body {
    pub fn at(x: Vector3<f64>) -> Self {
        Self {
            x,
            v: Vector3::zeros(),
            q: UnitQuaternion::identity(),
            w: Vector3::zeros(),
        }
    }

    pub fn state(&self) -> RigidState<f64> {
        let r = self.q.to_rotation_matrix().into_inner();
        RigidState {
            position: self.x,
            attitude: r,
            angular_velocity: self.w,
            velocity: r.transpose() * self.v,
        }
    }
}

type D = (Vector3<f64>, Vector3<f64>, Quaternion<f64>, Vector3<f64>);

fn derivative(b: &Body, q: &Quaternion<f64>, t: &Truth, u: &Vector6<f64>) -> D {
    let unit = UnitQuaternion::from_quaternion(*q);
    let r = unit.to_rotation_matrix().into_inner();
    let tau = Vector3::new(u[0], u[1], u[2]);
    let f = Vector3::new(u[3], u[4], u[5]);
    let a = (r * f + t.force) / t.mass - Vector3::new(0.0, 0.0, t.gravity);
    let jw = t.inertia * b.w;
    let alpha = t.inertia.try_inverse().unwrap() * (tau - b.w.cross(&jw) + t.torque);
    let q_dot = q * Quaternion::from_parts(0.0, b.w) * 0.5;
    (b.v, a, q_dot, alpha)
}

/// One RK4 step of `h` seconds under the held wrench `u`.
pub fn rk4(b: &Body, t: &Truth, u: &Vector6<f64>, h: f64) -> Body {
    let q0 = *b.q.quaternion();
    let shift = |k: &D, s: f64| -> (Body, Quaternion<f64>) {
        let q = q0 + k.2 * s;
        (
            Body {
                x: b.x + k.0 * s,
                v: b.v + k.1 * s,
                q: b.q,
                w: b.w + k.3 * s,
            },
            q,
        )
    };
    let k1 = derivative(b, &q0, t, u);
    let (b2, q2) = shift(&k1, h / 2.0);
    let k2 = derivative(&b2, &q2, t, u);
    let (b3, q3) = shift(&k2, h / 2.0);
    let k3 = derivative(&b3, &q3, t, u);
    let (b4, q4) = shift(&k3, h);
    let k4 = derivative(&b4, &q4, t, u);
    let s = h / 6.0;
    let q = q0 + (k1.2 + k2.2 * 2.0 + k3.2 * 2.0 + k4.2) * s;
    Body {
        x: b.x + (k1.0 + k2.0 * 2.0 + k3.0 * 2.0 + k4.0) * s,
        v: b.v + (k1.1 + k2.1 * 2.0 + k3.1 * 2.0 + k4.1) * s,
        q: UnitQuaternion::from_quaternion(q),
        w: b.w + (k1.3 + k2.3 * 2.0 + k3.3 * 2.0 + k4.3) * s,
    }
}

/// One sample per control period.
#[derive(Clone, Copy, Debug)]
pub struct Sample {
    pub t: f64,
    /// `||x - x_r||` (m).
    pub position_error: f64,
    /// Angle of `R_r^T R` (rad).
    pub attitude_error: f64,
    /// `x - x_r` (m).
    pub e_x: Vector3<f64>,
    /// `||compensation.force||`, `||compensation.torque||` after the period.
    pub compensation: (f64, f64),
    /// Whether the period saturated (the anti-windup flags).
    pub saturation: tvmd_core::Saturation,
    /// `||compensation.force||` before the period.
    pub compensation_before: f64,
}

/// Flies `controller` on `truth` from `body` for `duration` s, the reference given per time.
/// A cycle error panics (the tests fly attainable flights, or expect bounded failure).
pub fn fly<A: Allocator<f64, N>, const N: usize>(
    controller: &mut Controller<f64, N, A>,
    truth: &Truth,
    body: &mut Body,
    reference: impl Fn(f64) -> Reference<f64>,
    duration: f64,
) -> Vec<Sample> {
    let dt = controller.settings().period;
    let steps = (duration / dt).round() as usize;
    let mut samples = Vec::with_capacity(steps);
    for k in 0..steps {
        let t = k as f64 * dt;
        let r = reference(t);
        let before = controller.offset_free_compensation().force.norm();
        let out = controller
            .step(&body.state(), &r)
            .unwrap_or_else(|e| panic!("cycle failed at t = {t}: {e}"));
        let u = out.allocation.wrench;
        for _ in 0..10 {
            *body = rk4(body, truth, &u, dt / 10.0);
        }
        let c = controller.offset_free_compensation();
        let state = body.state();
        let e = r.attitude.transpose() * state.attitude;
        let sin = Vector3::new(
            e[(2, 1)] - e[(1, 2)],
            e[(0, 2)] - e[(2, 0)],
            e[(1, 0)] - e[(0, 1)],
        )
        .norm()
            / 2.0;
        let cos = (e.trace() - 1.0) / 2.0;
        samples.push(Sample {
            t: t + dt,
            position_error: (state.position - r.position).norm(),
            attitude_error: sin.atan2(cos),
            e_x: state.position - r.position,
            compensation: (c.force.norm(), c.torque.norm()),
            saturation: tvmd_core::Saturation::from_cycle(
                out.projection.t_tf,
                out.projection.t_eta,
                out.planner.status == tvmd_core::PlannerStatus::Unreachable,
                out.allocation.wrench_error,
                out.law.u_d.norm(),
            ),
            compensation_before: before,
        });
    }
    samples
}

/// The largest `f(sample)` over `t >= from`.
pub fn worst_after(samples: &[Sample], from: f64, f: impl Fn(&Sample) -> f64) -> f64 {
    samples
        .iter()
        .filter(|s| s.t >= from)
        .map(f)
        .fold(0.0, f64::max)
}

/// The first time after which `position_error` stays within `band`.
pub fn settling_time(samples: &[Sample], band: f64) -> f64 {
    samples
        .iter()
        .rev()
        .find(|s| s.position_error > band)
        .map_or(0.0, |s| s.t)
}
