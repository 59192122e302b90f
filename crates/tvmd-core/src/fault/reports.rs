//! Knowing an agent failed from its own reports ([`AgentReading`]): each report is checked
//! against the command it answers, through a model of the actuators' lag, and an agent whose
//! reports disagree with its commands for [`ReportCheck::persistence`] reports in a row is
//! named; an agent whose report is older than [`ReportCheck::link_timeout`] has lost its link.
//!
//! Per period ([`ReportState::update`]), for each working agent with a command in force
//! `(T_c, eta_x,c, eta_y,c)`:
//! - the model of the slowest healthy actuator: the thrust a first-order lag of the command
//!   (the controller's stated actuator lag, [`crate::fault_detection::FAULT_ACTUATOR_LAG`]),
//!   each gimbal angle a first-order lag of its command ([`ReportCheck::servo_lag`]) turning at
//!   most at the slowest healthy servo rate ([`ReportCheck::servo_rate`]), both from rest (zero
//!   thrust, gimbal centred) when the check starts;
//! - a healthy actuator lies between that model and the command (the fastest actuator), but a
//!   report shows it as it was `a` (the report's age) plus `d` (the command link's stated
//!   delay) ago, and a fast rotor follows a chattering command (the allocation at the
//!   attainable set's boundary) within a period. So the check keeps envelopes of both: the
//!   lowest thrust and the lowest and highest angles, each the running minimum (maximum) of
//!   the model and the command that forgets at a stated rate `r`
//!   ([`ReportCheck::thrust_forget`], [`ReportCheck::angle_forget`]): `low_k = min(model_k,
//!   c_k, low_(k-1) + r dt)`. A new report is compared with the envelope widened by the
//!   tolerance and by what it forgot since the report was measured, `r (a + d + dt)`: a thrust
//!   short of it is a thrust fault of efficiency `T_reported / min(T_model, T_c)` (a
//!   [`FaultKind::Loss`] at `<= 0.2`, else [`FaultKind::PartialLoss`]), an angle outside it a
//!   [`FaultKind::StuckGimbal`]. A thrust above names nothing (no kind is a runaway rotor; the
//!   residual sees it as unexplained);
//! - a report older than the link timeout is a [`FaultKind::LinkLoss`], confirmed at once
//!   (the timeout is its persistence); a report only older than usual is checked with the
//!   larger allowance its age gives, and is no fault by itself.
//!
//! Proven (by the construction): a report, within the tolerance, of an actuator that was at
//! that moment between the model and any command sent within the report's age and the stated
//! delay (plus a period) is never named, whatever the commands did; a report that does not
//! arrive is named only after the link timeout. Measured, not proven: how fast real faults are named and
//! that the model's allowance covers the real actuators' lag and the command link's jitter
//! (the simulator's fault study, `docs/fault-detection.md`). What the reports cannot see: a
//! damaged propeller at full speed (the ESC measures speed, not thrust), a report that lies;
//! the residual ([`crate::fault::FaultState`]) keeps running for those.

use super::reading::AgentReading;
use super::{loss_kind, FaultKind, FaultVerdict};
use crate::agent::command::AgentCommand;
use crate::agent::failure::FailureMask;
use crate::foundation::error::{positive, ConfigError, ConfigField};
use crate::foundation::real::{fmax, fmin, lit, Real};

