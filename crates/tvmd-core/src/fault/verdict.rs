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
    /// The agent's reports stopped for longer than the stated link timeout
    /// ([`crate::fault::ReportCheck::link_timeout`]): its command link is taken as gone (named
    /// by the report check only; the residual names what the agent then does).
    LinkLoss,
}

/// Which check named the verdict's agent.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum FaultSource {
    /// The wrench residual: the vehicle's motion ([`crate::fault::FaultState`]).
    #[default]
    Residual,
    /// The agents' own reports checked against their commands ([`crate::fault::ReportState`]).
    Reports,
}

impl FaultSource {
    /// `"residual"` or `"reports"`.
    pub const fn as_str(self) -> &'static str {
        match self {
            Self::Residual => "residual",
            Self::Reports => "reports",
        }
    }
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
/// agent was fitted), and the check that named the verdict's agent.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FaultReport<T: Real> {
    /// The verdict.
    pub verdict: FaultVerdict<T>,
    /// The check that named the verdict's agent ([`FaultSource::Residual`] for a verdict that
    /// names none).
    pub source: FaultSource,
    /// `||r||_Sigma`.
    pub statistic: T,
    /// `k`.
    pub threshold: T,
    /// The smallest misfit over the agents.
    pub best_misfit: T,
    /// The second smallest.
    pub runner_up_misfit: T,
}
