//! The detector's verdict and report types ([`crate::fault`]).

use crate::foundation::real::Real;

/// What an isolated agent's residual looks like.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FaultKind<T: Real> {
    /// The agent delivers (almost) nothing of its command (`efficiency <= 0.2`).
    Loss,
    /// The agent delivers this fraction of its command, in `(0.2, 1)`.
    PartialLoss {
        /// The fraction delivered.
        efficiency: T,
    },
    /// The agent's force turned away from its command: a stuck or slipping gimbal.
    StuckGimbal,
}

/// The detector's verdict this period.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FaultVerdict<T: Real> {
    /// The residual is within the noise.
    Nominal,
    /// Above the threshold, but no single agent explains it (a gust, a payload, model error).
    Unexplained,
    /// Agent `agent` explains it, for `periods` consecutive periods, fewer than the persistence.
    Suspected {
        /// The agent's index.
        agent: usize,
        /// The kind of fault its residual looks like.
        kind: FaultKind<T>,
        /// Consecutive periods so far.
        periods: u32,
    },
    /// Agent `agent` explained the residual for the persistence's periods.
    Confirmed {
        /// The agent's index.
        agent: usize,
        /// The kind of fault.
        kind: FaultKind<T>,
    },
}

/// One period's report: the verdict, the statistic and the threshold it was compared with, and
/// the isolation's best and runner-up misfits (in noise units; the largest finite `T` when no
/// agent was fitted).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FaultReport<T: Real> {
    /// The verdict.
    pub verdict: FaultVerdict<T>,
    /// `||r||_Sigma`.
    pub statistic: T,
    /// `k`.
    pub threshold: T,
    /// The smallest misfit over the agents.
    pub best_misfit: T,
    /// The second smallest.
    pub runner_up_misfit: T,
}
