//! Reference trajectories as pure functions of time.
//!
//! The paper's reference (section Simulations; see `docs/method.md`):
//! - A) ascent on `[0, 2]` s: `x_r = [0, 0, 0.75 (1 - cos(pi t / 2))]`, then hover at
//!   `[0, 0, 1.5]`;
//! - B) tilt on `[4, 10]` s: roll `phi_r(t) = (pi/6)(1 + cos((t - 7) pi / 3))` (peak `pi/3`
//!   at `t = 7`), `R_r = R_x(phi_r)`, `Omega_d = 0`;
//! - C) descent on `[12, 14]` s: the ascent mirrored back to `z = 0`.
//!
//! Position references come with their first and second derivatives; for the attitude only
//! `R_r` is given and `Omega_d = 0` (as in the paper). The roll rate is reported for plots.

use std::f64::consts::PI;

use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};

use crate::math::rot_x;

mod tracking;

pub use tracking::{FigureEight, Sine, Step};

/// The reference at one instant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReferenceSample {
    /// Time (s).
    pub t: f64,
    /// `x_r` (m).
    pub position: Vector3<f64>,
    /// `x_r_dot` (m/s).
    pub velocity: Vector3<f64>,
    /// `x_r_ddot` (m/s^2).
    pub acceleration: Vector3<f64>,
    /// `R_r`.
    pub rotation: Matrix3<f64>,
    /// `Omega_d` (body frame, rad/s); zero for the paper's reference.
    pub omega: Vector3<f64>,
    /// `Omega_d_dot` (rad/s^2); zero for the paper's reference.
    pub omega_dot: Vector3<f64>,
    /// Reference roll `phi_r` (rad), for logs and plots.
    pub roll: f64,
    /// Time derivative of `phi_r` (rad/s), for logs only (the controller gets `Omega_d = 0`).
    pub roll_rate: f64,
}

/// Parameters of the paper's reference (defaults are the paper's values).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PaperTilt {
    /// Hover height after the ascent (m); 1.5.
    pub ascent_height: f64,
    /// Peak of the roll reference (rad); `pi/3`.
    pub roll_peak: f64,
    /// Ascent interval `[start, end]` (s); `[0, 2]`.
    pub ascent: [f64; 2],
    /// Tilt interval (s); `[4, 10]`.
    pub tilt: [f64; 2],
    /// Descent interval (s); `[12, 14]`.
    pub descent: [f64; 2],
}

impl Default for PaperTilt {
    fn default() -> Self {
        Self {
            ascent_height: 1.5,
            roll_peak: PI / 3.0,
            ascent: [0.0, 2.0],
            tilt: [4.0, 10.0],
            descent: [12.0, 14.0],
        }
    }
}

/// A reference trajectory.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum ReferenceConfig {
    /// The paper's ascent / tilt / descent reference.
    PaperTilt(PaperTilt),
    /// Constant position and roll.
    Hover {
        /// Position (m).
        position: [f64; 3],
        /// Roll (rad).
        #[serde(default)]
        roll: f64,
    },
    /// A reference jump between two hover positions.
    Step(Step),
    /// Sine tracking about a hover position.
    Sine(Sine),
    /// A horizontal figure-eight.
    FigureEight(FigureEight),
}

impl Default for ReferenceConfig {
    fn default() -> Self {
        Self::PaperTilt(PaperTilt::default())
    }
}

/// `(h/2)(1 - cos(pi (t - t0)/T))` on `[t0, t1)` (0 before, `h` from `t1`), with derivatives:
/// the first instant carries the ramp's acceleration, so a controller ticking at `t0` gets it.
fn cosine_ramp(t: f64, [t0, t1]: [f64; 2], h: f64) -> (f64, f64, f64) {
    let big_t = t1 - t0;
    if t < t0 {
        return (0.0, 0.0, 0.0);
    }
    if t >= t1 || big_t <= 0.0 {
        return (h, 0.0, 0.0);
    }
    let w = PI / big_t;
    let a = w * (t - t0);
    (
        0.5 * h * (1.0 - a.cos()),
        0.5 * h * w * a.sin(),
        0.5 * h * w * w * a.cos(),
    )
}

