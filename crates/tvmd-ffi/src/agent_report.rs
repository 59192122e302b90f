//! An agent's own report through the C interface ([`tvmd_set_agent_report`]): what PX4 reads
//! of each agent, its ESC telemetry (`esc_status`: the rotor's rpm and the message's
//! timestamp) and its servos' feedback (the two gimbal angles), for the controller's fault
//! detection to check against the commands it sent (`docs/fault-detection.md`).

use core::f32::consts::PI;

use tvmd_core::ReportError;

use crate::handle::{checked_size, inner_mut, TvmdController};
use crate::status::*;

/// One agent's report.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TvmdAgentReport {
    /// `sizeof(TvmdAgentReport)`, set by the caller.
    pub size: u32,
    /// The agent (`0 .. n_agents`).
    pub agent: u32,
    /// The rotor's measured speed (rpm, as `esc_status.esc[i].esc_rpm`), at least 0.
    pub rpm: f32,
    /// The rpm at the maximum thrust, for a configuration whose limits carry no rotor
    /// constants (speeds normalized to 1 at the maximum thrust: the speed is `rpm / max_rpm`);
    /// 0 when they carry them (the speed is `rpm * 2 pi / 60` rad/s). Finite, at least 0.
    pub max_rpm: f32,
    /// The measured inner gimbal angle `eta_x` (rad, servo feedback).
    pub eta_x: f32,
    /// The measured outer gimbal angle `eta_y` (rad, servo feedback).
    pub eta_y: f32,
    /// How long ago it was measured (s): now minus the message's timestamp, at least 0.
    pub age: f32,
}

/// Gives the controller agent `report->agent`'s newest report, checked at the next
/// `tvmd_step` against the commands it answers; the controller ages it by its period at each
/// step until the next report replaces it, and names a `TVMD_FAULT_KIND_LINK_LOSS` when it
/// grows older than the link timeout (0.1 s). Call it whenever a new `esc_status` (or servo
/// feedback) arrives, or every period with the newest one and its age: the same report given
/// again is not counted twice. Agents never reported are checked by the residual only.
///
/// Statuses: `TVMD_ERR_INPUT_NON_FINITE` (a NaN or infinite value),
/// `TVMD_ERR_INPUT_OUT_OF_RANGE` (a negative rpm, `max_rpm` or age),
/// `TVMD_ERR_REPORT_AGENT`, `TVMD_ERR_REPORT_DETECTION_OFF`; the agent's previous report is
/// kept.
///
/// # Safety
/// `handle` is null or points to a `TvmdController`; `report` is null or points to a
/// `TvmdAgentReport`.
#[no_mangle]
pub unsafe extern "C" fn tvmd_set_agent_report(
    handle: *mut TvmdController,
    report: *const TvmdAgentReport,
) -> TvmdStatus {
    let Some(report) = report.as_ref() else {
        return TVMD_ERR_NULL_POINTER;
    };
    if let Err(status) = checked_size::<TvmdAgentReport>(report.size) {
        return status;
    }
    let controller = match inner_mut(handle) {
        Ok(inner) => &mut inner.controller,
        Err(status) => return status,
    };
    let r = *report;
    if !r.max_rpm.is_finite() {
        return TVMD_ERR_INPUT_NON_FINITE;
    }
    if r.max_rpm < 0.0 {
        return TVMD_ERR_INPUT_OUT_OF_RANGE;
    }
    let speed = if r.max_rpm > 0.0 {
        r.rpm / r.max_rpm
    } else {
        r.rpm * (2.0 * PI / 60.0)
    };
    let agent = usize::try_from(r.agent).unwrap_or(usize::MAX);
    match controller.set_report_speed(agent, speed, r.eta_x, r.eta_y, r.age) {
        Ok(()) => TVMD_OK,
        Err(ReportError::NonFinite { .. }) => TVMD_ERR_INPUT_NON_FINITE,
        Err(ReportError::Negative { .. }) => TVMD_ERR_INPUT_OUT_OF_RANGE,
        Err(ReportError::Agent { .. }) => TVMD_ERR_REPORT_AGENT,
        Err(ReportError::DetectionOff) => TVMD_ERR_REPORT_DETECTION_OFF,
    }
}
