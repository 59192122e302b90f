//! The controller's fault detection settings ([`FaultDetection`], [`FaultResponse`]): the stated
//! relative model error, the threshold in its units, the persistence and what to do on a
//! confirmed loss (`docs/method.md`, "Beyond the paper: agent faults"). The detector runs inside
//! [`crate::Controller`] when [`crate::ControllerSettings::fault_detection`] is set.
//!
//! The noise is stated as a relative model error `epsilon` and resolved for the team at
//! [`crate::Controller::new`]: `sigma_f = epsilon m_C g`, `sigma_tau = epsilon m_C g l` with `l`
//! the largest agent distance `||p_i||`, so one setting fits every team (a loss of one of `n`
//! agents at hover is about `1 / (n epsilon)` noise units in force alone).

use crate::fault::{FaultDetector, ReportCheck};
use crate::foundation::error::ConfigError;
use crate::foundation::real::{lit, Real};
use crate::foundation::stored::tag_below;

/// Relative model error `epsilon` of [`FaultDetection::recommended`].
pub const FAULT_MODEL_ERROR: f64 = 0.015;
/// Threshold `k` (noise units) of [`FaultDetection::recommended`].
pub const FAULT_THRESHOLD: f64 = 5.0;
/// Bandwidth (rad/s) of the residual's slow baseline: the detector reads the residual's change
/// from it, so the persistent part of the model error (a mass, inertia or centre-of-mass
/// error, a steady wind) is not a fault, while a fault, which steps within a few periods, is
/// read whole (the baseline is held while the statistic is above half the threshold).
pub const FAULT_BASELINE_BANDWIDTH: f64 = 1.0;
/// The actuators' stated lag (s): the time constant of a first-order lag from the allocated
/// wrench to the delivered one (rotors and gimbal servos; the simulator's default conditions
/// have a 30 ms rotor lag and 40 rad/s servos). The detector adds what this lag leaves
/// undelivered back to the residual, so a changing command (the tilt manoeuvre) is not read as
/// a fault.
pub const FAULT_ACTUATOR_LAG: f64 = 0.03;
/// The share of the last jump of the commanded wrench added to the residual's stated noise:
/// what the lag model ([`FAULT_ACTUATOR_LAG`]) misses of a jump (rate limits, the servos' own
/// dynamics).
pub const FAULT_JUMP_SHARE: f64 = 0.1;
/// Persistence (periods) of [`FaultDetection::recommended`].
pub const FAULT_PERSISTENCE: u32 = 5;

/// What the controller does when the detector confirms an agent's loss. `repr(u8)`: the tag
/// checked raw by [`crate::Controller::storage_intact`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum FaultResponse {
    /// Report only ([`crate::Controller::fault_report`]): the caller keeps the decision.
    #[default]
    Report,
    /// Mask the agent ([`crate::Controller::set_failures`]) and report it with the hover-capability
    /// certificate ([`crate::Controller::fault_masking`]): a confirmed loss from either source
    /// (the residual or the agent's reports) and a confirmed link loss. Partial losses and
    /// stuck gimbals are reported only.
    Mask,
}

/// The controller's fault detection: the stated relative model error, the threshold in its
/// units, the persistence and the response, and the check of the agents' own reports (used
/// only for agents that report, [`crate::Controller::set_report`]: recommended values unless
/// [`Self::with_report_check`] states others). Validated: each finite and positive
/// (`persistence >= 1`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FaultDetection<T: Real> {
    model_error: T,
    threshold: T,
    persistence: u32,
    response: FaultResponse,
    reports: ReportCheck<T>,
}

impl<T: Real> FaultDetection<T> {
    /// `model_error` `epsilon`: one standard deviation of the residual without a fault, as a
    /// fraction of the team's weight (force) and of its weight times the largest arm
    /// (torque); `threshold` `k` in those units; `persistence` in periods.
    ///
    /// Errors: as [`FaultDetector::new`] ([`crate::ConfigField::FaultNoise`],
    /// [`crate::ConfigField::FaultThreshold`], [`crate::ConfigField::FaultPersistence`]).
    pub fn new(
        model_error: T,
        threshold: T,
        persistence: u32,
        response: FaultResponse,
    ) -> Result<Self, ConfigError> {
        FaultDetector::new(model_error, model_error, threshold, persistence)?;
        Ok(Self {
            model_error,
            threshold,
            persistence,
            response,
            reports: ReportCheck::recommended(),
        })
    }

    /// [`FAULT_MODEL_ERROR`], [`FAULT_THRESHOLD`], [`FAULT_PERSISTENCE`] with `response`.
    pub fn recommended(response: FaultResponse) -> Self {
        Self {
            model_error: lit(FAULT_MODEL_ERROR),
            threshold: lit(FAULT_THRESHOLD),
            persistence: FAULT_PERSISTENCE,
            response,
            reports: ReportCheck::recommended(),
        }
    }

    /// `epsilon`.
    pub fn model_error(&self) -> T {
        self.model_error
    }

    /// `k`.
    pub fn threshold(&self) -> T {
        self.threshold
    }

    /// Periods that confirm a candidate.
    pub fn persistence(&self) -> u32 {
        self.persistence
    }

    /// The response to a confirmed loss.
    pub fn response(&self) -> FaultResponse {
        self.response
    }

    /// The same detection with another response.
    pub fn with_response(self, response: FaultResponse) -> Self {
        Self { response, ..self }
    }

    /// The check of the agents' reports ([`ReportCheck::recommended`] unless set).
    pub fn report_check(&self) -> &ReportCheck<T> {
        &self.reports
    }

    /// The same detection with another report check.
    pub fn with_report_check(self, reports: ReportCheck<T>) -> Self {
        Self { reports, ..self }
    }

    /// The detector for a team of weight `m_C g` (N) whose farthest agent is `arm` (m) from
    /// the centre: `sigma_f = epsilon m_C g`, `sigma_tau = epsilon m_C g arm`.
    ///
    /// Errors: [`crate::ConfigField::FaultNoise`] when a noise is not finite and positive (e.g. a
    /// single agent at the centre).
    pub fn detector(&self, weight: T, arm: T) -> Result<FaultDetector<T>, ConfigError> {
        let force = self.model_error * weight;
        FaultDetector::new(force, force * arm, self.threshold, self.persistence)
    }
}

impl<T: Real> FaultDetection<T> {
    /// Whether the settings at `this` hold a valid response tag (two variants; the rest are
    /// numbers). Reads only.
    ///
    /// # Safety
    /// `this` is aligned and points to `size_of::<Self>()` readable bytes.
    pub(crate) unsafe fn storage_intact(this: *const Self) -> bool {
        tag_below(core::ptr::addr_of!((*this).response), 2)
    }
}

#[cfg(test)]
mod storage_tests {
    use super::*;
    use crate::foundation::stored::{accepts, refused_bytes};

    #[test]
    fn its_response_tag_is_checked() {
        let check = FaultDetection::<f32>::storage_intact;
        for response in [FaultResponse::Report, FaultResponse::Mask] {
            let d = FaultDetection::recommended(response);
            assert!(accepts(&d, check) && refused_bytes(&d, 2, check) == 1);
        }
    }
}
