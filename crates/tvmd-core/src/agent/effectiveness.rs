//! The effectiveness model `M(Xi)` (eq. 4): what wrench the team produces from agent forces.
//!
//! Stored as one 6x3 block per agent, never as a heap matrix, so every product is `O(n)`.

use nalgebra::{Matrix6, Matrix6x3, Vector3, Vector6};

use crate::foundation::error::ConfigError;
use crate::foundation::linalg::{max_diagonal, weighted_gram, GramSolver, Ldlt};
use crate::foundation::real::{eps, lit, to_f64, Real};
use crate::foundation::stored::Stored;

/// `R_z(m pi/2)`, at its old path (now in [`crate::foundation::rotation`]).
pub use crate::foundation::rotation::quarter_turn;

/// `M_i = [[p_i]x R_z(psi_i); R_z(psi_i)]`, agent `i`'s block of eq. (4), rows `[torque; force]`.
pub fn agent_block<T: Real>(position: &Vector3<T>, quarter_turns: i32) -> Matrix6x3<T> {
    let rz = quarter_turn::<T>(quarter_turns);
    let mut block = Matrix6x3::zeros();
    block
        .fixed_view_mut::<3, 3>(0, 0)
        .copy_from(&(position.cross_matrix() * rz));
    block.fixed_view_mut::<3, 3>(3, 0).copy_from(&rz);
    block
}

/// `M(Xi)` of the working agents: `u = [u_tau; u_f] = sum_i M_i f_i` (eq. 4), with `f_i` in
/// agent `i`'s frame. Failed agents have no block.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Effectiveness<T: Real, const N: usize> {
    blocks: [Stored<Matrix6x3<T>>; N],
    /// How many blocks there are, counted when they were assigned: a plain count, so that the
    /// allocators' round bounds never derive from the blocks' tags (a stray write in a C
    /// caller's handle can make a tag anything, and an optimizer may count by adding tags).
    pub(crate) working: usize,
    /// The factor of `M M^T`, computed once here and reused by the pseudo-inverses.
    gram: GramSolver<T>,
}

impl<T: Real, const N: usize> Effectiveness<T, N> {
    /// The blocks of the working agents, given as `(slot, p_i, m_i)` (slot `< N`; others are
    /// ignored). [`crate::TeamConfig::effectiveness`] builds it from a team and failure mask.
    ///
    /// ```
    /// use tvmd_core::{team::presets, FailureMask, TeamConfig};
    /// let team: TeamConfig<f64, 4> = presets::a4_inc()?;
    /// let m = team.effectiveness(&FailureMask::with_failed(&[2])?);
    /// assert_eq!(m.working_count(), 3);
    /// assert!(m.block(2).is_none());
    /// # Ok::<(), tvmd_core::ConfigError>(())
    /// ```
    pub fn new<'a>(agents: impl IntoIterator<Item = (usize, &'a Vector3<T>, i32)>) -> Self {
        let mut m = Self {
            blocks: [Stored::Absent; N],
            working: 0,
            gram: GramSolver::Zero,
        };
        m.assign(agents);
        m
    }

    /// Writes the model [`Self::new`] builds from `agents` at `this`, without a model on the
    /// stack.
    ///
    /// # Safety
    /// `this` is valid for writes and aligned; what it held is overwritten, not dropped.
    pub(crate) unsafe fn write_new<'a>(
        this: *mut Self,
        agents: impl IntoIterator<Item = (usize, &'a Vector3<T>, i32)>,
    ) {
        let blocks = core::ptr::addr_of_mut!((*this).blocks).cast::<Stored<Matrix6x3<T>>>();
        for i in 0..N {
            blocks.add(i).write(Stored::Absent);
        }
        core::ptr::addr_of_mut!((*this).working).write(0);
        core::ptr::addr_of_mut!((*this).gram).write(GramSolver::Zero);
        (*this).assign(agents);
    }

    /// Rebuilds this model from `(slot, p_i, m_i)` in place, as [`Self::new`] would build it.
    /// Why in place: with 16 agents in `f32` the model is 1.4 KB, and a new one built on the
    /// stack and moved here costs a small-stack caller (a flight stack's work queue) twice that.
    pub fn assign<'a>(&mut self, agents: impl IntoIterator<Item = (usize, &'a Vector3<T>, i32)>) {
        for slot in self.blocks.iter_mut() {
            *slot = Stored::Absent;
        }
        for (i, position, quarter_turns) in agents {
            if let Some(slot) = self.blocks.get_mut(i) {
                *slot = Stored::Present(agent_block(position, quarter_turns));
            }
        }
        self.working = self.blocks.iter().flatten().count();
        self.gram = GramSolver::new(&self.gram());
    }

    /// The factor of `M M^T` for the pseudo-inverses.
    pub(crate) fn gram_solver(&self) -> &GramSolver<T> {
        &self.gram
    }

    /// Block of agent `i`, `None` if it failed or does not exist.
    pub fn block(&self, agent: usize) -> Option<&Matrix6x3<T>> {
        self.blocks.get(agent).and_then(Stored::as_ref)
    }

    /// Blocks per slot of the capacity ([`Stored::Absent`] for failed or absent agents).
    pub fn blocks(&self) -> &[Stored<Matrix6x3<T>>; N] {
        &self.blocks
    }

    /// Number of working agents (at most `N`).
    pub fn working_count(&self) -> usize {
        // The stored count (checked by `Controller::storage_intact`), at most the capacity
        // whatever it holds: it bounds the allocators' rounds.
        self.working.min(N)
    }

    /// `u = M f` (eq. 4) for agent-frame forces; failed agents' forces are ignored.
    pub fn wrench(&self, forces: &[Vector3<T>; N]) -> Vector6<T> {
        self.blocks
            .iter()
            .zip(forces)
            .filter_map(|(b, f)| b.as_ref().map(|b| b * f))
            .fold(Vector6::zeros(), |acc, u| acc + u)
    }

    /// `M W^-1 M^T = sum_i M_i M_i^T / w_i` (with `w_i = 1`: `M M^T`), the 6x6 Gram matrix of the
    /// pseudo-inverse. `weights[i] > 0` is agent `i`'s cost weight.
    pub fn weighted_gram(&self, weights: Option<&[T; N]>) -> Matrix6<T> {
        let weight = |i: usize| weights.and_then(|w| w.get(i)).copied().unwrap_or(T::one());
        weighted_gram(
            Matrix6::zeros(),
            self.blocks
                .iter()
                .enumerate()
                .filter_map(|(i, b)| b.as_ref().map(|b| (b, weight(i)))),
        )
    }

    /// `M M^T`.
    pub fn gram(&self) -> Matrix6<T> {
        self.weighted_gram(None)
    }

    /// Writes the dense `6 x 3n` matrix row-major into `out` (length `18 n` for `n` slots,
    /// zero columns for failed agents). Returns `false` if `out` has the wrong length.
    pub fn write_dense(&self, n: usize, out: &mut [T]) -> bool {
        if out.len() != 18 * n || n > N {
            return false;
        }
        for (row, out_row) in out.chunks_exact_mut(3 * n).enumerate() {
            for (block, cols) in self.blocks.iter().zip(out_row.chunks_exact_mut(3)) {
                for (col, x) in cols.iter_mut().enumerate() {
                    *x = block
                        .as_ref()
                        .and_then(|b| b.get((row, col)).copied())
                        .unwrap_or(T::zero());
                }
            }
        }
        true
    }

    /// Errors with [`ConfigError::RankDeficient`] unless `M` has rank 6, judged by the
    /// `L D L^T` pivots of `M M^T`: the smallest must exceed `1e3 eps` times the largest
    /// diagonal entry (the reported conditioning is that ratio).
    pub fn check_rank(&self) -> Result<(), ConfigError> {
        check_gram_rank(&self.gram())
    }
}

