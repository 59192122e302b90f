//! A ray `w(t) = origin + t direction` in wrench space (rows `[torque; force]`), and the
//! bracket of its farthest attainable point: an attained inner point and a weak-duality outer
//! bound.

use nalgebra::Vector6;
use tvmd_core::GimbalCommand;

/// `w(t) = origin + t direction`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    /// `w(0)`.
    pub origin: Vector6<f64>,
    /// The direction (unit norm).
    pub direction: Vector6<f64>,
}

impl Ray {
    /// The point at `t`.
    pub fn at(&self, t: f64) -> Vector6<f64> {
        self.origin + self.direction * t
    }

    /// The `t` of the point of the ray nearest `w`.
    pub fn parameter(&self, w: &Vector6<f64>) -> f64 {
        (w - self.origin).dot(&self.direction)
    }
}

/// Bounds on the farthest attainable `t` along a ray.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bracket {
    /// The largest `t` attained by a command found (`None`: the origin itself was not attained).
    pub lower: Option<f64>,
    /// An upper bound of every attainable `t` (weak duality: exact for the convex hull's
    /// support when the multiplier is optimal).
    pub upper: f64,
}

impl Bracket {
    /// `upper - lower` (infinite without a lower bound).
    pub fn width(&self) -> f64 {
        self.lower.map_or(f64::INFINITY, |l| self.upper - l)
    }
}

/// A ray's bracket with its certificates.
#[derive(Clone, Debug)]
pub struct RayBound {
    /// The bracket.
    pub bracket: Bracket,
    /// The commands attaining `bracket.lower`.
    pub commands: Option<Vec<GimbalCommand<f64>>>,
    /// The multiplier `y` (with `y . direction = 1`) whose dual value is `bracket.upper`.
    pub multiplier: Vector6<f64>,
}