/// [`ReportCheck::thrust_tolerance`] of [`ReportCheck::recommended`]: a tenth of the maximum
/// thrust (an ESC's speed reading is good to a few percent; the rotor model's `k` to ten).
pub const REPORT_THRUST_TOLERANCE: f64 = 0.1;
/// [`ReportCheck::angle_tolerance`] of [`ReportCheck::recommended`] (rad): about 3 degrees,
/// ten times a servo potentiometer's typical noise.
pub const REPORT_ANGLE_TOLERANCE: f64 = 0.05;
/// [`ReportCheck::servo_rate`] of [`ReportCheck::recommended`] (rad/s): the slowest rate a
/// healthy gimbal servo turns at (the simulator's Monte Carlo servos are rate-limited at 6
/// rad/s; a hobby servo's 60 degrees in 0.1 s is 10 rad/s).
pub const REPORT_SERVO_RATE: f64 = 6.0;
/// [`ReportCheck::servo_lag`] of [`ReportCheck::recommended`] (s): the time constant of the
/// slowest healthy servo below its rate limit (the simulator's Monte Carlo servos, second order
/// at 40 rad/s and damping 0.8, settle like a first-order lag of `2 zeta / w_n` = 0.04 s).
pub const REPORT_SERVO_LAG: f64 = 0.05;
/// [`ReportCheck::thrust_forget`] of [`ReportCheck::recommended`] (share of the maximum thrust
/// per second): over a report's usual 40 ms (20 ms latency, 10 ms of delay, a period) the
/// thrust envelope forgets a tenth of the maximum thrust, as much as its tolerance.
pub const REPORT_THRUST_FORGET: f64 = 2.5;
/// [`ReportCheck::angle_forget`] of [`ReportCheck::recommended`] (rad/s): 0.1 rad over 40 ms.
pub const REPORT_ANGLE_FORGET: f64 = 2.5;
/// [`ReportCheck::command_delay`] of [`ReportCheck::recommended`] (s): the command link's
/// latency and jitter the allowance covers.
pub const REPORT_COMMAND_DELAY: f64 = 0.01;
/// [`ReportCheck::link_timeout`] of [`ReportCheck::recommended`] (s): at 100 reports a second
/// and 20 ms latency, eight reports lost in a row (at 10% loss, once in `10^8` reports).
pub const REPORT_LINK_TIMEOUT: f64 = 0.1;
/// [`ReportCheck::persistence`] of [`ReportCheck::recommended`] (reports in a row).
pub const REPORT_PERSISTENCE: u8 = 2;

/// The report check's settings. Validated: tolerances, servo rate and link timeout finite and
/// positive, the command delay finite and at least 0, the persistence at least 1.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReportCheck<T: Real> {
    thrust_tolerance: T,
    angle_tolerance: T,
    servo_rate: T,
    servo_lag: T,
    command_delay: T,
    link_timeout: T,
    persistence: u8,
    thrust_forget: T,
    angle_forget: T,
}

impl<T: Real> ReportCheck<T> {
    /// `thrust_tolerance` (share of the maximum thrust), `angle_tolerance` (rad), `servo_rate`
    /// (rad/s) and `servo_lag` (s) of the slowest healthy servo, `command_delay` (s),
    /// `link_timeout` (s), `persistence` (reports in a row).
    ///
    /// Errors: [`ConfigError::NonFinite`] or [`ConfigError::Parameter`] naming
    /// [`ConfigField::ReportTolerance`], [`ConfigField::ReportServoRate`] (also for the
    /// servo lag),
    /// [`ConfigField::ReportLinkTimeout`] (also for the command delay) or
    /// [`ConfigField::ReportPersistence`].
    pub fn new(
        thrust_tolerance: T,
        angle_tolerance: T,
        servo_rate: T,
        servo_lag: T,
        command_delay: T,
        link_timeout: T,
        persistence: u8,
    ) -> Result<Self, ConfigError> {
        if persistence == 0 {
            return Err(ConfigError::Parameter {
                field: ConfigField::ReportPersistence,
            });
        }
        let field = ConfigField::ReportLinkTimeout;
        if !command_delay.is_finite() {
            return Err(ConfigError::NonFinite { field });
        }
        if command_delay < T::zero() {
            return Err(ConfigError::Parameter { field });
        }
        Ok(Self {
            thrust_tolerance: positive(thrust_tolerance, ConfigField::ReportTolerance)?,
            angle_tolerance: positive(angle_tolerance, ConfigField::ReportTolerance)?,
            servo_rate: positive(servo_rate, ConfigField::ReportServoRate)?,
            servo_lag: positive(servo_lag, ConfigField::ReportServoRate)?,
            command_delay,
            link_timeout: positive(link_timeout, field)?,
            persistence,
            thrust_forget: lit(REPORT_THRUST_FORGET),
            angle_forget: lit(REPORT_ANGLE_FORGET),
        })
    }

