//! What one solve did: [`SolveReport`] and [`FallbackReason`].

use core::fmt;
use std::time::Duration;

#[cfg(doc)]
use super::ClarabelAllocator;
#[cfg(doc)]
use crate::allocation::Allocator;

/// Clarabel's termination status (re-exported from `clarabel::solver::SolverStatus`).
pub use ::clarabel::solver::SolverStatus as ClarabelStatus;

/// Why [`ClarabelAllocator`] fell back to the redistributed pseudo-inverse.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FallbackReason {
    /// No agent works (every force is zero).
    NoAgents,
    /// The wrench, an effectiveness block or a set bound was NaN or infinite.
    NonFiniteInput,
    /// Clarabel refused the problem or its settings (should not happen; a bug report).
    Setup,
    /// Clarabel stopped without a solution; [`SolveReport::status`] says how.
    Status,
    /// Clarabel reported a solution containing NaN or infinity.
    NonFiniteSolution,
    /// The request exceeds `1e6` times the largest wrench component the agents can produce
    /// ([`ClarabelAllocator`]'s range): its squares would swamp the solver's scaling, and every
    /// agent saturates anyway.
    OutOfRange,
}

impl fmt::Display for FallbackReason {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::NoAgents => "no working agent",
            Self::NonFiniteInput => "non-finite input",
            Self::Setup => "solver setup failed",
            Self::Status => "solver did not converge",
            Self::NonFiniteSolution => "non-finite solution",
            Self::OutOfRange => "request out of the solver's range",
        })
    }
}

/// What happened in the last [`Allocator::allocate`] call.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolveReport {
    /// Clarabel's status (`Unsolved` when the solver did not run).
    pub status: ClarabelStatus,
    /// Interior-point iterations (0 when the solver did not run).
    pub iterations: u32,
    /// Wall time of Clarabel's `solve()` alone (not the data update or rebuild). Measured
    /// here: Clarabel's own `solve_time` also counts its one-off setup, in every solve.
    pub solver_time: Duration,
    /// Wall time of the whole call: data update (or rebuild), solve and post-processing.
    pub wall_time: Duration,
    /// `||W (M f - u_d)||^2 + lambda ||f||^2` at the returned forces (also after a fallback).
    pub objective: f64,
    /// The solver was (re)built in this call: first call, or the set of working agents or the
    /// kind of an `eta_x` constraint changed. Otherwise the data were updated in place.
    pub rebuilt: bool,
    /// The unconstrained minimiser (a 6x6 solve) satisfied every constraint, so it is the
    /// optimum and Clarabel was not called (status `Unsolved`, 0 iterations).
    pub unconstrained: bool,
    /// The active-set polish replaced Clarabel's answer (see [`ClarabelAllocator`], "Solving").
    pub polished: bool,
    /// `Some` when the returned allocation is the redistributed pseudo-inverse's.
    pub fallback: Option<FallbackReason>,
}

impl SolveReport {
    /// Whether the allocation fell back to the redistributed pseudo-inverse.
    pub fn is_fallback(&self) -> bool {
        self.fallback.is_some()
    }

    /// Whether the returned forces are the QP's optimum (to the solver tolerance): the
    /// unconstrained minimiser was feasible, or Clarabel reported `Solved` / `AlmostSolved`.
    pub fn is_optimal(&self) -> bool {
        !self.is_fallback()
            && (self.unconstrained
                || matches!(
                    self.status,
                    ClarabelStatus::Solved | ClarabelStatus::AlmostSolved
                ))
    }
}

impl fmt::Display for SolveReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.unconstrained {
            return write!(
                f,
                "clarabel not called: unconstrained minimum admissible ({:.1} us, objective {:e})",
                self.wall_time.as_secs_f64() * 1e6,
                self.objective
            );
        }
        write!(
            f,
            "clarabel {} in {} iterations, {:.1} us solver / {:.1} us total, objective {:e}{}",
            self.status,
            self.iterations,
            self.solver_time.as_secs_f64() * 1e6,
            self.wall_time.as_secs_f64() * 1e6,
            self.objective,
            if self.rebuilt { ", rebuilt" } else { "" }
        )?;
        if self.polished {
            f.write_str(", polished")?;
        }
        if let Some(reason) = self.fallback {
            write!(
                f,
                "; fell back to the redistributed pseudo-inverse ({reason})"
            )?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::string::ToString;

    fn report() -> SolveReport {
        SolveReport {
            status: ClarabelStatus::Solved,
            iterations: 7,
            solver_time: Duration::from_micros(10),
            wall_time: Duration::from_micros(20),
            objective: 0.5,
            rebuilt: true,
            unconstrained: false,
            polished: true,
            fallback: None,
        }
    }

    #[test]
    fn optimal_unless_fallen_back() {
        let r = report();
        assert!(r.is_optimal() && !r.is_fallback());
        let text = r.to_string();
        assert!(
            text.contains("7 iterations") && text.contains("rebuilt") && text.contains("polished")
        );
        let fell = SolveReport {
            status: ClarabelStatus::MaxIterations,
            fallback: Some(FallbackReason::Status),
            ..r
        };
        assert!(!fell.is_optimal() && fell.is_fallback());
        assert!(fell.to_string().contains("did not converge"));
    }
}
