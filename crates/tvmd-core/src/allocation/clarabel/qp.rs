//! Assembly of one period's QP: the working agents' data in `f64` and Clarabel's `P`, `q`,
//! `A`, `b` and cones.

use std::vec::Vec;

use ::clarabel::solver::SupportedConeT;
use nalgebra::{Matrix6x3, Vector3, Vector6};

use super::cones::{Bounds, Shape, XBound};
use crate::allocation::AllocationRequest;
use crate::foundation::real::{to_f64, Real};

/// A working agent in the problem: its capacity slot, weighted block and bounds.
#[derive(Clone, Copy, Debug)]
pub(super) struct Agent {
    pub(super) slot: usize,
    /// `W M_i` in `f64`.
    pub(super) block: Matrix6x3<f64>,
    pub(super) bounds: Bounds,
}

/// One period's problem data in `f64`.
pub(super) struct Problem<const N: usize> {
    pub(super) key: [Option<Shape>; N],
    pub(super) agents: Vec<Agent>,
    /// `W u_d`.
    pub(super) target: Vector6<f64>,
    pub(super) lambda: f64,
}

impl<const N: usize> Problem<N> {
    /// `None` if any used number is not finite.
    pub(super) fn new<T: Real>(
        request: &AllocationRequest<'_, T, N>,
        weights: &[f64; 6],
        lambda: f64,
    ) -> Option<Self> {
        let w = Vector6::from_iterator(weights.iter().copied());
        let target = request.wrench.map(|x| to_f64(x)).component_mul(&w);
        if target.iter().any(|x| !x.is_finite()) {
            return None;
        }
        let mut key = [None; N];
        let mut agents = Vec::with_capacity(N);
        for (slot, ((block, set), k)) in request
            .effectiveness
            .blocks()
            .iter()
            .zip(request.sets)
            .zip(key.iter_mut())
            .enumerate()
        {
            let Some(block) = block.as_ref() else {
                continue;
            };
            let mut weighted = block.map(|x| to_f64(x));
            for (mut row, wr) in weighted.row_iter_mut().zip(weights) {
                row *= *wr;
            }
            if weighted.iter().any(|x| !x.is_finite()) {
                return None;
            }
            let bounds = Bounds::new(set)?;
            *k = Some(bounds.shape());
            agents.push(Agent {
                slot,
                block: weighted,
                bounds,
            });
        }
        Some(Self {
            key,
            agents,
            target,
            lambda,
        })
    }

    /// `sum_k ||B_k f_k - W u||^2 + lambda sum_k ||f_k||^2` (`B_k = W M_k`).
    pub(super) fn objective(&self, forces: &[[f64; 3]]) -> f64 {
        let mut residual = -self.target;
        let mut norm = 0.0;
        for (agent, f) in self.agents.iter().zip(forces) {
            let f = Vector3::from(*f);
            residual += agent.block * f;
            norm += f.norm_squared();
        }
        residual.norm_squared() + self.lambda * norm
    }

    /// `3 n` forces, then the 6 weighted wrench errors `r`.
    pub(super) fn variables(&self) -> usize {
        3 * self.agents.len() + 6
    }

    pub(super) fn linear_rows(&self) -> usize {
        self.agents
            .iter()
            .map(|a| a.bounds.shape().linear_rows())
            .sum()
    }

    /// 6 equality rows, the linear rows, the cones.
    pub(super) fn rows(&self) -> usize {
        6 + self.linear_rows()
            + 4 * self
                .agents
                .iter()
                .map(|a| a.bounds.shape().cones())
                .sum::<usize>()
    }

    /// `P = diag(2 lambda (forces), 2 (errors))`.
    pub(super) fn p_values(&self, out: &mut Vec<f64>) {
        out.clear();
        out.extend(core::iter::repeat_n(
            2.0 * self.lambda,
            3 * self.agents.len(),
        ));
        out.extend([2.0; 6]);
    }