    /// The same check whose envelopes forget at `thrust` (share of the maximum thrust per
    /// second) and `angle` (rad/s) ([`REPORT_THRUST_FORGET`], [`REPORT_ANGLE_FORGET`] unless
    /// set). Errors: [`ConfigError::NonFinite`] or [`ConfigError::Parameter`] naming
    /// [`ConfigField::ReportTolerance`] unless both are finite and positive.
    pub fn with_forgetting(self, thrust: T, angle: T) -> Result<Self, ConfigError> {
        Ok(Self {
            thrust_forget: positive(thrust, ConfigField::ReportTolerance)?,
            angle_forget: positive(angle, ConfigField::ReportTolerance)?,
            ..self
        })
    }

    /// The thrust envelope's forgetting rate (share of the maximum thrust per second).
    pub fn thrust_forget(&self) -> T {
        self.thrust_forget
    }

    /// The angle envelopes' forgetting rate (rad/s).
    pub fn angle_forget(&self) -> T {
        self.angle_forget
    }

    /// The recommended values ([`REPORT_THRUST_TOLERANCE`], [`REPORT_ANGLE_TOLERANCE`],
    /// [`REPORT_SERVO_RATE`], [`REPORT_SERVO_LAG`], [`REPORT_COMMAND_DELAY`], [`REPORT_LINK_TIMEOUT`],
    /// [`REPORT_PERSISTENCE`]).
    pub fn recommended() -> Self {
        Self {
            thrust_tolerance: lit(REPORT_THRUST_TOLERANCE),
            angle_tolerance: lit(REPORT_ANGLE_TOLERANCE),
            servo_rate: lit(REPORT_SERVO_RATE),
            servo_lag: lit(REPORT_SERVO_LAG),
            command_delay: lit(REPORT_COMMAND_DELAY),
            link_timeout: lit(REPORT_LINK_TIMEOUT),
            persistence: REPORT_PERSISTENCE,
            thrust_forget: lit(REPORT_THRUST_FORGET),
            angle_forget: lit(REPORT_ANGLE_FORGET),
        }
    }

    /// The thrust tolerance (share of the maximum thrust).
    pub fn thrust_tolerance(&self) -> T {
        self.thrust_tolerance
    }

    /// The angle tolerance (rad).
    pub fn angle_tolerance(&self) -> T {
        self.angle_tolerance
    }

    /// The slowest healthy servo rate (rad/s) the model turns at.
    pub fn servo_rate(&self) -> T {
        self.servo_rate
    }

    /// The slowest healthy servo's time constant (s) below its rate limit.
    pub fn servo_lag(&self) -> T {
        self.servo_lag
    }

    /// The command link's stated delay (s).
    pub fn command_delay(&self) -> T {
        self.command_delay
    }

    /// The age (s) past which an agent's link is taken as gone.
    pub fn link_timeout(&self) -> T {
        self.link_timeout
    }

    /// Reports in a row that confirm a fault.
    pub fn persistence(&self) -> u8 {
        self.persistence
    }
}

/// One agent's report, model and count: plain numbers only (every bit pattern is a value, so
/// a controller in memory a stray write changed, [`crate::Controller::storage_intact`], holds
/// no invalid tag here; a wrong number is a wrong reading, never undefined behaviour).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Slot<T: Real> {
    /// Thrust, `eta_x`, `eta_y`, age of the newest report; no report while the age is not finite (NaN).
    reading: [T; 4],
    /// A report not yet checked (non-zero).
    fresh: u8,
    /// The modelled thrust and angles now.
    model: [T; 3],
    /// The envelopes of the model and the commands: the lowest thrust, the lowest and the
    /// highest `eta_x` and `eta_y`.
    envelope: [T; 5],
    /// Disagreeing reports in a row.
    strikes: u8,
    /// The last disagreement's kind: 1 a thrust short by `1 - efficiency`, 2 an angle off,
    /// anything else none.
    kind: u8,
    efficiency: T,
}

