//! Agent fault detection's configuration in the C interface ([`TvmdFaultDetection`], the
//! `fault` field of [`crate::types::TvmdConfig`]; the report is [`crate::fault_report`]). The
//! core's detector (`docs/fault-detection.md`): each period the
//! disturbance observer's residual is compared with what each agent's loss, partial loss or
//! stuck gimbal would produce; a verdict that holds `persistence` periods is confirmed, and with
//! `TVMD_FAULT_MASK` the controller then masks the agent itself (as `tvmd_set_failures` would,
//! with the hover classification of the remaining team).
//!
//! A zero-initialized `TvmdFaultDetection` is off. It needs the observer
//! (`law.offset_free = TVMD_OFFSET_FREE_OBSERVER`): on with another law is
//! `TVMD_ERR_CONFIG_PARAMETER`.

use tvmd_core::{FaultDetection, FaultResponse};

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
        Ok(Some(FaultDetection::new(
            self.model_error,
            self.threshold,
            self.persistence,
            response,
        )?))
    }
}
