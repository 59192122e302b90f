//! `[disturbances.air]`: wind as air velocity (constant, plus gusts, plus Dryden turbulence)
//! acting on the team through a quadratic drag model (`docs/method.md`, "Scenario families").

use serde::{Deserialize, Serialize};
use tvmd_plant::turbulence::{Turbulence, MIN_SPEED};

use crate::checks::{check_magnitude, check_nonneg, check_pos, check_range};
use crate::error::invalid;
use crate::ScenarioError;

/// Largest wind or gust speed (m/s).
pub const MAX_WIND_SPEED: f64 = 100.0;

/// A `1 - cos` gust: the air velocity rises from zero to `velocity` at mid-gust and back to
/// zero over `duration`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Gust {
    /// Start time (s).
    pub start: f64,
    /// Length (s).
    pub duration: f64,
    /// Peak air velocity added, world frame (m/s).
    pub velocity: [f64; 3],
}

impl Gust {
    /// The gust's air velocity at `t`: `(v / 2)(1 - cos(2 pi (t - start) / duration))` inside
    /// its window, zero outside.
    pub fn at(&self, t: f64) -> [f64; 3] {
        let tau = (t - self.start) / self.duration;
        if !(0.0..=1.0).contains(&tau) {
            return [0.0; 3];
        }
        let k = 0.5 * (1.0 - (2.0 * std::f64::consts::PI * tau).cos());
        self.velocity.map(|v| k * v)
    }
}

/// Wind on the team: the air moves at `velocity` plus the gusts plus the turbulence (carried
/// past the team by `velocity`), and the team feels the drag
/// `F = (rho / 2) C_d A |w - v| (w - v)` through its centre of mass (`w`: air velocity, `v`: the
/// team's), world frame.
///
/// ```toml
/// [disturbances.air]
/// velocity = [3.0, 0.0, 0.0]  # m/s
/// drag_area = 0.2             # C_d A (m^2); default 0.05 per agent
/// gusts = [{ start = 5.0, duration = 2.0, velocity = [0.0, 3.0, 0.0] }]
/// turbulence = { wind_speed_20ft = 7.72, altitude = 1.5, seed = 0 }  # Dryden, MIL-F-8785C
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Air {
    /// Steady air velocity, world frame (m/s).
    pub velocity: [f64; 3],
    /// Gusts on top of it.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub gusts: Vec<Gust>,
    /// Dryden turbulence on top ([`Turbulence`]); needs a steady `velocity` of at least
    /// [`MIN_SPEED`] to carry the frozen field past the team.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub turbulence: Option<Turbulence>,
    /// Drag area `C_d A` of the whole team (m^2), the same in every direction; none:
    /// [`DRAG_AREA_PER_AGENT`] per agent.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub drag_area: Option<f64>,
    /// Air density `rho` (kg/m^3); 1.225 (sea level).
    pub density: f64,
}

/// Default drag area per agent (m^2): a drag coefficient of about 1 on the frontal area of one
/// coaxial agent with its arm and gimbal (about 0.05 m^2). A rough figure for the paper's
/// 0.7 kg agents; give `drag_area` for a measured team.
pub const DRAG_AREA_PER_AGENT: f64 = 0.05;

impl Default for Air {
    fn default() -> Self {
        Self {
            velocity: [0.0; 3],
            gusts: Vec::new(),
            turbulence: None,
            drag_area: None,
            density: 1.225,
        }
    }
}

impl Air {
    /// The air velocity at `t` (m/s).
    pub fn velocity_at(&self, t: f64) -> [f64; 3] {
        let mut w = self.velocity;
        for g in &self.gusts {
            let d = g.at(t);
            for k in 0..3 {
                w[k] += d[k];
            }
        }
        if let Some(turbulence) = &self.turbulence {
            let d = turbulence.velocity_at(t, self.velocity);
            for k in 0..3 {
                w[k] += d[k];
            }
        }
        w
    }

    /// `C_d A` for a team of `n` agents (m^2).
    pub fn drag_area(&self, n: usize) -> f64 {
        self.drag_area.unwrap_or(DRAG_AREA_PER_AGENT * n as f64)
    }

    /// The drag force (N, world frame) at `t` on a team of `n` agents moving at `v` (m/s).
    pub fn force(&self, t: f64, v: [f64; 3], n: usize) -> [f64; 3] {
        let w = self.velocity_at(t);
        let rel = [w[0] - v[0], w[1] - v[1], w[2] - v[2]];
        let speed = rel.iter().map(|x| x * x).sum::<f64>().sqrt();
        let k = 0.5 * self.density * self.drag_area(n) * speed;
        rel.map(|x| k * x)
    }