impl PaperTilt {
    /// Evaluates the reference at `t`.
    pub fn at(&self, t: f64) -> ReferenceSample {
        let h = self.ascent_height;
        let (up, up_d, up_dd) = cosine_ramp(t, self.ascent, h);
        let (down, down_d, down_dd) = cosine_ramp(t, self.descent, h);
        let z = up - down;
        let (z_d, z_dd) = (up_d - down_d, up_dd - down_dd);
        let [b0, b1] = self.tilt;
        let (roll, roll_rate) = if t > b0 && t < b1 && b1 > b0 {
            let w = 2.0 * PI / (b1 - b0);
            let a = w * (t - 0.5 * (b0 + b1));
            (
                0.5 * self.roll_peak * (1.0 + a.cos()),
                -0.5 * self.roll_peak * w * a.sin(),
            )
        } else {
            (0.0, 0.0)
        };
        ReferenceSample {
            t,
            position: Vector3::new(0.0, 0.0, z),
            velocity: Vector3::new(0.0, 0.0, z_d),
            acceleration: Vector3::new(0.0, 0.0, z_dd),
            rotation: rot_x(roll),
            omega: Vector3::zeros(),
            omega_dot: Vector3::zeros(),
            roll,
            roll_rate,
        }
    }
}

impl ReferenceConfig {
    /// Evaluates the reference at `t`.
    pub fn at(&self, t: f64) -> ReferenceSample {
        match self {
            Self::PaperTilt(p) => p.at(t),
            Self::Hover { position, roll } => ReferenceSample {
                t,
                position: Vector3::from(*position),
                velocity: Vector3::zeros(),
                acceleration: Vector3::zeros(),
                rotation: rot_x(*roll),
                omega: Vector3::zeros(),
                omega_dot: Vector3::zeros(),
                roll: *roll,
                roll_rate: 0.0,
            },
            Self::Step(s) => s.at(t),
            Self::Sine(s) => s.at(t),
            Self::FigureEight(f) => f.at(t),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paper_values() {
        let p = PaperTilt::default();
        assert_eq!(p.at(0.0).position, Vector3::zeros());
        assert!((p.at(1.0).position.z - 0.75).abs() < 1e-12);
        assert!((p.at(2.0).position.z - 1.5).abs() < 1e-12);
        assert!((p.at(7.0).roll - PI / 3.0).abs() < 1e-12);
        assert!(p.at(4.0).roll.abs() < 1e-12 && p.at(10.0).roll.abs() < 1e-12);
        // phi_r(t) = (pi/6)(1 + cos((t - 7) pi / 3)).
        let t = 5.3;
        assert!((p.at(t).roll - (PI / 6.0) * (1.0 + ((t - 7.0) * PI / 3.0).cos())).abs() < 1e-12);
        assert!((p.at(13.0).position.z - 0.75).abs() < 1e-12);
        assert!(p.at(14.0).position.z.abs() < 1e-12 && p.at(16.0).position.z.abs() < 1e-12);
        assert_eq!(p.at(6.0).omega, Vector3::zeros());
    }

    /// A ramp is evaluated on `[t0, t1)`: its first instant carries the full feed-forward
    /// `a = (h/2)(pi/T)^2` (1.85 m/s^2 for paper-tilt), its end none.
    #[test]
    fn ramps_start_with_their_acceleration() {
        let p = PaperTilt::default();
        let a = 0.5 * 1.5 * (PI / 2.0) * (PI / 2.0);
        assert!((p.at(0.0).acceleration.z - a).abs() < 1e-12);
        assert!((p.at(12.0).acceleration.z + a).abs() < 1e-12);
        assert_eq!(p.at(12.0).position.z, 1.5);
        assert_eq!(p.at(14.0).acceleration.z, 0.0);
        assert_eq!(p.at(-0.01).acceleration.z, 0.0);
    }

    #[test]
    fn derivatives_match_finite_differences() {
        let p = PaperTilt::default();
        let h = 1e-5;
        for &t in &[0.3, 1.1, 1.9, 5.0, 12.4, 13.7] {
            let (a, b, c) = (p.at(t - h), p.at(t), p.at(t + h));
            let v_fd = (c.position - a.position) / (2.0 * h);
            let a_fd = (c.velocity - a.velocity) / (2.0 * h);
            assert!((v_fd - b.velocity).norm() < 1e-8, "t = {t}");
            assert!((a_fd - b.acceleration).norm() < 1e-7, "t = {t}");
            let r_fd = (c.roll - a.roll) / (2.0 * h);
            assert!((r_fd - b.roll_rate).abs() < 1e-8, "t = {t}");
        }
    }
}
