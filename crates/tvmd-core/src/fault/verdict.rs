//! The detector's verdict and report types ([`crate::fault`]).

use core::ptr::addr_of;

use crate::foundation::real::Real;
use crate::foundation::stored::tag_below;

/// What an isolated agent's residual looks like. `repr(u8)`, as every enum a controller
/// stores: the tag first, checked raw by [`crate::Controller::storage_intact`].
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(u8)]
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

/// Which check named the verdict's agent (`repr(u8)`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[repr(u8)]
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

/// The detector's verdict this period (`repr(u8)`).
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(u8)]
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

/// [`FaultVerdict::Suspected`] as `repr(u8)` lays it out (RFC 2195: a `repr(C)` struct of the
/// tag and the fields), to find its kind.
#[repr(C)]
#[allow(dead_code)] // Only its layout is read.
struct SuspectedLayout<T: Real> {
    tag: u8,
    agent: usize,
    kind: FaultKind<T>,
    periods: u32,
}

/// [`FaultVerdict::Confirmed`] as `repr(u8)` lays it out.
#[repr(C)]
#[allow(dead_code)] // Only its layout is read.
struct ConfirmedLayout<T: Real> {
    tag: u8,
    agent: usize,
    kind: FaultKind<T>,
}

impl<T: Real> FaultReport<T> {
    /// Whether the report at `this` holds valid tags: the verdict's (four variants), its
    /// kind's (four) when it names an agent, and the source's (two). Reads only.
    ///
    /// # Safety
    /// `this` is aligned and points to `size_of::<Self>()` readable bytes.
    pub(crate) unsafe fn storage_intact(this: *const Self) -> bool {
        let verdict = addr_of!((*this).verdict);
        let kind = match verdict.cast::<u8>().read() {
            0 | 1 => None,
            2 => Some(addr_of!((*verdict.cast::<SuspectedLayout<T>>()).kind)),
            3 => Some(addr_of!((*verdict.cast::<ConfirmedLayout<T>>()).kind)),
            _ => return false,
        };
        kind.is_none_or(|k| tag_below(k, 4)) && tag_below(addr_of!((*this).source), 2)
    }
}

#[cfg(test)]
mod storage_tests {
    #![allow(clippy::unwrap_used, clippy::unreachable)]
    use super::*;
    use crate::foundation::stored::{accepts, refuses};
    use core::ptr::addr_of_mut;

    fn report(verdict: FaultVerdict<f32>) -> FaultReport<f32> {
        FaultReport {
            verdict,
            source: FaultSource::Reports,
            statistic: 1.0,
            threshold: 1.0,
            best_misfit: 0.0,
            runner_up_misfit: 0.0,
        }
    }

    #[test]
    fn an_invalid_verdict_kind_or_source_tag_is_refused() {
        let check = FaultReport::<f32>::storage_intact;
        let kind = FaultKind::PartialLoss { efficiency: 0.5 };
        let named = [
            FaultVerdict::Suspected {
                agent: 3,
                kind,
                periods: 2,
            },
            FaultVerdict::Confirmed { agent: 3, kind },
        ];
        for verdict in [FaultVerdict::Nominal, FaultVerdict::Unexplained] {
            let r = report(verdict);
            assert!(accepts(&r, check));
            assert!(refuses(
                &r,
                4,
                |p| unsafe { addr_of_mut!((*p).verdict).cast() },
                check
            ));
            assert!(refuses(
                &r,
                2,
                |p| unsafe { addr_of_mut!((*p).source).cast() },
                check
            ));
        }
        for verdict in named {
            let r = report(verdict);
            assert!(accepts(&r, check));
            // The kind where the layout mirrors say, and a tag past the last refused there.
            let (FaultVerdict::Suspected { kind, .. } | FaultVerdict::Confirmed { kind, .. }) =
                &r.verdict
            else {
                unreachable!()
            };
            let at = kind as *const FaultKind<f32> as usize - &r as *const _ as usize;
            let mirrored = match r.verdict {
                FaultVerdict::Suspected { .. } => core::mem::offset_of!(SuspectedLayout<f32>, kind),
                _ => core::mem::offset_of!(ConfirmedLayout<f32>, kind),
            };
            assert_eq!(
                at,
                mirrored + core::mem::offset_of!(FaultReport<f32>, verdict)
            );
            let kind = |p: *mut FaultReport<f32>| unsafe { p.cast::<u8>().add(at) };
            assert!(refuses(&r, 4, kind, check));
        }
    }
}
