//! Agent fault detection in the controller (`[fault_detection]`, `docs/method.md`, "Beyond the
//! paper: agent faults"): off unless the table is given.
//!
//! ```toml
//! [fault_detection]          # every key optional; the core's recommended values by default
//! model_error = 0.015        # the residual's noise, as a fraction of the weight (and weight x arm)
//! threshold = 5.0            # k, in those units
//! persistence = 5            # controller periods that confirm an agent
//! response = "mask"          # or "report": the controller masks a confirmed lost agent itself
//!
//! [fault_detection.report_check]   # the agents' reports' check, crate::ReportCheckConfig
//! link_timeout = 0.1
//! ```
//!
//! It reads the disturbance observer's measurement, so it needs `law.offset_free` to be the
//! observer (the default law).

use serde::{Deserialize, Serialize};

use crate::checks::check_pos;
use crate::error::invalid;
use crate::{OffsetFreeConfig, ReportCheckConfig, ScenarioError};

/// The core's recommended values (`tvmd_core::FaultDetection::recommended`).
pub use tvmd_core::controller::{FAULT_MODEL_ERROR, FAULT_PERSISTENCE, FAULT_THRESHOLD};

/// What the controller does on a confirmed loss.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum FaultResponseConfig {
    /// Report the verdict only (the log's `/fault`, the summary); the scenario's failure flags
    /// stay what they were.
    #[default]
    Report,
    /// Mask the agent; the simulator's `failure_response` then runs as for an informed failure.
    Mask,
}

/// `[fault_detection]`: the detector's settings.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct FaultDetectionConfig {
    /// Relative model error `epsilon` (the noise unit); [`FAULT_MODEL_ERROR`].
    pub model_error: f64,
    /// Threshold `k` in noise units; [`FAULT_THRESHOLD`].
    pub threshold: f64,
    /// Controller periods that confirm an agent; [`FAULT_PERSISTENCE`].
    pub persistence: u32,
    /// `"report"` (default) or `"mask"`.
    pub response: FaultResponseConfig,
    /// The check of the agents' reports (`[fault_detection.report_check]`, read with
    /// `[reports]`); the core's recommended values by default.
    pub report_check: ReportCheckConfig,
}

impl Default for FaultDetectionConfig {
    fn default() -> Self {
        Self {
            model_error: FAULT_MODEL_ERROR,
            threshold: FAULT_THRESHOLD,
            persistence: FAULT_PERSISTENCE,
            response: FaultResponseConfig::Report,
            report_check: ReportCheckConfig::default(),
        }
    }
}

impl FaultDetectionConfig {
    /// The recommended detector with `response`.
    pub fn with_response(response: FaultResponseConfig) -> Self {
        Self {
            response,
            ..Self::default()
        }
    }

    /// Range checks naming the field, and the observer it needs (`offset_free` of the law).
    pub fn validate(&self, offset_free: &OffsetFreeConfig) -> Result<(), ScenarioError> {
        check_pos("fault_detection.model_error", self.model_error)?;
        check_pos("fault_detection.threshold", self.threshold)?;
        if self.persistence == 0 {
            return Err(invalid("fault_detection.persistence", "must be at least 1"));
        }
        self.report_check.validate()?;
        if !matches!(offset_free, OffsetFreeConfig::Observer { .. }) {
            return Err(invalid(
                "fault_detection",
                "needs the disturbance observer (law.offset_free = { kind = \"observer\" }, \
                 the default law)",
            ));
        }
        Ok(())
    }
}
