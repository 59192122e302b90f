//! The convexification of the exact gimbal set at a force `f0` (the convex-concave procedure
//! of [`super::SequentialConvexAllocator`]), its projection of a solver answer, and one solve.

use std::boxed::Box;
use std::time::Instant;
use std::vec::Vec;

use ::clarabel::solver::{DefaultSettings, IPSolver};
use nalgebra::Vector3;

use super::cache::Cache;
use super::cones::{Bounds, XBound};
use super::qp::{Agent, Problem};
use super::report::{ClarabelStatus, FallbackReason};

impl Bounds {
    /// These bounds linearized at `f0`: the concave constraints of the exact set (eq. 6) are
    /// replaced by half-spaces through `f0` that lie inside them, the convex ones kept.
    ///
    /// - `eta_x <= hi` with `hi >= 0` is `-f_y <= sin(hi) ||f||`, concave in `f`. With `a` the
    ///   unit direction of `f0`'s `(f_x, f_z)` and `||f|| >= ||(a . (f_x, f_z), f_y)||`, the row
    ///   `-f_y <= tan(hi) a . (f_x, f_z)` lies inside it, and is tight where the exact cone is in
    ///   the vertical plane through `a`: it contains the corners the pyramid (`a = z`) drops.
    ///   `eta_x >= lo` with `lo <= 0` likewise; the cones `hi < 0`, `lo > 0` are convex and stay.
    /// - `T >= T_lo > 0` (`||f|| >= T_lo`, concave) becomes its tangent `f0_hat . f >= T_lo`.
    /// - `eta_y` (planes) and `T <= T_hi` (a ball) are convex and exact.
    ///
    /// An admissible `f0` satisfies its own linearization (the new rows bound `||f0||` from
    /// below by itself), so each step starts feasible and the objective cannot increase.
    pub(super) fn linearized_at(&self, [fx, fy, fz]: [f64; 3]) -> Self {
        // Plain norms: the forces are admissible, at most `T_hi`, so nothing overflows.
        let planar = (fx * fx + fz * fz).sqrt();
        let axis = if planar > 0.0 && planar.is_finite() {
            [fx / planar, fz / planar]
        } else {
            [0.0, 1.0]
        };
        let norm = (planar * planar + fy * fy).sqrt();
        let lift = if self.thrust_lo > 0.0 && norm > 0.0 && norm.is_finite() {
            [fx / norm, fy / norm, fz / norm]
        } else {
            // `f_z >= 0` (or `>= T_lo`): inside the exact set, whose forces all have `f_z >= 0`.
            [0.0, 0.0, 1.0]
        };
        Self {
            tilted: true,
            axis,
            lift,
            ..*self
        }
    }

    /// Moves `f` onto the linear rows of the linearized bounds and into the thrust ball (an
    /// interior-point answer violates them by the solver tolerance): `f_z >= 0`, `f_x` into the
    /// `eta_y` wedge, `f_y` into the `eta_x` rows (they hold `f_x`, `f_z` fixed), then a scaling
    /// up to the minimum-thrust row and down into the ball (the cones are homogeneous). The
    /// caller checks the result with [`Bounds::feasible`] and how far it moved.
    pub(super) fn project(&self, [fx, fy, fz]: [f64; 3]) -> [f64; 3] {
        let fz = fz.max(0.0);
        let fx = fx.max(self.tan_y_lo * fz).min(self.tan_y_hi * fz);
        let [ax, az] = self.axis;
        let along = ax * fx + az * fz;
        let mut fy = fy;
        if let XBound::Tan(t) = self.x_hi {
            fy = fy.max(-t * along);
        }
        if let XBound::Tan(t) = self.x_lo {
            fy = fy.min(-t * along);
        }
        let mut f = Vector3::new(fx, fy, fz);
        let lifted = Vector3::from(self.lift).dot(&f);
        if lifted < self.thrust_lo && lifted > 0.0 {
            f *= self.thrust_lo / lifted;
        }
        let norm = f.norm();
        if norm > self.thrust_hi && norm > 0.0 {
            f *= self.thrust_hi / norm;
        }
        f.into()
    }
}

impl<const N: usize> Problem<N> {
    /// Linearizes every agent's bounds at its force in `forces` (agent order).
    pub(super) fn linearize(&mut self, forces: &[[f64; 3]]) {
        for (agent, f) in self.agents.iter_mut().zip(forces) {
            agent.bounds = agent.bounds.linearized_at(*f);
            if let Some(key) = self.key.get_mut(agent.slot) {
                *key = Some(agent.bounds.shape());
            }
        }
    }