impl<T: Real> Slot<T> {
    fn new() -> Self {
        Self {
            reading: [T::zero(), T::zero(), T::zero(), lit(f64::NAN)],
            fresh: 0,
            model: [T::zero(); 3],
            envelope: [T::zero(); 5],
            strikes: 0,
            kind: 0,
            efficiency: T::zero(),
        }
    }

    fn reading(&self) -> Option<AgentReading<T>> {
        let [thrust, eta_x, eta_y, age] = self.reading;
        AgentReading::new(thrust, eta_x, eta_y, age).ok()
    }

    fn kind(&self) -> Option<FaultKind<T>> {
        match self.kind {
            1 => Some(loss_kind(T::one() - self.efficiency)),
            2 => Some(FaultKind::StuckGimbal),
            _ => None,
        }
    }
}

/// The report check's state: per agent its newest report, its actuators' model and its count
/// of disagreeing reports. `N` slots, no allocation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReportState<T: Real, const N: usize> {
    slots: [Slot<T>; N],
}

impl<T: Real, const N: usize> Default for ReportState<T, N> {
    fn default() -> Self {
        Self::new()
    }
}

impl<T: Real, const N: usize> ReportState<T, N> {
    /// No reports, no model.
    pub fn new() -> Self {
        Self {
            slots: [Slot::new(); N],
        }
    }

    /// Whether any agent has reported.
    pub fn any(&self) -> bool {
        self.slots.iter().any(|s| s.reading[3].is_finite())
    }

    /// Agent `agent`'s newest report, aged to now.
    pub fn reading(&self, agent: usize) -> Option<AgentReading<T>> {
        self.slots.get(agent).and_then(Slot::reading)
    }

    /// Takes agent `agent`'s report (`agent < N`, checked by the caller against the team).
    /// It is new (checked at the next [`Self::update`]) unless it is the report held already,
    /// given again: an age within half a `period` of the held one's or older.
    pub fn set(&mut self, agent: usize, reading: AgentReading<T>, period: T) {
        let Some(slot) = self.slots.get_mut(agent) else {
            return;
        };
        let held = slot.reading[3];
        if !held.is_finite() || reading.age() < held - period * lit(0.5) {
            slot.fresh = 1;
        }
        slot.reading = [
            reading.thrust(),
            reading.eta_x(),
            reading.eta_y(),
            reading.age(),
        ];
    }

    /// Forgets the models and the counts (a reset, a landing); the reports are kept.
    pub fn forget(&mut self) {
        for s in &mut self.slots {
            *s = Slot {
                reading: s.reading,
                ..Slot::new()
            };
        }
    }

    /// Forgets the reports too.
    pub fn clear(&mut self) {
        *self = Self::new();
    }

