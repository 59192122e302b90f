//! Agent fault detection's configuration in the C interface ([`TvmdFaultDetection`], the
//! `fault` field of [`crate::types::TvmdConfig`]; the report is [`crate::fault_report`]). The
//! core's detector (`docs/fault-detection.md`): each period the
//! disturbance observer's residual is compared with what each agent's loss, partial loss or
//! stuck gimbal would produce; a verdict that holds `persistence` periods is confirmed, and with
//! `TVMD_FAULT_MASK` the controller then masks the agent itself (as `tvmd_set_failures` would,
//! with the hover classification of the remaining team).
//!
//! The check of the agents' own reports (`tvmd_set_agent_report`) has its settings in
//! `reports` ([`TvmdReportCheck`]; the recommended ones in both library configurations).
//!
//! A zero-initialized `TvmdFaultDetection` is off. It needs the observer
//! (`law.offset_free = TVMD_OFFSET_FREE_OBSERVER`): on with another law is
//! `TVMD_ERR_CONFIG_PARAMETER`.

use tvmd_core::error::{ConfigError, ConfigField};
use tvmd_core::{FaultDetection, FaultResponse, ReportCheck};

use crate::status::ConvertError;

/// `fault.mode`: no detection (the paper's and the default configurations).
pub const TVMD_FAULT_OFF: u32 = 0;
/// `fault.mode`: detect and report (`tvmd_fault_report`); the caller keeps the decision.
pub const TVMD_FAULT_REPORT: u32 = 1;
/// `fault.mode`: detect, report, and mask an agent whose loss is confirmed.
pub const TVMD_FAULT_MASK: u32 = 2;

/// Fault detection settings. `tvmd_config_default` and `tvmd_config_paper` set the mode off and
/// the recommended numbers, so switching the mode on uses them.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TvmdFaultDetection {
    /// One of `TVMD_FAULT_*` (`OFF`, `REPORT`, `MASK`).
    pub mode: u32,
    /// The stated relative model error `epsilon`: one standard deviation of the residual
    /// without a fault, as a fraction of the team's weight (force) and of its weight times its
    /// largest arm (torque); finite and positive (recommended 0.015).
    pub model_error: f32,
    /// The threshold `k` in those noise units; finite and positive (recommended 5).
    pub threshold: f32,
    /// Periods a verdict must hold to be confirmed, `>= 1` (recommended 5).
    pub persistence: u32,
    /// The check of the agents' reports (read only for agents that report).
    pub reports: TvmdReportCheck,
}

/// The check of the agents' own reports (`tvmd_set_agent_report`; docs/fault-detection.md,
/// "The agents' reports"). Both library configurations set the recommended values. Every
/// number finite and positive but `command_delay` (finite, `>= 0`); otherwise `tvmd_create`
/// (or `tvmd_reconfigure`) refuses it with `TVMD_ERR_CONFIG_NON_FINITE` or
/// `TVMD_ERR_CONFIG_PARAMETER` when the mode is on.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TvmdReportCheck {
    /// A report's thrust tolerance, as a share of the maximum thrust (recommended 0.1).
    pub thrust_tolerance: f32,
    /// A report's gimbal angle tolerance (rad, recommended 0.05).
    pub angle_tolerance: f32,
    /// The slowest healthy gimbal servo's rate (rad/s, recommended 6).
    pub servo_rate: f32,
    /// The slowest healthy servo's time constant below its rate limit (s, recommended 0.05).
    pub servo_lag: f32,
    /// The command link's latency and jitter the allowance covers (s, `>= 0`, recommended
    /// 0.01).
    pub command_delay: f32,
    /// A report older than this (s) says the agent's link is gone (recommended 0.1).
    pub link_timeout: f32,
    /// Reports in a row that confirm a fault, 1 to 255 (recommended 2).
    pub persistence: u32,
    /// What the thrust envelope forgets, as a share of the maximum thrust per second
    /// (recommended 2.5).
    pub thrust_forget: f32,
    /// What the angle envelopes forget (rad/s, recommended 2.5).
    pub angle_forget: f32,
}

impl TvmdReportCheck {
    /// The core's recommended check.
    fn recommended() -> Self {
        let r = ReportCheck::<f32>::recommended();
        Self {
            thrust_tolerance: r.thrust_tolerance(),
            angle_tolerance: r.angle_tolerance(),
            servo_rate: r.servo_rate(),
            servo_lag: r.servo_lag(),
            command_delay: r.command_delay(),
            link_timeout: r.link_timeout(),
            persistence: u32::from(r.persistence()),
            thrust_forget: r.thrust_forget(),
            angle_forget: r.angle_forget(),
        }
    }

    /// The core's check (errors as [`ReportCheck::new`]; a persistence over 255 names
    /// [`ConfigField::ReportPersistence`]).
    fn to_core(self) -> Result<ReportCheck<f32>, ConfigError> {
        let persistence = u8::try_from(self.persistence).map_err(|_| ConfigError::Parameter {
            field: ConfigField::ReportPersistence,
        })?;
        ReportCheck::new(
            self.thrust_tolerance,
            self.angle_tolerance,
            self.servo_rate,
            self.servo_lag,
            self.command_delay,
            self.link_timeout,
            persistence,
        )?
        .with_forgetting(self.thrust_forget, self.angle_forget)
    }
}

impl TvmdFaultDetection {
    /// The recommended numbers with the mode off.
    pub(crate) fn recommended_off() -> Self {
        let r = FaultDetection::<f32>::recommended(FaultResponse::Report);
        Self {
            mode: TVMD_FAULT_OFF,
            model_error: r.model_error(),
            threshold: r.threshold(),
            persistence: r.persistence(),
            reports: TvmdReportCheck::recommended(),
        }
    }

    /// The core's setting (`None` when off).
    pub(crate) fn to_core(self) -> Result<Option<FaultDetection<f32>>, ConvertError> {
        let response = match self.mode {
            TVMD_FAULT_OFF => return Ok(None),
            TVMD_FAULT_REPORT => FaultResponse::Report,
            TVMD_FAULT_MASK => FaultResponse::Mask,
            _ => return Err(ConvertError::EnumValue),
        };
        let detection =
            FaultDetection::new(self.model_error, self.threshold, self.persistence, response)?;
        Ok(Some(detection.with_report_check(self.reports.to_core()?)))
    }
}