    /// The same problem with its objective multiplied by `scale^2` (the wrench rows by
    /// `scale`). Clarabel's gap tolerance is absolute on the objective, so at `J = 1e-10` it no
    /// longer resolves the wrench error (`1e-5`); scaled by `1 / J(f^k)` each step's answer is
    /// resolved relative to the objective it starts from.
    pub(super) fn scaled(&self, scale: f64) -> Self {
        Self {
            key: self.key,
            agents: self
                .agents
                .iter()
                .map(|a| Agent {
                    block: a.block * scale,
                    ..*a
                })
                .collect(),
            target: self.target * scale,
            lambda: self.lambda * scale * scale,
        }
    }

    /// `||W (M f - u_d)||` over the working agents (`forces` in agent order).
    pub(super) fn residual(&self, forces: &[[f64; 3]]) -> f64 {
        let mut residual = -self.target;
        for (agent, f) in self.agents.iter().zip(forces) {
            residual += agent.block * Vector3::from(*f);
        }
        residual.norm()
    }
}

/// Updates the cached solver (or rebuilds it when the structure changed) and solves `problem`;
/// `record` accumulates what happened (also on failure). The solution's forces, agent order,
/// not yet projected.
pub(super) fn solve<const N: usize>(
    cache: &mut Option<Box<Cache<N>>>,
    settings: &DefaultSettings<f64>,
    problem: &Problem<N>,
    record: &mut SolveRecord,
) -> Result<Vec<[f64; 3]>, FallbackReason> {
    let reused = match cache.as_mut() {
        Some(c) if c.key == problem.key => c.update(problem).is_ok(),
        _ => false,
    };
    if !reused {
        record.rebuilt = true;
        *cache = Cache::build(problem, settings).map(Box::new);
    }
    let c = cache.as_mut().ok_or(FallbackReason::Setup)?;
    let solving = Instant::now();
    c.solver.solve();
    record.solver_time += solving.elapsed();
    let solution = &c.solver.solution;
    record.status = solution.status;
    record.iterations += solution.iterations;
    if !matches!(
        solution.status,
        ClarabelStatus::Solved | ClarabelStatus::AlmostSolved
    ) {
        return Err(FallbackReason::Status);
    }
    if solution.x.iter().any(|x| !x.is_finite()) {
        return Err(FallbackReason::NonFiniteSolution);
    }
    Ok(solution
        .x
        .chunks_exact(3)
        .take(problem.agents.len())
        .map(|x| <[f64; 3]>::try_from(x).unwrap_or([0.0; 3]))
        .collect())
}

/// The solver's side of a report, accumulated over the steps.
#[derive(Clone, Copy, Debug)]
pub(super) struct SolveRecord {
    pub(super) status: ClarabelStatus,
    pub(super) iterations: u32,
    pub(super) solver_time: core::time::Duration,
    pub(super) rebuilt: bool,
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::indexing_slicing)]
    use crate::allocation::clarabel::cones::tests::symmetric;

    #[test]
    fn the_linearization_keeps_its_point_and_a_corner_the_pyramid_drops() {
        let b = symmetric();
        // The corner eta_x = pi/6, eta_y = pi/4 at 8 N: outside the pyramid.
        let (sx, cx) = core::f64::consts::FRAC_PI_6.sin_cos();
        let (sy, cy) = core::f64::consts::FRAC_PI_4.sin_cos();
        let corner = [8.0 * cx * sy, -8.0 * sx, 8.0 * cx * cy];
        assert!(!b.feasible(corner));
        let tilted = b.linearized_at(corner);
        assert!(tilted.feasible(corner) && tilted.active(corner));
        // Linearized at a point in the same vertical plane, the corner is inside too.
        let inner = [4.0 * sy, 0.0, 4.0 * cy];
        assert!(b.linearized_at(inner).feasible(corner));
        // Inner bound: a force beyond eta_x = pi/6 in that plane is outside.
        let beyond = [8.0 * cx * sy, -8.5 * sx, 8.0 * cx * cy];
        assert!(!tilted.feasible(beyond));
        // The projection moves a slightly infeasible answer onto the rows.
        let p = tilted.project([corner[0], corner[1] - 1e-7, corner[2]]);
        assert!(tilted.feasible(p));
        assert!((p[1] - corner[1]).abs() < 1e-6, "{p:?}");
    }
}
