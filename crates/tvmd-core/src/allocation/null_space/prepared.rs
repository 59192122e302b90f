//! A [`NullSpaceObjective`] prepared for one request: its value, gradient and margins (cargo
//! feature `null-space`).

use nalgebra::Vector3;

use super::super::exact_boundary::constraint::{constraints, Constraint, CONSTRAINTS};
use super::NullSpaceObjective;
use crate::agent::admissible::AdmissibleSet;
use crate::agent::effectiveness::Effectiveness;
use crate::foundation::linalg::norm;
use crate::foundation::real::{count, eps, lit, Real};

/// Sharpness `kappa` of the soft minimum of the margins (margins are fractions of a range, so
/// `1 / kappa = 1/32` is the scale below which a difference of margins counts as "the same").
const KAPPA: f64 = 32.0;

/// The objective prepared for one request: each working agent's constraints, the ranges that
/// normalize them, and its tilt target.
pub(super) struct Prepared<T: Real, const N: usize> {
    objective: NullSpaceObjective<T>,
    working: [bool; N],
    bounds: [[Constraint<T>; CONSTRAINTS]; N],
    /// `w_k` per constraint (gimbal: a range of `sin`; thrust: `T_max - T_min`); zero drops it.
    ranges: [[T; CONSTRAINTS]; N],
    targets: [Vector3<T>; N],
}

impl<T: Real, const N: usize> Prepared<T, N> {
    pub(super) fn new(
        objective: NullSpaceObjective<T>,
        effectiveness: &Effectiveness<T, N>,
        sets: &[AdmissibleSet<T>; N],
        working: [bool; N],
    ) -> Self {
        let bounds = super::super::exact_boundary::per_set(sets, |s| constraints(s));
        let ranges = super::super::exact_boundary::per_set(sets, ranges);
        let angle = match objective {
            NullSpaceObjective::InwardTilt { angle } => angle,
            NullSpaceObjective::Margin => T::zero(),
        };
        let targets = effectiveness
            .blocks()
            .each_ref()
            .map(|b| b.as_ref().map_or(Vector3::z(), |b| tilt_target(b, angle)));
        Self {
            objective,
            working,
            bounds,
            ranges,
            targets,
        }
    }

    /// The objective's value (higher is better).
    pub(super) fn value(&self, forces: &[Vector3<T>; N]) -> T {
        match self.objective {
            NullSpaceObjective::Margin => self.soft_min(forces, None),
            NullSpaceObjective::InwardTilt { .. } => self.alignment(forces, None),
        }
    }

    /// Its gradient with respect to every agent's force (zero for failed agents).
    pub(super) fn gradient(&self, forces: &[Vector3<T>; N]) -> [Vector3<T>; N] {
        let mut g = [Vector3::zeros(); N];
        match self.objective {
            NullSpaceObjective::Margin => self.soft_min(forces, Some(&mut g)),
            NullSpaceObjective::InwardTilt { .. } => self.alignment(forces, Some(&mut g)),
        };
        g
    }

    /// The smallest normalized margin `h_j` over the working agents (see
    /// [`NullSpaceObjective::Margin`]); `1` when no limit counts.
    pub(super) fn smallest_margin(&self, forces: &[Vector3<T>; N]) -> T {
        let mut least = T::one();
        self.each_margin(forces, |_, _, h, _| least = least.min(h));
        least
    }

    /// Bit `k` of entry `i`: agent `i`'s margin to constraint `k` is below `1 / kappa` (near
    /// enough that a step is kept from crossing it, see [`super::NullSpaceStage`]).
    pub(super) fn near(&self, forces: &[Vector3<T>; N]) -> [u8; N] {
        let near: T = T::one() / lit(KAPPA);
        let mut bits = [0u8; N];
        self.each_margin(forces, |i, k, h, _| {
            if let Some(b) = bits.get_mut(i) {
                if h < near && k < 8 {
                    *b |= 1 << k;
                }
            }
        });
        bits
    }