    /// The diagonal structure of [`Self::p_values`].
    pub(super) fn p_structure(&self) -> (Vec<usize>, Vec<usize>) {
        let n = self.variables();
        ((0..=n).collect(), (0..n).collect())
    }

    /// `q = 0`.
    pub(super) fn q_values(&self, out: &mut Vec<f64>) {
        out.clear();
        out.extend(core::iter::repeat_n(0.0, self.variables()));
    }

    /// `b`: `W u` on the equality rows; `-T_lo` on the `f_z` rows; `T_hi` heading each thrust
    /// cone; zeros elsewhere.
    pub(super) fn b_values(&self, out: &mut Vec<f64>) {
        out.clear();
        out.extend(self.target.iter().copied());
        for agent in &self.agents {
            let shape = agent.bounds.shape();
            out.extend(core::iter::repeat_n(0.0, shape.linear_rows() - 1));
            out.push(-agent.bounds.thrust_lo);
        }
        for agent in &self.agents {
            out.extend([agent.bounds.thrust_hi, 0.0, 0.0, 0.0]);
            let extra = agent.bounds.shape().cones() - 1;
            out.extend(core::iter::repeat_n(0.0, 4 * extra));
        }
    }

    /// `A` as `(column, row, value)` triplets sorted column-major (`A x + s = b`, `s` in the
    /// cones): the equalities `W M f - r = W u`, then per agent the linear rows (all agents),
    /// then the cones (all agents).
    pub(super) fn a_triplets(&self, out: &mut Vec<(usize, usize, f64)>) {
        out.clear();
        for (k, agent) in self.agents.iter().enumerate() {
            for (c, column) in agent.block.column_iter().enumerate() {
                out.extend(column.iter().enumerate().map(|(r, v)| (3 * k + c, r, *v)));
            }
        }
        let errors = 3 * self.agents.len();
        out.extend((0..6).map(|r| (errors + r, r, -1.0)));
        let mut row = 6;
        for (k, agent) in self.agents.iter().enumerate() {
            let (x, y, z) = (3 * k, 3 * k + 1, 3 * k + 2);
            let b = &agent.bounds;
            // f_x - tan(hi_y) f_z <= 0
            out.extend([(x, row, 1.0), (z, row, -b.tan_y_hi)]);
            row += 1;
            // -f_x + tan(lo_y) f_z <= 0
            out.extend([(x, row, -1.0), (z, row, b.tan_y_lo)]);
            row += 1;
            // Untilted, `axis . (f_x, f_z)` is `f_z` and `lift . f` is `f_z`.
            let [ax, az] = b.axis;
            if let XBound::Tan(t) = b.x_hi {
                // -f_y - tan(hi_x) axis . (f_x, f_z) <= 0
                if b.tilted {
                    out.push((x, row, -t * ax));
                }
                out.extend([(y, row, -1.0), (z, row, -t * az)]);
                row += 1;
            }
            if let XBound::Tan(t) = b.x_lo {
                // f_y + tan(lo_x) axis . (f_x, f_z) <= 0
                if b.tilted {
                    out.push((x, row, t * ax));
                }
                out.extend([(y, row, 1.0), (z, row, t * az)]);
                row += 1;
            }
            // -lift . f <= -T_lo
            let [hx, hy, hz] = b.lift;
            if b.tilted {
                out.extend([(x, row, -hx), (y, row, -hy)]);
            }
            out.push((z, row, -hz));
            row += 1;
        }
        for (k, agent) in self.agents.iter().enumerate() {
            let (x, y, z) = (3 * k, 3 * k + 1, 3 * k + 2);
            let b = &agent.bounds;
            let heads = [
                None,
                match b.x_hi {
                    XBound::Cone(s) => Some(-s),
                    XBound::Tan(_) => None,
                },
                match b.x_lo {
                    XBound::Cone(s) => Some(s),
                    XBound::Tan(_) => None,
                },
            ];
            // Thrust cone (head row empty: s_0 = T_hi), then the eta_x cones (s_0 = +-s f_y).
            for (i, head) in heads.iter().enumerate() {
                if i > 0 && head.is_none() {
                    continue;
                }
                if let Some(h) = head {
                    out.push((y, row, *h));
                }
                out.extend([(x, row + 1, -1.0), (y, row + 2, -1.0), (z, row + 3, -1.0)]);
                row += 4;
            }
        }
        out.sort_unstable_by_key(|t| (t.0, t.1));
    }

