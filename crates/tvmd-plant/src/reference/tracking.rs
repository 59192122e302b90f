//! The authors' other flight tasks as references: a position step (reference jump), sine
//! tracking and a figure-eight, all at level attitude from a hover (`docs/method.md`,
//! "Scenario families").

use std::f64::consts::PI;

use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};

use super::ReferenceSample;

/// A level reference at `position` with its derivatives.
fn level(t: f64, p: Vector3<f64>, v: Vector3<f64>, a: Vector3<f64>) -> ReferenceSample {
    ReferenceSample {
        t,
        position: p,
        velocity: v,
        acceleration: a,
        rotation: Matrix3::identity(),
        omega: Vector3::zeros(),
        omega_dot: Vector3::zeros(),
        roll: 0.0,
        roll_rate: 0.0,
    }
}

/// The phase `phi(tau)` of a pattern of angular rate `w` that starts at rest: its rate rises as
/// `w (1 - cos(pi tau / T)) / 2` over the ramp `T`, then stays `w`. Returns `(phi, phi', phi'')`.
fn ramped_phase(tau: f64, w: f64, ramp: f64) -> (f64, f64, f64) {
    if tau <= 0.0 {
        return (0.0, 0.0, 0.0);
    }
    if tau >= ramp {
        return (w * (tau - 0.5 * ramp), w, 0.0);
    }
    let k = PI / ramp;
    let (s, c) = (k * tau).sin_cos();
    (
        0.5 * w * (tau - s / k),
        0.5 * w * (1.0 - c),
        0.5 * w * k * s,
    )
}

/// Position, velocity and acceleration of `p(phi(tau))` from `p`, `dp/dphi`, `d2p/dphi2`.
fn chain((phi, d, dd): (f64, f64, f64), p: impl Fn(f64) -> [Vector3<f64>; 3]) -> [Vector3<f64>; 3] {
    let [x, x1, x2] = p(phi);
    [x, x1 * d, x2 * (d * d) + x1 * dd]
}

/// A reference jump: hover at `initial`, then at `time` hover at `target` (a step, no
/// feed-forward: what the authors' jump test asks of the loop).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Step {
    /// Position before the jump (m); `[0, 0, 1.5]`.
    pub initial: [f64; 3],
    /// Position after it (m); `[0.5, 0, 1.5]`.
    pub target: [f64; 3],
    /// Time of the jump (s); 2.
    pub time: f64,
}

impl Default for Step {
    fn default() -> Self {
        Self {
            initial: [0.0, 0.0, 1.5],
            target: [0.5, 0.0, 1.5],
            time: 2.0,
        }
    }
}

impl Step {
    /// The reference at `t`.
    pub fn at(&self, t: f64) -> ReferenceSample {
        let p = if t < self.time {
            self.initial
        } else {
            self.target
        };
        level(t, Vector3::from(p), Vector3::zeros(), Vector3::zeros())
    }
}

/// Sine tracking: `x_r = c + A sin(phi)` per axis, `phi` the phase of `2 pi f` from `start` on,
/// its rate ramped up from zero over `ramp` so the reference starts at rest at `c`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Sine {
    /// Centre `c` (m); `[0, 0, 1.5]`.
    pub center: [f64; 3],
    /// Amplitude `A` per axis (m); `[0.5, 0, 0]`.
    pub amplitude: [f64; 3],
    /// Frequency `f` (Hz); 0.2.
    pub frequency: f64,
    /// Start (s); 1.
    pub start: f64,
    /// Time over which the phase rate rises to `2 pi f` (s); 2.
    pub ramp: f64,
}

impl Default for Sine {
    fn default() -> Self {
        Self {
            center: [0.0, 0.0, 1.5],
            amplitude: [0.5, 0.0, 0.0],
            frequency: 0.2,
            start: 1.0,
            ramp: 2.0,
        }
    }
}

impl Sine {
    /// The reference at `t`.
    pub fn at(&self, t: f64) -> ReferenceSample {
        let c = Vector3::from(self.center);
        let a = Vector3::from(self.amplitude);
        let phase = ramped_phase(t - self.start, 2.0 * PI * self.frequency, self.ramp);
        let [p, v, acc] = chain(phase, |phi| {
            let (s, co) = phi.sin_cos();
            [c + a * s, a * co, -a * s]
        });
        level(t, p, v, acc)
    }
}