    /// One period of length `period` whose commands in force were `commands`: advances the
    /// models (the thrust's a first-order lag of time constant `rotor_lag` s), checks the new reports, ages every report by `period` and returns the verdict
    /// (the first confirmed agent, else the suspected one with the most disagreeing reports,
    /// else [`FaultVerdict::Nominal`]). Agents `failures` masks are skipped and their counts
    /// forgotten. `max_thrust` (N) scales the thrust tolerance.
    pub fn update(
        &mut self,
        check: &ReportCheck<T>,
        commands: &[AgentCommand<T>; N],
        failures: &FailureMask<N>,
        max_thrust: T,
        period: T,
        rotor_lag: T,
    ) -> FaultVerdict<T> {
        let closed = T::one() - (-(period / rotor_lag)).exp();
        let servo_closed = T::one() - (-(period / check.servo_lag)).exp();
        let step = check.servo_rate * period;
        let (forget_t, forget_a) = (
            check.thrust_forget * max_thrust * period,
            check.angle_forget * period,
        );
        let mut verdict = FaultVerdict::Nominal;
        let mut most = 0_u8;
        for (i, (slot, c)) in self.slots.iter_mut().zip(commands).enumerate() {
            // From rest at the start (the model is zero then): between rest and the command a
            // healthy actuator of any speed is never named while the model catches up.
            let before = slot.model;
            let toward = |m: T, target: T| m + fmin(fmax((target - m) * servo_closed, -step), step);
            slot.model = [
                before[0] + (c.thrust - before[0]) * closed,
                toward(before[1], c.eta_x),
                toward(before[2], c.eta_y),
            ];
            let [t, x, y] = slot.model;
            let [low, x_low, x_high, y_low, y_high] = slot.envelope;
            slot.envelope = [
                fmin(fmin(t, c.thrust), low + forget_t),
                fmin(fmin(x, c.eta_x), x_low + forget_a),
                fmax(fmax(x, c.eta_x), x_high - forget_a),
                fmin(fmin(y, c.eta_y), y_low + forget_a),
                fmax(fmax(y, c.eta_y), y_high - forget_a),
            ];
            let Some(reading) = slot.reading() else {
                continue;
            };
            slot.reading[3] = reading.aged(period).age();
            let fresh = core::mem::take(&mut slot.fresh) != 0;
            if failures.is_failed(i) {
                slot.strikes = 0;
                continue;
            }
            let confirmed = matches!(verdict, FaultVerdict::Confirmed { .. });
            if reading.age() > check.link_timeout {
                slot.strikes = 0;
                if !confirmed {
                    verdict = FaultVerdict::Confirmed {
                        agent: i,
                        kind: FaultKind::LinkLoss,
                    };
                }
                continue;
            }
            if fresh {
                let kind = disagreement(check, slot, c, &reading, max_thrust, period);
                (slot.kind, slot.efficiency) = match kind {
                    Some(FaultKind::StuckGimbal) => (2, T::zero()),
                    Some(FaultKind::PartialLoss { efficiency }) => (1, efficiency),
                    Some(_) => (1, T::zero()),
                    None => (0, T::zero()),
                };
                slot.strikes = match kind {
                    Some(_) => slot.strikes.saturating_add(1),
                    None => 0,
                };
            }
            let (Some(kind), true) = (slot.kind(), slot.strikes > 0) else {
                continue;
            };
            if slot.strikes >= check.persistence {
                if !confirmed {
                    verdict = FaultVerdict::Confirmed { agent: i, kind };
                }
            } else if slot.strikes > most && !confirmed {
                most = slot.strikes;
                verdict = FaultVerdict::Suspected {
                    agent: i,
                    kind,
                    periods: u32::from(slot.strikes),
                };
            }
        }
        verdict
    }
}

/// What a new report says against the envelopes (`c`: the command in force): `None` when it
/// agrees within the allowance.
fn disagreement<T: Real>(
    check: &ReportCheck<T>,
    slot: &Slot<T>,
    c: &AgentCommand<T>,
    reading: &AgentReading<T>,
    max_thrust: T,
    period: T,
) -> Option<FaultKind<T>> {
    let [low, x_low, x_high, y_low, y_high] = slot.envelope;
    // What the envelopes forgot since the report was measured (and the command's delay).
    let since = reading.age() + check.command_delay + period;
    let thrust_allowed = (check.thrust_tolerance + check.thrust_forget * since) * max_thrust;
    let angle_allowed = check.angle_tolerance + check.angle_forget * since;
    if low - reading.thrust() > thrust_allowed {
        // `min(T_model, T_c) >= low > thrust_allowed > 0`: the efficiency is in `[0, 1)`.
        let expected = fmin(slot.model[0], c.thrust);
        return Some(loss_kind(T::one() - reading.thrust() / expected));
    }
    let outside = |r: T, lo: T, hi: T| fmax(fmax(lo - r, r - hi), T::zero());
    let off = fmax(
        outside(reading.eta_x(), x_low, x_high),
        outside(reading.eta_y(), y_low, y_high),
    );
    (off > angle_allowed).then_some(FaultKind::StuckGimbal)
}

#[cfg(test)]
#[path = "reports_tests.rs"]
mod tests;
