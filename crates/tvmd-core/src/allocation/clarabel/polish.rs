//! Closed-form least squares over a free set, the unconstrained shortcut, and the active-set
//! polish of an interior-point answer.

use std::vec::Vec;

use nalgebra::{Matrix6, Vector3};

use super::cones::lerp;
use super::qp::Problem;
use crate::foundation::linalg::{solve_gram, weighted_gram};

impl<const N: usize> Problem<N> {
    /// The regularised least-squares forces of the agents marked free, the others held at
    /// `forces`: `f_k = B_k^T (sum_free B_j B_j^T + lambda I)^-1 (W u - sum_fixed B_j f_j)`
    /// (minimum norm when the bracket is singular).
    pub(super) fn least_squares(&self, free: &[bool], forces: &[[f64; 3]]) -> Vec<[f64; 3]> {
        let mut rhs = self.target;
        for ((agent, is_free), f) in self.agents.iter().zip(free).zip(forces) {
            if !*is_free {
                rhs -= agent.block * Vector3::from(*f);
            }
        }
        let gram = weighted_gram(
            Matrix6::identity() * self.lambda,
            self.agents
                .iter()
                .zip(free)
                .filter(|(_, is_free)| **is_free)
                .map(|(agent, _)| (&agent.block, 1.0)),
        );
        let y = solve_gram(&gram, &rhs);
        self.agents
            .iter()
            .zip(free)
            .zip(forces)
            .map(|((agent, is_free), f)| {
                if *is_free {
                    (agent.block.transpose() * y).into()
                } else {
                    *f
                }
            })
            .collect()
    }

    /// The unconstrained minimiser if it satisfies every constraint (then it is the optimum).
    pub(super) fn unconstrained(&self) -> Option<Vec<[f64; 3]>> {
        let free = std::vec![true; self.agents.len()];
        let forces = self.least_squares(&free, &std::vec![[0.0; 3]; self.agents.len()]);
        self.agents
            .iter()
            .zip(&forces)
            .all(|(a, f)| a.bounds.feasible(*f))
            .then_some(forces)
    }

    /// Active-set polish of an interior-point answer `start` (feasible): agents with an active
    /// constraint are held; the others move along the line to their closed-form least-squares
    /// forces ([`Self::least_squares`]) as far as every one stays feasible; the agent that
    /// blocks the step is held too, and so on (at most one round per agent). The objective is
    /// convex with its minimum on each line at the end, so it never increases. `Some` if the
    /// forces changed and the objective did not grow.
    pub(super) fn polish(&self, start: &[[f64; 3]]) -> Option<Vec<[f64; 3]>> {
        let mut forces = start.to_vec();
        let mut free: Vec<bool> = self
            .agents
            .iter()
            .zip(start)
            .map(|(a, f)| a.bounds.feasible(*f) && !a.bounds.active(*f))
            .collect();
        let mut moved = false;
        for _ in 0..self.agents.len() {
            if !free.iter().any(|f| *f) {
                break;
            }
            let target = self.least_squares(&free, &forces);
            // The largest step in [0, 1] keeping every free agent feasible, and who blocks it.
            let mut step = 1.0;
            let mut blocking = None;
            for (k, ((agent, is_free), (from, to))) in self
                .agents
                .iter()
                .zip(&free)
                .zip(forces.iter().zip(&target))
                .enumerate()
            {
                if !*is_free {
                    continue;
                }
                let t = agent.bounds.max_step(*from, *to, step);
                if t < step {
                    step = t;
                    blocking = Some(k);
                }
            }
            for ((f, to), is_free) in forces.iter_mut().zip(&target).zip(&free) {
                if *is_free {
                    *f = lerp(*f, *to, step);
                }
            }
            moved = true;
            match blocking.and_then(|k| free.get_mut(k)) {
                Some(is_free) => *is_free = false,
                None => break,
            }
        }
        (moved && self.objective(&forces) <= self.objective(start)).then_some(forces)
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::indexing_slicing)]
    use crate::allocation::clarabel::qp::tests::two_agents;

    #[test]
    fn least_squares_matches_the_hand_computation() {
        // Forces f_1 = B_1^T y, f_2 = B_2^T y with (B_1 B_1^T + B_2 B_2^T + lambda I) y = u:
        // on the force rows (1 + 4 + lambda) y = u, so f_1 = u / 5.5, f_2 = 2 u / 5.5.
        let p = two_agents(0.5);
        let f = p.least_squares(&[true, true], &[[0.0; 3]; 2]);
        for (k, scale) in [(0, 1.0), (1, 2.0)] {
            for (i, u) in [0.1, 0.1, 3.0].iter().enumerate() {
                assert!((f[k][i] - scale * u / 5.5).abs() < 1e-14, "{f:?}");
            }
        }
        // Agent 0 held at (0, 0, 1): agent 1 alone, (4 + lambda) y = u - (0, 0, 1), f_2 = 2 y.
        let held = p.least_squares(&[false, true], &[[0.0, 0.0, 1.0], [0.0; 3]]);
        assert_eq!(held[0], [0.0, 0.0, 1.0]);
        assert!((held[1][2] - 2.0 * 2.0 / 4.5).abs() < 1e-14, "{held:?}");
    }

    #[test]
    fn unconstrained_minimiser_and_polish() {
        let p = two_agents(1e-6);
        let f = p.unconstrained().unwrap();
        assert!(f[1][2] > 0.0);
        // From a feasible interior point the polish reaches the same minimiser and never
        // increases the objective.
        let start = [[0.0, 0.0, 0.1], [0.0, 0.0, 0.1]];
        let polished = p.polish(&start).unwrap();
        assert!(p.objective(&polished) <= p.objective(&start));
        for (a, b) in polished.iter().flatten().zip(f.iter().flatten()) {
            assert!((a - b).abs() < 1e-9, "{polished:?} vs {f:?}");
        }
    }
}
