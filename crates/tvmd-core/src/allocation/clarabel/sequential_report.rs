//! What one call of [`SequentialConvexAllocator`] did: [`SequentialReport`] and [`StopReason`].

use core::fmt;
use std::time::Duration;

use super::report::{ClarabelStatus, FallbackReason};
#[cfg(doc)]
use super::SequentialConvexAllocator;

/// Why [`SequentialConvexAllocator`] stopped stepping.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StopReason {
    /// The weighted wrench error is at most `1e-9 ||W u_d||`: nothing left to gain.
    Exact,
    /// A step lowered the objective by less than the relative decrease tolerance (or not at
    /// all, and was not taken).
    Converged,
    /// The step limit was reached.
    StepLimit,
    /// Clarabel stopped without a solution (the report's `status` says how) or returned a
    /// non-finite one; the best forces so far are returned.
    Solver,
    /// A step's forces, projected onto the linearized constraints, were not admissible to
    /// round-off, and were rejected; the best forces so far are returned.
    Rejected,
    /// No step was tried: see [`SequentialReport::fallback`].
    NotSolved,
}

impl fmt::Display for StopReason {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::Exact => "wrench exact",
            Self::Converged => "objective decrease below tolerance",
            Self::StepLimit => "step limit",
            Self::Solver => "solver did not converge",
            Self::Rejected => "step rejected as not admissible",
            Self::NotSolved => "not solved",
        })
    }
}

/// What happened in the last call of [`SequentialConvexAllocator`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SequentialReport {
    /// Convex steps solved by Clarabel (0 when the start was exact).
    pub steps: u32,
    /// Steps whose forces were taken (the objective did not increase).
    pub accepted: u32,
    /// Interior-point iterations over all steps.
    pub iterations: u32,
    /// Clarabel's status in the last step (`Unsolved` when no step ran).
    pub status: ClarabelStatus,
    /// Why the steps stopped.
    pub stop: StopReason,
    /// The start was the previous period's forces (lower objective than the redistributed
    /// pseudo-inverse's, and admissible), not the redistributed pseudo-inverse's.
    pub warm_start: bool,
    /// `||W (M f - u_d)||^2 + lambda ||f||^2` at the start.
    pub start_objective: f64,
    /// The same at the returned forces (never above `start_objective`).
    pub objective: f64,
    /// Wall time of Clarabel's `solve()` over all steps.
    pub solver_time: Duration,
    /// Wall time of the whole call.
    pub wall_time: Duration,
    /// The solver was (re)built in this call (else its data were updated in place).
    pub rebuilt: bool,
    /// `Some` when the call returned the redistributed pseudo-inverse's answer without trying
    /// (no working agent, non-finite input, request out of range).
    pub fallback: Option<FallbackReason>,
}

impl fmt::Display for SequentialReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} of {} convex steps taken ({} interior-point iterations, last {}), stopped: {}; \
             objective {:e} -> {:e}; {:.1} us solver / {:.1} us total",
            self.accepted,
            self.steps,
            self.iterations,
            self.status,
            self.stop,
            self.start_objective,
            self.objective,
            self.solver_time.as_secs_f64() * 1e6,
            self.wall_time.as_secs_f64() * 1e6,
        )?;
        if self.warm_start {
            f.write_str(", warm start")?;
        }
        if let Some(reason) = self.fallback {
            write!(f, "; redistributed pseudo-inverse ({reason})")?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::string::ToString;

    #[test]
    fn the_report_says_how_it_stopped() {
        let r = SequentialReport {
            steps: 3,
            accepted: 2,
            iterations: 30,
            status: ClarabelStatus::Solved,
            stop: StopReason::Converged,
            warm_start: true,
            start_objective: 2.0,
            objective: 1.0,
            solver_time: Duration::from_micros(50),
            wall_time: Duration::from_micros(80),
            rebuilt: false,
            fallback: None,
        };
        let text = r.to_string();
        assert!(
            text.contains("2 of 3") && text.contains("below tolerance"),
            "{text}"
        );
        assert!(text.contains("warm start"));
        let fell = SequentialReport {
            stop: StopReason::NotSolved,
            fallback: Some(FallbackReason::NoAgents),
            ..r
        };
        assert!(fell.to_string().contains("no working agent"));
    }
}