    /// Calls `visit(agent, constraint, h, grad h)` for every counted limit of every working agent.
    fn each_margin(
        &self,
        forces: &[Vector3<T>; N],
        mut visit: impl FnMut(usize, usize, T, Vector3<T>),
    ) {
        for (i, (((f, b), r), w)) in forces
            .iter()
            .zip(&self.bounds)
            .zip(&self.ranges)
            .zip(&self.working)
            .enumerate()
        {
            if !*w {
                continue;
            }
            let length = norm(f);
            for (k, (c, range)) in b.iter().zip(r).enumerate() {
                if *range <= T::zero() {
                    continue;
                }
                if k >= 4 {
                    // Thrust: `h = -g / range`, `g` linear in `||f||`.
                    visit(i, k, -c.value(f) / *range, -c.gradient(f) / *range);
                } else if length > T::zero() {
                    // Gimbal: `g` is homogeneous of degree one, so `-g / ||f||` is an angle's
                    // function; `grad (g / ||f||) = grad g / ||f|| - g f / ||f||^3`.
                    let g = c.value(f);
                    let scale = length * *range;
                    let grad = (c.gradient(f) - f * (g / (length * length))) / scale;
                    visit(i, k, -g / scale, -grad);
                } else {
                    // No force, no gimbal direction: the idle gimbal's margin, no gradient.
                    visit(i, k, -c.value(&Vector3::z()) / *range, Vector3::zeros());
                }
            }
        }
    }

    /// `-(1/kappa) ln sum exp(-kappa h_j)`, written around the smallest `h` so no exponential
    /// overflows; its gradient `sum_j softmax_j grad h_j` into `grad` when asked.
    fn soft_min(&self, forces: &[Vector3<T>; N], grad: Option<&mut [Vector3<T>; N]>) -> T {
        let kappa: T = lit(KAPPA);
        let least = self.smallest_margin(forces);
        let mut sum = T::zero();
        self.each_margin(forces, |_, _, h, _| sum += (-(h - least) * kappa).exp());
        if let Some(grad) = grad {
            if sum > T::zero() {
                self.each_margin(forces, |i, _, h, dh| {
                    if let Some(slot) = grad.get_mut(i) {
                        *slot += dh * ((-(h - least) * kappa).exp() / sum);
                    }
                });
            }
        }
        if sum > T::zero() {
            least - sum.ln() / kappa
        } else {
            least
        }
    }

    /// Mean `cos` of the angle between each thrusting agent's force and its target; its
    /// gradient `(t - (f_hat . t) f_hat) / (||f|| n)` into `grad` when asked. `1` when no agent
    /// thrusts.
    fn alignment(&self, forces: &[Vector3<T>; N], grad: Option<&mut [Vector3<T>; N]>) -> T {
        let thrusting = forces
            .iter()
            .zip(&self.working)
            .filter(|(f, w)| **w && norm(*f) > T::zero())
            .count();
        if thrusting == 0 {
            return T::one();
        }
        let n = count::<T>(thrusting);
        let mut sum = T::zero();
        let mut grad = grad;
        for (i, ((f, t), w)) in forces
            .iter()
            .zip(&self.targets)
            .zip(&self.working)
            .enumerate()
        {
            let length = norm(f);
            if !*w || length <= T::zero() {
                continue;
            }
            let unit = f / length;
            let cos = unit.dot(t);
            sum += cos;
            if let Some(slot) = grad.as_deref_mut().and_then(|g| g.get_mut(i)) {
                *slot = (t - unit * cos) / (length * n);
            }
        }
        sum / n
    }
}

/// `w_k` of each constraint of `set`, in the order of [`constraints`]; zero for a limit that
/// cannot bind (no idle thrust) or a range too narrow to normalize by.
fn ranges<T: Real>(set: &AdmissibleSet<T>) -> [T; CONSTRAINTS] {
    let (ex, ey, th) = (set.eta_x(), set.eta_y(), set.thrust());
    let floor = eps::<T>().sqrt();
    let keep = |w: T| if w > floor { w } else { T::zero() };
    let sin_x = keep(ex.hi.sin() - ex.lo.sin());
    let sin_y = keep((ey.hi - ey.lo).min(T::frac_pi_2()).sin());
    let thrust = keep(th.hi - th.lo);
    let idle = if th.lo > T::zero() { thrust } else { T::zero() };
    [sin_x, sin_x, sin_y, sin_y, thrust, idle]
}