/// [`Effectiveness::check_rank`] of the model whose `M M^T` is `gram`.
pub(crate) fn check_gram_rank<T: Real>(gram: &Matrix6<T>) -> Result<(), ConfigError> {
    let scale = max_diagonal(gram);
    let conditioning = Ldlt::new(gram, T::zero())
        .map(|f| f.pivots().iter().fold(scale, |m, d| m.min(*d)) / scale)
        .filter(|c| c.is_finite())
        .unwrap_or(T::zero());
    if scale > T::zero() && conditioning > eps::<T>() * lit(1e3) {
        Ok(())
    } else {
        Err(ConfigError::RankDeficient {
            conditioning: to_f64(conditioning).max(0.0),
        })
    }
}

impl<T: Real, const N: usize> Effectiveness<T, N> {
    /// Whether the model at `this` holds valid tags (each block's and the Gram factor's) and
    /// as many blocks as its count of working agents. Reads only; about `N + 2` loads.
    ///
    /// # Safety
    /// `this` is aligned and points to `size_of::<Self>()` readable bytes.
    pub(crate) unsafe fn storage_intact(this: *const Self) -> bool {
        let blocks = core::ptr::addr_of!((*this).blocks).cast::<Stored<Matrix6x3<T>>>();
        let (mut bits, mut present) = (0_u8, 0_usize);
        for i in 0..N {
            let tag = blocks.add(i).cast::<u8>().read();
            bits |= tag;
            present += usize::from(tag & 1);
        }
        bits <= 1
            && present == core::ptr::addr_of!((*this).working).read()
            && GramSolver::storage_intact(core::ptr::addr_of!((*this).gram))
    }
}

#[cfg(test)]
mod storage_tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use crate::foundation::stored::{accepts, refuses};
    use crate::{team::presets, FailureMask};
    use core::ptr::addr_of_mut;

    #[test]
    fn an_invalid_block_or_gram_tag_or_a_block_the_count_misses_is_refused() {
        let team = presets::a4_inc::<f32, 4>().unwrap();
        let check = Effectiveness::<f32, 4>::storage_intact;
        for failed in [&[][..], &[2]] {
            let m = team.effectiveness(&FailureMask::with_failed(failed).unwrap());
            assert!(accepts(&m, check));
            type P = *mut Effectiveness<f32, 4>;
            let block = |i: usize| {
                move |p: P| unsafe {
                    addr_of_mut!((*p).blocks)
                        .cast::<Stored<Matrix6x3<f32>>>()
                        .add(i)
                        .cast()
                }
            };
            assert!(refuses(&m, 2, block(3), check), "tag 2");
            // A working agent's block taken away, or a failed one's given: the count disagrees.
            assert!(refuses(&m, 0, block(1), check), "block absent");
            assert!(refuses(
                &m,
                3,
                |p: P| unsafe { addr_of_mut!((*p).gram).cast() },
                check
            ));
        }
        let mut m = team.effectiveness(&FailureMask::with_failed(&[2]).unwrap());
        m.blocks[2] = m.blocks[0];
        assert!(!accepts(&m, check), "a failed agent's block present");
    }
}
