//! The Clarabel solver kept between periods for one sparsity structure, updated in place.

use std::vec::Vec;

use ::clarabel::algebra::CscMatrix;
use ::clarabel::solver::{DefaultSettings, DefaultSolver};

use super::cones::Shape;
use super::qp::Problem;

/// The Clarabel solver for one structure, with the buffers of its data.
pub(super) struct Cache<const N: usize> {
    pub(super) key: [Option<Shape>; N],
    pub(super) solver: DefaultSolver<f64>,
    pub(super) p: Vec<f64>,
    pub(super) a_triplets: Vec<(usize, usize, f64)>,
    pub(super) a: Vec<f64>,
    pub(super) q: Vec<f64>,
    pub(super) b: Vec<f64>,
    /// Scratch for the new `P` values, compared with `p` before updating.
    pub(super) scratch: Vec<f64>,
}

impl<const N: usize> Cache<N> {
    /// A new solver for `problem` (`None` if Clarabel rejects it).
    pub(super) fn build(problem: &Problem<N>, settings: &DefaultSettings<f64>) -> Option<Self> {
        let (n, m) = (problem.variables(), problem.rows());
        let mut p = Vec::new();
        problem.p_values(&mut p);
        let (colptr, rowval) = problem.p_structure();
        let p_matrix = CscMatrix::new(n, n, colptr, rowval, p.clone());

        let mut a_triplets = Vec::new();
        problem.a_triplets(&mut a_triplets);
        let mut a_colptr = Vec::with_capacity(n + 1);
        a_colptr.push(0);
        let mut a_rowval = Vec::with_capacity(a_triplets.len());
        let mut a = Vec::with_capacity(a_triplets.len());
        for col in 0..n {
            for (_, r, v) in a_triplets.iter().filter(|t| t.0 == col) {
                a_rowval.push(*r);
                a.push(*v);
            }
            a_colptr.push(a_rowval.len());
        }
        let a_matrix = CscMatrix::new(m, n, a_colptr, a_rowval, a.clone());

        let (mut q, mut b) = (Vec::new(), Vec::new());
        problem.q_values(&mut q);
        problem.b_values(&mut b);
        let cones = problem.cones();
        let solver =
            DefaultSolver::new(&p_matrix, &q, &a_matrix, &b, &cones, settings.clone()).ok()?;
        if !solver.is_data_update_allowed() {
            return None;
        }
        Some(Self {
            key: problem.key,
            solver,
            p,
            a_triplets,
            a,
            q,
            b,
            scratch: Vec::new(),
        })
    }

    /// Writes `problem`'s numbers into the solver (same structure); `P`, `A` and `q` only if
    /// changed (in normal use `b` alone changes with the wrench, `A` with the sets).
    pub(super) fn update(
        &mut self,
        problem: &Problem<N>,
    ) -> Result<(), ::clarabel::solver::DataUpdateError> {
        problem.p_values(&mut self.scratch);
        if self.scratch != self.p {
            core::mem::swap(&mut self.scratch, &mut self.p);
            self.solver.update_P(&self.p)?;
        }
        problem.a_triplets(&mut self.a_triplets);
        self.scratch.clear();
        self.scratch.extend(self.a_triplets.iter().map(|t| t.2));
        if self.scratch != self.a {
            core::mem::swap(&mut self.scratch, &mut self.a);
            self.solver.update_A(&self.a)?;
        }
        problem.q_values(&mut self.scratch);
        if self.scratch != self.q {
            core::mem::swap(&mut self.scratch, &mut self.q);
            self.solver.update_q(&self.q)?;
        }
        problem.b_values(&mut self.b);
        self.solver.update_b(&self.b)?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::indexing_slicing)]
    use super::*;
    use crate::allocation::clarabel::qp::tests::two_agents;
    use crate::allocation::clarabel::settings::default_settings;
    use ::clarabel::solver::{IPSolver, SolverStatus};

    #[test]
    fn solves_then_updates_in_place() {
        let mut problem = two_agents(1e-6);
        let mut cache = Cache::build(&problem, &default_settings()).unwrap();
        cache.solver.solve();
        assert_eq!(cache.solver.solution.status, SolverStatus::Solved);
        let first = cache.solver.solution.x[5];
        // A new wrench changes only `b`; the solver follows it without a rebuild.
        problem.target *= 2.0;
        cache.update(&problem).unwrap();
        assert_eq!(cache.b[5], 6.0);
        cache.solver.solve();
        assert_eq!(cache.solver.solution.status, SolverStatus::Solved);
        let second = cache.solver.solution.x[5];
        // Agent 1's f_z is 2 u_z / (5 + lambda) in closed form: 1.2 N, then 2.4 N (to the
        // interior-point accuracy along the weakly regularised null space).
        assert!(
            (first - 1.2).abs() < 1e-3 && (second - 2.4).abs() < 1e-3,
            "{first} {second}"
        );
    }
}
