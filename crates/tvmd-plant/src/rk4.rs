//! An independent RK4 integration of the paper's rigid-body dynamics (eqs. 2-3).
//!
//! `G xi_dot = C(xi) xi + u + g_C` with twist `xi = [Omega; v]` in the body frame,
//! `G = blockdiag(J, m I)`, `C(xi) xi = [-Omega x J Omega; -Omega x m v]`,
//! `g_C = [0; -m g R^T e_3]` (z up), `x_dot = R v` and `R_dot = R [Omega]x`.
//!
//! The attitude is integrated as a unit quaternion (`q_dot = q (0, Omega) / 2`) and
//! renormalised after each step. This module shares no code with rapier; it exists to check
//! the rapier body (see `tests/rk4_vs_rapier.rs`).

use nalgebra::{Matrix3, Quaternion, UnitQuaternion, Vector3};

use crate::physics::PlantState;

/// Mass properties and gravity for [`Rk4Body`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RigidBodyParams {
    /// Mass `m` (kg).
    pub mass: f64,
    /// Inertia `J` about the centre of mass, body frame (kg m^2).
    pub inertia: Matrix3<f64>,
    /// Gravity magnitude `g` (m/s^2) along `-z`.
    pub gravity: f64,
}

/// A body-frame wrench `u = [tau; f]`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BodyWrench {
    /// Torque in the body frame (N m).
    pub torque: Vector3<f64>,
    /// Force in the body frame (N).
    pub force: Vector3<f64>,
}

/// Integration state: position, attitude quaternion, body-frame twist.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Q {
    x: Vector3<f64>,
    q: Quaternion<f64>,
    omega: Vector3<f64>,
    v: Vector3<f64>,
}

impl Q {
    fn axpy(&self, h: f64, d: &Q) -> Q {
        Q {
            x: self.x + h * d.x,
            q: self.q + d.q * h,
            omega: self.omega + h * d.omega,
            v: self.v + h * d.v,
        }
    }
}

/// A rigid body integrated with the classical fourth-order Runge-Kutta method.
#[derive(Clone, Debug)]
pub struct Rk4Body {
    params: RigidBodyParams,
    inertia_inv: Matrix3<f64>,
    s: Q,
    time: f64,
}

impl Rk4Body {
    /// A body with `params` in `initial` at time 0. Returns `None` if the inertia is singular.
    pub fn new(params: RigidBodyParams, initial: &PlantState) -> Option<Self> {
        let inertia_inv = params.inertia.try_inverse()?;
        let q = UnitQuaternion::from_matrix(&initial.rotation).into_inner();
        Some(Self {
            params,
            inertia_inv,
            s: Q {
                x: initial.position,
                q,
                omega: initial.omega,
                v: initial.rotation.transpose() * initial.velocity,
            },
            time: 0.0,
        })
    }

    /// Current time (s).
    pub fn time(&self) -> f64 {
        self.time
    }

    /// Current state.
    pub fn state(&self) -> PlantState {
        let r = UnitQuaternion::from_quaternion(self.s.q)
            .to_rotation_matrix()
            .into_inner();
        PlantState {
            position: self.s.x,
            rotation: r,
            velocity: r * self.s.v,
            omega: self.s.omega,
        }
    }

    fn derivative(&self, s: &Q, u: &BodyWrench) -> Q {
        let p = &self.params;
        // Use the normalised quaternion for R so that the stages see a rotation.
        let uq = UnitQuaternion::from_quaternion(s.q);
        let r = uq.to_rotation_matrix().into_inner();
        let j_omega = p.inertia * s.omega;
        let omega_dot = self.inertia_inv * (u.torque - s.omega.cross(&j_omega));
        let g_body = -p.mass * p.gravity * r.transpose() * Vector3::z();
        let v_dot = (u.force + g_body) / p.mass - s.omega.cross(&s.v);
        let q_dot = s.q * Quaternion::from_parts(0.0, s.omega) * 0.5;
        Q {
            x: r * s.v,
            q: q_dot,
            omega: omega_dot,
            v: v_dot,
        }
    }

    /// Advances by `dt` with the body-frame wrench `wrench(t, state)` (evaluated at the RK4
    /// stages, so a continuous program is integrated to fourth order).
    pub fn step<F>(&mut self, dt: f64, wrench: F)
    where
        F: Fn(f64, &PlantState) -> BodyWrench,
    {
        let t = self.time;
        let state_of = |s: &Q| {
            let r = UnitQuaternion::from_quaternion(s.q)
                .to_rotation_matrix()
                .into_inner();
            PlantState {
                position: s.x,
                rotation: r,
                velocity: r * s.v,
                omega: s.omega,
            }
        };
        let s0 = self.s;
        let k1 = self.derivative(&s0, &wrench(t, &state_of(&s0)));
        let s1 = s0.axpy(dt / 2.0, &k1);
        let k2 = self.derivative(&s1, &wrench(t + dt / 2.0, &state_of(&s1)));
        let s2 = s0.axpy(dt / 2.0, &k2);
        let k3 = self.derivative(&s2, &wrench(t + dt / 2.0, &state_of(&s2)));
        let s3 = s0.axpy(dt, &k3);
        let k4 = self.derivative(&s3, &wrench(t + dt, &state_of(&s3)));
        let mut n = s0
            .axpy(dt / 6.0, &k1)
            .axpy(dt / 3.0, &k2)
            .axpy(dt / 3.0, &k3)
            .axpy(dt / 6.0, &k4);
        n.q = n.q.normalize();
        self.s = n;
        self.time += dt;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn free_fall_is_exact() {
        let params = RigidBodyParams {
            mass: 2.0,
            inertia: Matrix3::from_diagonal(&Vector3::new(0.1, 0.2, 0.3)),
            gravity: 9.81,
        };
        let mut b = Rk4Body::new(params, &PlantState::at_rest(Vector3::zeros())).unwrap();
        for _ in 0..1000 {
            b.step(1e-3, |_, _| BodyWrench::default());
        }
        let z = b.state().position.z;
        assert!((z + 0.5 * 9.81).abs() < 1e-9, "z = {z}");
    }

    #[test]
    fn torque_free_rotation_conserves_energy_and_momentum() {
        let j = Matrix3::from_diagonal(&Vector3::new(0.1, 0.2, 0.3));
        let params = RigidBodyParams {
            mass: 1.0,
            inertia: j,
            gravity: 0.0,
        };
        let mut s = PlantState::at_rest(Vector3::zeros());
        s.omega = Vector3::new(1.0, 2.0, 0.5);
        let mut b = Rk4Body::new(params, &s).unwrap();
        let energy = |s: &PlantState| 0.5 * s.omega.dot(&(j * s.omega));
        let momentum = |s: &PlantState| s.rotation * j * s.omega;
        let (e0, h0) = (energy(&s), momentum(&s));
        for _ in 0..2000 {
            b.step(1e-3, |_, _| BodyWrench::default());
        }
        let s1 = b.state();
        assert!((energy(&s1) - e0).abs() < 1e-9);
        assert!((momentum(&s1) - h0).norm() < 1e-9);
    }
}