/// A figure-eight (the 1:2 Lissajous curve) in the horizontal plane through `center`:
/// `x_r = c + [a sin(phi), (a/2) sin(2 phi), 0]`, `phi` the phase of `2 pi / period` from
/// `start` on, its rate ramped up from zero over `ramp` so the reference starts at rest at `c`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct FigureEight {
    /// Centre (m); `[0, 0, 1.5]`.
    pub center: [f64; 3],
    /// Half-width `a` along x (m); 1.
    pub size: f64,
    /// Period of one eight (s); 10.
    pub period: f64,
    /// Start (s); 1.
    pub start: f64,
    /// Time over which the phase rate rises to `2 pi / period` (s); 2.
    pub ramp: f64,
}

impl Default for FigureEight {
    fn default() -> Self {
        Self {
            center: [0.0, 0.0, 1.5],
            size: 1.0,
            period: 10.0,
            start: 1.0,
            ramp: 2.0,
        }
    }
}

impl FigureEight {
    /// The reference at `t`.
    pub fn at(&self, t: f64) -> ReferenceSample {
        let c = Vector3::from(self.center);
        let a = self.size;
        let phase = ramped_phase(t - self.start, 2.0 * PI / self.period, self.ramp);
        let [p, v, acc] = chain(phase, |phi| {
            let (s1, c1) = phi.sin_cos();
            let (s2, c2) = (2.0 * phi).sin_cos();
            [
                c + Vector3::new(a * s1, 0.5 * a * s2, 0.0),
                Vector3::new(a * c1, a * c2, 0.0),
                Vector3::new(-a * s1, -2.0 * a * s2, 0.0),
            ]
        });
        level(t, p, v, acc)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check_derivatives(f: impl Fn(f64) -> ReferenceSample, times: &[f64]) {
        let h = 1e-5;
        for &t in times {
            let (a, b, c) = (f(t - h), f(t), f(t + h));
            let v = (c.position - a.position) / (2.0 * h);
            let acc = (c.velocity - a.velocity) / (2.0 * h);
            assert!((v - b.velocity).norm() < 1e-7, "t = {t}");
            assert!((acc - b.acceleration).norm() < 1e-6, "t = {t}");
        }
    }

    #[test]
    fn tracking_references_and_their_derivatives() {
        let s = Sine::default();
        assert_eq!(s.at(0.5).position, Vector3::new(0.0, 0.0, 1.5));
        // At rest at the start; after the ramp (2 s) the phase lags by w T / 2 = 0.4 pi, so
        // the peak comes a quarter period later than an unramped sine's: at t = 1 + 1 + 1.25.
        assert_eq!(s.at(1.0).velocity, Vector3::zeros());
        assert!((s.at(3.25).position.x - 0.5).abs() < 1e-12);
        assert!((s.at(5.0).velocity.x - 0.5 * 0.4 * PI * (0.4 * PI * 3.0).cos()).abs() < 1e-12);
        check_derivatives(|t| s.at(t), &[1.3, 2.7, 5.1]);
        let e = FigureEight::default();
        assert_eq!(e.at(1.0).velocity, Vector3::zeros());
        // After the ramp the phase is w (tau - 1): a quarter period (2.5 s) later, x = a.
        let q = e.at(1.0 + 1.0 + 2.5).position;
        assert!((q.x - 1.0).abs() < 1e-12 && q.y.abs() < 1e-12 && q.z == 1.5);
        // The eight crosses its centre every half period.
        assert!((e.at(7.0).position - Vector3::new(0.0, 0.0, 1.5)).norm() < 1e-12);
        check_derivatives(|t| e.at(t), &[1.3, 2.6, 4.0, 8.8]);
        let j = Step::default();
        assert_eq!(j.at(1.99).position.x, 0.0);
        assert_eq!(j.at(2.0).position.x, 0.5);
        assert_eq!(j.at(3.0).velocity, Vector3::zeros());
    }
}
