//! The support function of one agent's exact admissible force set
//! `E = { T a_hat(eta_x, eta_y) : T in [T_lo, T_hi], |eta_x| <= sigma_x, |eta_y| <= sigma_y }`
//! (eqs. 1 and 6), in closed form: `h(c) = max_{f in E} c . f` and a maximizer.

use nalgebra::Vector3;
use tvmd_core::GimbalCommand;

/// One agent's admissible box (agent frame).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AgentBox {
    /// `T_lo`, the idle thrust (N).
    pub min_thrust: f64,
    /// `T_hi = sigma_Tf` (N).
    pub max_thrust: f64,
    /// `sigma_x` (rad), at most `pi/2`.
    pub sigma_x: f64,
    /// `sigma_y` (rad), at most `pi/2`.
    pub sigma_y: f64,
}

impl AgentBox {
    /// Clamps a command into the box.
    pub fn clamp(&self, cmd: GimbalCommand<f64>) -> GimbalCommand<f64> {
        GimbalCommand {
            thrust: cmd.thrust.clamp(self.min_thrust, self.max_thrust),
            eta_x: cmd.eta_x.clamp(-self.sigma_x, self.sigma_x),
            eta_y: cmd.eta_y.clamp(-self.sigma_y, self.sigma_y),
        }
    }

    /// Whether `cmd` lies in the box (to `tol` in each coordinate).
    pub fn contains(&self, cmd: &GimbalCommand<f64>, tol: f64) -> bool {
        cmd.thrust >= self.min_thrust - tol
            && cmd.thrust <= self.max_thrust + tol
            && cmd.eta_x.abs() <= self.sigma_x + tol
            && cmd.eta_y.abs() <= self.sigma_y + tol
    }
}

/// `h(c) = max_{f in E} c . f` and the command that attains it.
///
/// With `cos(eta_x) >= 0` on the box, `c . a_hat = cos(eta_x) G(eta_y) - c_y sin(eta_x)` with
/// `G(eta_y) = c_x sin(eta_y) + c_z cos(eta_y)`, so the best `eta_y` maximizes `G` alone (the
/// clamp of `atan2(c_x, c_z)`, the nearer end of the symmetric interval when outside), then the
/// best `eta_x` is the clamp of `atan2(-c_y, G)`; the thrust is `T_hi` for a positive value and
/// `T_lo` otherwise. Exact up to rounding: no sampling.
pub fn support(c: &Vector3<f64>, b: &AgentBox) -> (f64, GimbalCommand<f64>) {
    let eta_y = c.x.atan2(c.z).clamp(-b.sigma_y, b.sigma_y);
    let g = c.x * eta_y.sin() + c.z * eta_y.cos();
    let eta_x = (-c.y).atan2(g).clamp(-b.sigma_x, b.sigma_x);
    let unit = g * eta_x.cos() - c.y * eta_x.sin();
    let thrust = if unit > 0.0 {
        b.max_thrust
    } else {
        b.min_thrust
    };
    (
        thrust * unit,
        GimbalCommand {
            thrust,
            eta_x,
            eta_y,
        },
    )
}

/// The maximizer over `[lo, hi]` (an interval inside `(-pi, pi)` no longer than `pi`) of
/// `R cos(eta - phi)`, `phi = atan2(s, c)`: `phi` clamped into the interval, or the better end.
fn best_angle(s: f64, c: f64, lo: f64, hi: f64) -> f64 {
    let value = |eta: f64| s * eta.sin() + c * eta.cos();
    let clamped = s.atan2(c).clamp(lo, hi);
    [lo, hi].into_iter().fold(
        clamped,
        |best, end| if value(end) > value(best) { end } else { best },
    )
}