    /// Checks the values.
    pub fn validate(&self) -> Result<(), ScenarioError> {
        const F: &str = "disturbances.air";
        check_magnitude(&format!("{F}.velocity"), &self.velocity, MAX_WIND_SPEED)?;
        if let Some(a) = self.drag_area {
            check_nonneg(&format!("{F}.drag_area"), &[a])?;
            if a > 100.0 {
                return Err(invalid(
                    format!("{F}.drag_area"),
                    format!("{a} m^2 above 100 m^2"),
                ));
            }
        }
        check_range(&format!("{F}.density"), self.density, 0.0, 10.0)?;
        for (i, g) in self.gusts.iter().enumerate() {
            let f = format!("{F}.gusts[{i}]");
            check_nonneg(&format!("{f}.start"), &[g.start])?;
            check_pos(&format!("{f}.duration"), g.duration)?;
            check_magnitude(&format!("{f}.velocity"), &g.velocity, MAX_WIND_SPEED)?;
        }
        if let Some(t) = &self.turbulence {
            let f = format!("{F}.turbulence");
            check_range(
                &format!("{f}.wind_speed_20ft"),
                t.wind_speed_20ft,
                0.0,
                50.0,
            )?;
            check_range(&format!("{f}.altitude"), t.altitude, 0.0, 304.8)?;
            check_range(&format!("{f}.scale"), t.scale, 0.0, 10.0)?;
            let speed = self.velocity.iter().map(|v| v * v).sum::<f64>().sqrt();
            if speed < MIN_SPEED {
                return Err(invalid(
                    f,
                    format!(
                        "the frozen turbulence field is carried past the team by the steady wind: \
                         give `{F}.velocity` of at least {MIN_SPEED} m/s (it is {speed} m/s)"
                    ),
                ));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn drag_opposes_the_relative_air_and_grows_with_its_square() {
        let air = Air {
            velocity: [2.0, 0.0, 0.0],
            drag_area: Some(0.2),
            ..Air::default()
        };
        // Still team in 2 m/s: (1.225 / 2) 0.2 * 4 = 0.49 N downwind.
        let f = air.force(0.0, [0.0; 3], 4);
        assert!(
            (f[0] - 0.49).abs() < 1e-12 && f[1] == 0.0 && f[2] == 0.0,
            "{f:?}"
        );
        // Moving with the air: no drag; twice as fast against it: four times the drag.
        assert_eq!(air.force(0.0, [2.0, 0.0, 0.0], 4), [0.0; 3]);
        let g = air.force(0.0, [-2.0, 0.0, 0.0], 4);
        assert!((g[0] - 4.0 * 0.49).abs() < 1e-12);
        // Default area: 0.05 m^2 per agent.
        assert!((Air::default().drag_area(6) - 0.3).abs() < 1e-15);
    }

    #[test]
    fn a_gust_rises_and_falls_inside_its_window() {
        let g = Gust {
            start: 1.0,
            duration: 2.0,
            velocity: [0.0, 3.0, 0.0],
        };
        assert_eq!(g.at(0.5), [0.0; 3]);
        assert!((g.at(2.0)[1] - 3.0).abs() < 1e-12);
        assert!(g.at(1.5)[1] > 0.0 && g.at(1.5)[1] < 3.0);
        assert!(g.at(3.0)[1].abs() < 1e-12 && g.at(3.5) == [0.0; 3]);
        let air = Air {
            gusts: vec![g],
            ..Air::default()
        };
        assert!((air.velocity_at(2.0)[1] - 3.0).abs() < 1e-12);
        let bad = Air {
            gusts: vec![Gust { duration: 0.0, ..g }],
            ..Air::default()
        };
        let e = bad.validate().unwrap_err().to_string();
        assert!(e.contains("disturbances.air.gusts[0].duration"), "{e}");
    }

    #[test]
    fn turbulence_rides_on_the_steady_wind_and_needs_one() {
        let calm = Air {
            turbulence: Some(Turbulence::default()),
            ..Air::default()
        };
        let e = calm.validate().unwrap_err().to_string();
        assert!(
            e.contains("disturbances.air.turbulence") && e.contains("velocity"),
            "{e}"
        );
        let windy = Air {
            velocity: [3.0, 0.0, 0.0],
            ..calm.clone()
        };
        windy.validate().unwrap();
        // The air moves about the steady wind, not at it.
        let mut sum = [0.0; 3];
        let mut differs = false;
        for i in 0..20_000 {
            let w = windy.velocity_at(i as f64 * 0.05);
            differs |= w != windy.velocity;
            for k in 0..3 {
                sum[k] += w[k] / 20_000.0;
            }
        }
        assert!(differs);
        assert!((sum[0] - 3.0).abs() < 0.3 && sum[1].abs() < 0.3 && sum[2].abs() < 0.3);
        let strong = Air {
            turbulence: Some(Turbulence {
                wind_speed_20ft: 80.0,
                ..Turbulence::default()
            }),
            ..windy
        };
        let e = strong.validate().unwrap_err().to_string();
        assert!(e.contains("turbulence.wind_speed_20ft"), "{e}");
    }
}