    pub(super) fn cones(&self) -> Vec<SupportedConeT<f64>> {
        let mut cones = Vec::with_capacity(2 + 3 * self.agents.len());
        cones.push(SupportedConeT::ZeroConeT(6));
        cones.push(SupportedConeT::NonnegativeConeT(self.linear_rows()));
        for agent in &self.agents {
            for _ in 0..agent.bounds.shape().cones() {
                cones.push(SupportedConeT::SecondOrderConeT(4));
            }
        }
        cones
    }
}

#[cfg(test)]
pub(super) mod tests {
    #![allow(clippy::unwrap_used, clippy::indexing_slicing)]
    use super::*;
    use crate::allocation::clarabel::cones::tests::symmetric;

    /// Two agents whose blocks are `[0; I]` and `[0; 2 I]` (force rows only), symmetric sets.
    pub(in crate::allocation::clarabel) fn two_agents(lambda: f64) -> Problem<2> {
        let block = |k: f64| {
            let mut b = Matrix6x3::zeros();
            b.fixed_view_mut::<3, 3>(3, 0)
                .copy_from(&(nalgebra::Matrix3::identity() * k));
            b
        };
        let bounds = symmetric();
        Problem {
            key: [Some(bounds.shape()); 2],
            agents: std::vec![
                Agent {
                    slot: 0,
                    block: block(1.0),
                    bounds,
                },
                Agent {
                    slot: 1,
                    block: block(2.0),
                    bounds,
                },
            ],
            target: Vector6::new(0.0, 0.0, 0.0, 0.1, 0.1, 3.0),
            lambda,
        }
    }

    #[test]
    fn p_q_and_b_of_two_agents() {
        let p = two_agents(0.5);
        assert_eq!((p.variables(), p.linear_rows(), p.rows()), (12, 10, 24));
        let (mut pv, mut q, mut b) = (Vec::new(), Vec::new(), Vec::new());
        p.p_values(&mut pv);
        assert_eq!(pv, [[1.0; 6], [2.0; 6]].concat());
        p.q_values(&mut q);
        assert_eq!(q, [0.0; 12]);
        p.b_values(&mut b);
        let linear = [0.0, 0.0, 0.0, 0.0, -0.0];
        let cone = [10.0, 0.0, 0.0, 0.0];
        let expected = [
            &[0.0, 0.0, 0.0, 0.1, 0.1, 3.0][..],
            &linear,
            &linear,
            &cone,
            &cone,
        ]
        .concat();
        assert_eq!(b, expected);
        assert_eq!(p.cones().len(), 4);
    }

    #[test]
    fn a_is_sorted_and_holds_the_wrench_rows() {
        let p = two_agents(0.5);
        let mut a = Vec::new();
        p.a_triplets(&mut a);
        assert!(a.windows(2).all(|w| (w[0].0, w[0].1) < (w[1].0, w[1].1)));
        // Agent 1's f_x (column 3) reaches wrench row 3 with weight 2; the error r_0 (column 6)
        // enters row 0 with -1.
        assert!(a.contains(&(3, 3, 2.0)) && a.contains(&(6, 0, -1.0)));
        // Objective at zero force: ||W u||^2 = 0.01 + 0.01 + 9.
        assert!((p.objective(&[[0.0; 3]; 2]) - 9.02).abs() < 1e-14);
    }
}