/// [`support`] of the plant as built with gimbal offsets `d`: `max c . (T a_hat(eta + d))`
/// over the commanded box, and the command (not the offset angles) that attains it. The true
/// angles range over `[-sigma + d, sigma + d]`, no longer symmetric, so each angle is the
/// better of the clamped stationary point and the interval's ends (exact: on an interval
/// shorter than `pi`, `R cos(eta - phi)` peaks at `phi` or at an end). Needs
/// `sigma_x + |d_x| <= pi/2` (then `cos(eta_x) >= 0` and the angles separate as in
/// [`support`]).
pub fn support_shifted(c: &Vector3<f64>, b: &AgentBox, d: [f64; 2]) -> (f64, GimbalCommand<f64>) {
    let eta_y = best_angle(c.x, c.z, -b.sigma_y + d[1], b.sigma_y + d[1]);
    let g = c.x * eta_y.sin() + c.z * eta_y.cos();
    let eta_x = best_angle(-c.y, g, -b.sigma_x + d[0], b.sigma_x + d[0]);
    let unit = g * eta_x.cos() - c.y * eta_x.sin();
    let thrust = if unit > 0.0 {
        b.max_thrust
    } else {
        b.min_thrust
    };
    (
        thrust * unit,
        GimbalCommand {
            thrust,
            // Clamped: `eta - d` can round a last bit outside the box.
            eta_x: (eta_x - d[0]).clamp(-b.sigma_x, b.sigma_x),
            eta_y: (eta_y - d[1]).clamp(-b.sigma_y, b.sigma_y),
        },
    )
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn paper_box(min_thrust: f64) -> AgentBox {
        AgentBox {
            min_thrust,
            max_thrust: 13.734,
            sigma_x: std::f64::consts::FRAC_PI_6,
            sigma_y: std::f64::consts::FRAC_PI_4,
        }
    }

    /// With gimbal offsets the closed form is still the maximum of a dense sampling of the
    /// (commanded) box, and attained by its command.
    #[test]
    fn shifted_support_is_the_maximum_over_a_dense_grid() {
        let mut rng = ChaCha8Rng::seed_from_u64(8);
        let b = paper_box(0.0);
        for _ in 0..200 {
            let c = Vector3::new(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
            );
            let d = [rng.random_range(-0.3..0.3), rng.random_range(-0.3..0.3)];
            let true_force = |cmd: &GimbalCommand<f64>| {
                GimbalCommand {
                    thrust: cmd.thrust,
                    eta_x: cmd.eta_x + d[0],
                    eta_y: cmd.eta_y + d[1],
                }
                .force()
            };
            let (h, cmd) = support_shifted(&c, &b, d);
            assert!(b.contains(&cmd, 0.0));
            assert!((c.dot(&true_force(&cmd)) - h).abs() < 1e-12);
            let k = 60;
            let mut best = f64::NEG_INFINITY;
            for i in 0..=k {
                for j in 0..=k {
                    let cmd = GimbalCommand {
                        thrust: b.max_thrust,
                        eta_x: -b.sigma_x + 2.0 * b.sigma_x * i as f64 / k as f64,
                        eta_y: -b.sigma_y + 2.0 * b.sigma_y * j as f64 / k as f64,
                    };
                    best = best.max(c.dot(&true_force(&cmd)).max(0.0));
                }
            }
            assert!(best <= h + 1e-12, "{c} {d:?}: grid {best} > {h}");
            assert!(
                h - best < 0.02 * b.max_thrust * c.norm(),
                "{c}: {h} vs {best}"
            );
        }
        // No offset: the symmetric closed form.
        let c = Vector3::new(0.3, -0.2, 0.9);
        assert_eq!(support_shifted(&c, &b, [0.0; 2]).0, support(&c, &b).0);
    }

    /// The closed form is the maximum of a dense sampling of the box, and attained.
    #[test]
    fn support_is_the_maximum_over_a_dense_grid() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        for min_thrust in [0.0, 2.0] {
            let b = paper_box(min_thrust);
            for _ in 0..200 {
                let c = Vector3::new(
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                );
                let (h, cmd) = support(&c, &b);
                assert!(b.contains(&cmd, 0.0));
                assert!((c.dot(&cmd.force()) - h).abs() < 1e-12);
                let mut best = f64::NEG_INFINITY;
                let k = 60;
                for i in 0..=k {
                    for j in 0..=k {
                        let ex = -b.sigma_x + 2.0 * b.sigma_x * i as f64 / k as f64;
                        let ey = -b.sigma_y + 2.0 * b.sigma_y * j as f64 / k as f64;
                        for thrust in [b.min_thrust, b.max_thrust] {
                            let f = GimbalCommand {
                                thrust,
                                eta_x: ex,
                                eta_y: ey,
                            }
                            .force();
                            best = best.max(c.dot(&f));
                        }
                    }
                }
                // The grid never beats the closed form and comes within its spacing.
                assert!(best <= h + 1e-12, "{c}: grid {best} > {h}");
                assert!(
                    h - best < 0.02 * b.max_thrust * c.norm(),
                    "{c}: {h} vs {best}"
                );
            }
        }
    }
}