/// The agent-frame tilt target of a block `M_i = [[p_i]x R_i; R_i]` (eq. 4): `R_i^T` of
/// `cos(angle) z + sin(angle) u_i`, `u_i` the horizontal unit vector from `p_i` toward the origin
/// (the centre of mass).
fn tilt_target<T: Real>(block: &nalgebra::Matrix6x3<T>, angle: T) -> Vector3<T> {
    // Copied element by element: a view's `into_owned` goes through nalgebra's
    // `from_iterator`, whose length check the optimizer cannot drop (a panic path on the target).
    let rows = |first: usize| {
        nalgebra::Matrix3::from_fn(|i, j| {
            block.get((first + i, j)).copied().unwrap_or_else(T::zero)
        })
    };
    let rotation = rows(3);
    let skew = rows(0) * rotation.transpose();
    // `[p]x` holds `p` as (m32, m13, m21).
    let inward = Vector3::new(-skew.m32, -skew.m13, T::zero());
    let length = norm(&inward);
    let (s, c) = angle.sin_cos();
    let team = if length > eps::<T>() {
        Vector3::z() * c + inward * (s / length)
    } else {
        Vector3::z()
    };
    rotation.tr_mul(&team)
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::indexing_slicing)]
    use super::*;
    use crate::agent::gimbal::GimbalCommand;
    use crate::agent::limits::Interval;

    fn set() -> AdmissibleSet<f64> {
        AdmissibleSet::new(
            Interval { lo: -0.5, hi: 0.5 },
            Interval { lo: -0.4, hi: 0.6 },
            Interval { lo: 1.0, hi: 11.0 },
        )
        .unwrap()
    }

    fn one_agent(position: Vector3<f64>, quarter_turns: i32) -> Effectiveness<f64, 1> {
        Effectiveness::new([(0, &position, quarter_turns)])
    }

    fn prepared(objective: NullSpaceObjective<f64>, e: &Effectiveness<f64, 1>) -> Prepared<f64, 1> {
        Prepared::new(objective, e, &[set()], [true])
    }

    #[test]
    fn margins_are_fractions_of_each_range() {
        let e = one_agent(Vector3::new(0.3, 0.0, 0.0), 0);
        let p = prepared(NullSpaceObjective::Margin, &e);
        let at = |thrust, eta_x, eta_y| {
            let f = GimbalCommand {
                thrust,
                eta_x,
                eta_y,
            }
            .force();
            let mut hs = [0.0; 6];
            let mut k = 0;
            p.each_margin(&[f], |_, _, h, _| {
                hs[k] = h;
                k += 1;
            });
            assert_eq!(k, 6);
            hs
        };
        let centre = at(6.0, 0.0, 0.1);
        // Thrust at mid-range: 0.5 from both ends.
        assert!((centre[4] - 0.5).abs() < 1e-12 && (centre[5] - 0.5).abs() < 1e-12);
        assert!((centre[0] - 0.5).abs() < 1e-12 && (centre[1] - 0.5).abs() < 1e-12);
        let edge = at(11.0, 0.5, 0.6);
        assert!(edge[0].abs() < 1e-12 && edge[2].abs() < 1e-12 && edge[4].abs() < 1e-12);
        assert!((edge[1] - 1.0).abs() < 1e-12);
        let f = GimbalCommand {
            thrust: 6.0,
            eta_x: 0.0,
            eta_y: 0.1,
        }
        .force();
        assert!((p.smallest_margin(&[f]) - 0.5).abs() < 1e-12);
        // The soft minimum lies just below the smallest margin.
        let soft = p.value(&[f]);
        assert!(soft < 0.5 && soft > 0.5 - 0.1, "{soft}");
    }

    #[test]
    fn gradients_match_finite_differences() {
        let e = one_agent(Vector3::new(0.3, -0.2, 0.05), 1);
        let f = [GimbalCommand {
            thrust: 7.0,
            eta_x: 0.2,
            eta_y: 0.3,
        }
        .force()];
        for objective in [
            NullSpaceObjective::Margin,
            NullSpaceObjective::InwardTilt { angle: 0.15 },
        ] {
            let p = prepared(objective, &e);
            let g = p.gradient(&f)[0];
            for axis in 0..3 {
                let mut step = Vector3::zeros();
                step[axis] = 1e-6;
                let fd = (p.value(&[f[0] + step]) - p.value(&[f[0] - step])) / 2e-6;
                assert!(
                    (fd - g[axis]).abs() < 1e-6,
                    "{objective:?} {axis}: {fd} {}",
                    g[axis]
                );
            }
        }
    }

    #[test]
    fn the_tilt_target_leans_toward_the_centre_in_the_agent_frame() {
        let angle = 0.2f64;
        for quarter_turns in 0..4 {
            let position = Vector3::new(0.4, 0.0, 0.0);
            let e = one_agent(position, quarter_turns);
            let block = e.block(0).unwrap();
            let t = tilt_target(block, angle);
            let rotation = block.fixed_rows::<3>(3).into_owned();
            let team = rotation * t;
            let want = Vector3::new(-angle.sin(), 0.0, angle.cos());
            assert!((team - want).norm() < 1e-12, "{quarter_turns}: {team}");
            let p = prepared(NullSpaceObjective::InwardTilt { angle }, &e);
            assert!((p.value(&[t * 5.0]) - 1.0).abs() < 1e-12);
        }
        // Above the centre: straight up.
        let e = one_agent(Vector3::new(0.0, 0.0, 0.3), 0);
        assert_eq!(tilt_target(e.block(0).unwrap(), angle), Vector3::z());
    }
}
