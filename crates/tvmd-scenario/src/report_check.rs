//! The check of the agents' own reports (`[fault_detection.report_check]`, the core's
//! `tvmd_core::ReportCheck`): read only when the controller gets reports (`[reports]`).
//!
//! ```toml
//! [fault_detection.report_check]  # every key optional; the core's recommended values by default
//! thrust_tolerance = 0.1          # share of the maximum thrust
//! angle_tolerance = 0.05          # rad
//! servo_rate = 6.0                # rad/s, the slowest healthy gimbal servo
//! servo_lag = 0.05                # s, its time constant below the rate limit
//! command_delay = 0.01            # s, the command link's latency and jitter
//! link_timeout = 0.1              # s, a report older than this: the link is gone
//! persistence = 2                 # reports in a row that confirm a fault
//! thrust_forget = 2.5             # share of the maximum thrust per second
//! angle_forget = 2.5              # rad/s
//! ```

use serde::{Deserialize, Serialize};
use tvmd_core::ReportCheck;

use crate::checks::{check_nonneg, check_pos};
use crate::core_float::{to_core, CoreFloat};
use crate::error::invalid;
use crate::ScenarioError;

/// `[fault_detection.report_check]`: the report check's settings, each the core's recommended
/// value ([`ReportCheck::recommended`], the default) unless given.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ReportCheckConfig {
    /// Thrust tolerance (share of the maximum thrust), finite and > 0.
    pub thrust_tolerance: f64,
    /// Gimbal angle tolerance (rad), finite and > 0.
    pub angle_tolerance: f64,
    /// Slowest healthy servo rate (rad/s), finite and > 0.
    pub servo_rate: f64,
    /// Slowest healthy servo's time constant (s), finite and > 0.
    pub servo_lag: f64,
    /// The command link's stated delay (s), finite and >= 0.
    pub command_delay: f64,
    /// Report age (s) past which the link is gone, finite and > 0.
    pub link_timeout: f64,
    /// Reports in a row that confirm a fault, 1 to 255.
    pub persistence: u32,
    /// Thrust envelope's forgetting (share of the maximum thrust per second), finite and > 0.
    pub thrust_forget: f64,
    /// Angle envelopes' forgetting (rad/s), finite and > 0.
    pub angle_forget: f64,
}

impl Default for ReportCheckConfig {
    /// The core's recommended check.
    fn default() -> Self {
        let r = ReportCheck::<f64>::recommended();
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
}

impl ReportCheckConfig {
    /// Range checks, each error naming its field (`fault_detection.report_check.<field>`).
    pub fn validate(&self) -> Result<(), ScenarioError> {
        let field = |name: &str| format!("fault_detection.report_check.{name}");
        for (name, v) in [
            ("thrust_tolerance", self.thrust_tolerance),
            ("angle_tolerance", self.angle_tolerance),
            ("servo_rate", self.servo_rate),
            ("servo_lag", self.servo_lag),
            ("link_timeout", self.link_timeout),
            ("thrust_forget", self.thrust_forget),
            ("angle_forget", self.angle_forget),
        ] {
            check_pos(&field(name), v)?;
        }
        check_nonneg(&field("command_delay"), &[self.command_delay])?;
        if !(1..=u32::from(u8::MAX)).contains(&self.persistence) {
            return Err(invalid(
                field("persistence"),
                format!("must be in [1, 255], got {}", self.persistence),
            ));
        }
        Ok(())
    }

    /// The core's report check in `T`, after [`Self::validate`].
    pub fn to_core<T: CoreFloat>(&self) -> Result<ReportCheck<T>, ScenarioError> {
        self.validate()?;
        // `validate` bounds the persistence to a u8 and every number as the core does.
        let persistence = u8::try_from(self.persistence)
            .map_err(|_| invalid("fault_detection.report_check.persistence", "too large"))?;
        ReportCheck::new(
            to_core(self.thrust_tolerance),
            to_core(self.angle_tolerance),
            to_core(self.servo_rate),
            to_core(self.servo_lag),
            to_core(self.command_delay),
            to_core(self.link_timeout),
            persistence,
        )
        .and_then(|c| c.with_forgetting(to_core(self.thrust_forget), to_core(self.angle_forget)))
        .map_err(|e| {
            invalid(
                "fault_detection.report_check",
                format!("rejected by the controller: {e}"),
            )
        })
    }
}
