//! The fault detector's latest report through the C interface ([`tvmd_fault_report`]), with
//! the controller's own mask (see [`crate::fault`] for the configuration).

use tvmd_core::{FaultKind, FaultSource, FaultVerdict};

use crate::handle::{checked_size, inner, TvmdController};
use crate::status::{TvmdStatus, TVMD_ERR_NULL_POINTER, TVMD_OK};

/// `TvmdFaultReport.verdict`: no report (detection off, or no period stepped yet).
pub const TVMD_FAULT_VERDICT_NONE: u32 = 0;
/// `TvmdFaultReport.verdict`: the residual is within the noise.
pub const TVMD_FAULT_VERDICT_NOMINAL: u32 = 1;
/// `TvmdFaultReport.verdict`: above the threshold, but no single agent explains it (a gust, a
/// payload, model error).
pub const TVMD_FAULT_VERDICT_UNEXPLAINED: u32 = 2;
/// `TvmdFaultReport.verdict`: `agent` explains it, for fewer periods than the persistence.
pub const TVMD_FAULT_VERDICT_SUSPECTED: u32 = 3;
/// `TvmdFaultReport.verdict`: `agent` explained it for the persistence's periods.
pub const TVMD_FAULT_VERDICT_CONFIRMED: u32 = 4;

/// `TvmdFaultReport.kind`: no agent named.
pub const TVMD_FAULT_KIND_NONE: u32 = 0;
/// `TvmdFaultReport.kind`: the agent delivers (almost) nothing of its command.
pub const TVMD_FAULT_KIND_LOSS: u32 = 1;
/// `TvmdFaultReport.kind`: the agent delivers the fraction `efficiency` of its command.
pub const TVMD_FAULT_KIND_PARTIAL_LOSS: u32 = 2;
/// `TvmdFaultReport.kind`: the agent's force turned away from its command (a stuck gimbal).
pub const TVMD_FAULT_KIND_STUCK_GIMBAL: u32 = 3;
/// `TvmdFaultReport.kind`: the agent's reports (`tvmd_set_agent_report`) stopped for longer
/// than the link timeout: its command link is taken as gone.
pub const TVMD_FAULT_KIND_LINK_LOSS: u32 = 4;

/// `TvmdFaultReport.source`: no agent named.
pub const TVMD_FAULT_SOURCE_NONE: u32 = 0;
/// `TvmdFaultReport.source`: the wrench residual (the vehicle's motion) named the agent.
pub const TVMD_FAULT_SOURCE_RESIDUAL: u32 = 1;
/// `TvmdFaultReport.source`: the agents' own reports named it.
pub const TVMD_FAULT_SOURCE_REPORTS: u32 = 2;

/// The detector's latest report and the controller's own mask.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TvmdFaultReport {
    /// `sizeof(TvmdFaultReport)`, set by the caller.
    pub size: u32,
    /// One of `TVMD_FAULT_VERDICT_*`.
    pub verdict: u32,
    /// The agent suspected or confirmed; -1 when none.
    pub agent: i32,
    /// One of `TVMD_FAULT_KIND_*` for that agent.
    pub kind: u32,
    /// The delivered fraction with `TVMD_FAULT_KIND_PARTIAL_LOSS`, NaN otherwise.
    pub efficiency: f32,
    /// Consecutive periods of a suspicion (0 otherwise).
    pub periods: u32,
    /// The test statistic `||r||_Sigma` (noise units); NaN without a report.
    pub statistic: f32,
    /// The threshold it was compared with; NaN without a report.
    pub threshold: f32,
    /// The agent the controller masked itself (`TVMD_FAULT_MASK`); -1 when it has not.
    pub masked_agent: i32,
    /// Non-zero when that mask was accepted and the remaining team can hold hover (the
    /// classification `tvmd_set_failures` returns); zero otherwise.
    pub masked_hover_capable: u32,
    /// One of `TVMD_FAULT_SOURCE_*`: the check that named `agent`.
    pub source: u32,
}

/// Fills `report` (whose `size` the caller sets) with the detector's latest report: after a
/// `tvmd_step` (or `tvmd_law`) with detection on, the period's verdict; `verdict =
/// TVMD_FAULT_VERDICT_NONE` with detection off or before the first period.
///
/// # Safety
/// `handle` is null or points to a `TvmdController`; `report` is null or points to a
/// `TvmdFaultReport`.
#[no_mangle]
pub unsafe extern "C" fn tvmd_fault_report(
    handle: *const TvmdController,
    report: *mut TvmdFaultReport,
) -> TvmdStatus {
    let Some(report) = report.as_mut() else {
        return TVMD_ERR_NULL_POINTER;
    };
    if let Err(status) = checked_size::<TvmdFaultReport>(report.size) {
        return status;
    }
    let controller = match inner(handle) {
        Ok(inner) => &inner.controller,
        Err(status) => return status,
    };
    let mut out = TvmdFaultReport {
        size: report.size,
        agent: -1,
        efficiency: f32::NAN,
        statistic: f32::NAN,
        threshold: f32::NAN,
        masked_agent: -1,
        ..TvmdFaultReport::default()
    };
    if let Some(r) = controller.fault_report() {
        out.statistic = r.statistic;
        out.threshold = r.threshold;
        let source = r.source;
        let named = |agent: usize, kind: &FaultKind<f32>, out: &mut TvmdFaultReport| {
            out.agent = i32::try_from(agent).unwrap_or(-1);
            match *kind {
                FaultKind::Loss => out.kind = TVMD_FAULT_KIND_LOSS,
                FaultKind::PartialLoss { efficiency } => {
                    out.kind = TVMD_FAULT_KIND_PARTIAL_LOSS;
                    out.efficiency = efficiency;
                }
                FaultKind::StuckGimbal => out.kind = TVMD_FAULT_KIND_STUCK_GIMBAL,
                FaultKind::LinkLoss => out.kind = TVMD_FAULT_KIND_LINK_LOSS,
            }
            out.source = match source {
                FaultSource::Residual => TVMD_FAULT_SOURCE_RESIDUAL,
                FaultSource::Reports => TVMD_FAULT_SOURCE_REPORTS,
            };
        };
        match &r.verdict {
            FaultVerdict::Nominal => out.verdict = TVMD_FAULT_VERDICT_NOMINAL,
            FaultVerdict::Unexplained => out.verdict = TVMD_FAULT_VERDICT_UNEXPLAINED,
            FaultVerdict::Suspected {
                agent,
                kind,
                periods,
            } => {
                out.verdict = TVMD_FAULT_VERDICT_SUSPECTED;
                out.periods = *periods;
                named(*agent, kind, &mut out);
            }
            FaultVerdict::Confirmed { agent, kind } => {
                out.verdict = TVMD_FAULT_VERDICT_CONFIRMED;
                named(*agent, kind, &mut out);
            }
        }
    }
    if let Some(m) = controller.fault_masking() {
        out.masked_agent = i32::try_from(m.agent).unwrap_or(-1);
        out.masked_hover_capable = u32::from(m.hover.is_some_and(|h| h.capable));
    }
    *report = out;
    TVMD_OK
}
