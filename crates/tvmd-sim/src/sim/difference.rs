//! The largest difference between two flights of one scenario sampled at the same ticks (e.g.
//! the f32 and the f64 controller flying `paper-tilt`): [`FlightDifference`].

use nalgebra::Rotation3;
use serde::Serialize;

use crate::sim::sample::Sample;

/// Largest differences between two flights over every matching sample.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct FlightDifference {
    /// Samples compared.
    pub samples: usize,
    /// Largest `||x_a - x_b||` (m).
    pub position: f64,
    /// Largest angle of `R_a^T R_b` (rad).
    pub attitude: f64,
    /// Largest `|eta_x|` or `|eta_y|` difference of a commanded gimbal angle, any agent (rad).
    pub gimbal: f64,
    /// Largest commanded-thrust difference, any agent (N).
    pub thrust: f64,
    /// Time of the largest position difference (s).
    pub position_time: f64,
    /// Time of the largest thrust difference (s).
    pub thrust_time: f64,
}

fn rotation(s: &Sample) -> nalgebra::Matrix3<f64> {
    let [roll, pitch, yaw] = s.roll_pitch_yaw;
    Rotation3::from_euler_angles(roll, pitch, yaw).into_inner()
}

/// The angle of `R_a^T R_b` from `||R_a - R_b||_F = 2 sqrt(2) sin(theta/2)`: unlike the acos
/// of the trace it resolves the tiny angles a precision comparison is about.
fn rotation_angle(a: &nalgebra::Matrix3<f64>, b: &nalgebra::Matrix3<f64>) -> f64 {
    let half_sine = (a - b).norm() / (2.0 * std::f64::consts::SQRT_2);
    2.0 * half_sine.min(1.0).asin()
}

fn distance(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y) * (x - y))
        .sum::<f64>()
        .sqrt()
}

impl FlightDifference {
    /// The differences between flights `a` and `b`; `None` unless they have the same number
    /// of samples at the same times (within 1 ns) with the same number of agents.
    pub fn between(a: &[Sample], b: &[Sample]) -> Option<Self> {
        if a.len() != b.len() {
            return None;
        }
        let mut d = Self {
            samples: a.len(),
            ..Self::default()
        };
        for (x, y) in a.iter().zip(b) {
            if (x.t - y.t).abs() > 1e-9 || x.commands.len() != y.commands.len() {
                return None;
            }
            let position = distance(&x.position, &y.position);
            if position > d.position {
                d.position = position;
                d.position_time = x.t;
            }
            d.attitude = d.attitude.max(rotation_angle(&rotation(x), &rotation(y)));
            for (p, q) in x.commands.iter().zip(&y.commands) {
                d.gimbal = d
                    .gimbal
                    .max((p.eta_x - q.eta_x).abs())
                    .max((p.eta_y - q.eta_y).abs());
                let thrust = (p.thrust - q.thrust).abs();
                if thrust > d.thrust {
                    d.thrust = thrust;
                    d.thrust_time = x.t;
                }
            }
        }
        Some(d)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use tvmd_plant::math::rot_x;

    #[test]
    fn rotation_angle_resolves_small_and_large_angles() {
        for angle in [1e-9, 1e-4, 0.3, 3.0] {
            let got = rotation_angle(&rot_x(0.2), &rot_x(0.2 + angle));
            assert!(
                (got - angle).abs() < 1e-12 * angle.max(1.0),
                "{angle}: {got}"
            );
        }
    }
}
