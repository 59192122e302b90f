//! Knowing an agent failed from its own reports ([`AgentReading`]): each report is checked
//! against the command it answers, through a model of the actuators' lag, and an agent whose
//! reports disagree with its commands for [`ReportCheck::persistence`] reports in a row is
//! named; an agent whose report is older than [`ReportCheck::link_timeout`] has lost its link.
//!
//! Per period ([`ReportState::update`]), for each working agent with a command in force
//! `(T_c, eta_x,c, eta_y,c)`:
//! - the model of the slowest healthy actuator: the thrust a first-order lag of the command
//!   (the controller's stated actuator lag, [`crate::fault_detection::FAULT_ACTUATOR_LAG`]), each gimbal angle moving towards its command at the slowest
//!   healthy servo rate ([`ReportCheck::servo_rate`]); with the model's change over the
//!   period, decayed by half a period, as its recent swing `s`;
//! - a healthy actuator lies between that model and the command in force (the fastest); a new
//!   report of age `a` is compared with that interval now, allowing the stated tolerance plus
//!   the swing over the report's age and the command's stated delay (`s ((a + d) / dt + 1)`,
//!   the model extrapolated back to when the report was measured): a thrust short of the
//!   interval by more is a thrust fault of efficiency `T_reported / min(T_model, T_c)`
//!   (a [`FaultKind::Loss`] at `<= 0.2`, else [`FaultKind::PartialLoss`]), an angle off by
//!   more a [`FaultKind::StuckGimbal`]. A thrust above the model names nothing (no kind is
//!   a runaway rotor; the residual sees it as unexplained);
//! - a report older than the link timeout is a [`FaultKind::LinkLoss`], confirmed at once
//!   (the timeout is its persistence); a report only older than usual is checked with the
//!   larger allowance its age gives, and is no fault by itself.
//!
//! Proven (by the construction): a report within the tolerance of an actuator that follows the
//! model or the command exactly is never named, whatever the command does; a report that does not arrive is
//! named only after the link timeout. Measured, not proven: how fast real faults are named and
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
    command_delay: T,
    link_timeout: T,
    persistence: u8,
}

impl<T: Real> ReportCheck<T> {
    /// `thrust_tolerance` (share of the maximum thrust), `angle_tolerance` (rad), `servo_rate`
    /// (rad/s), `command_delay` (s), `link_timeout` (s), `persistence` (reports in a row).
    ///
    /// Errors: [`ConfigError::NonFinite`] or [`ConfigError::Parameter`] naming
    /// [`ConfigField::ReportTolerance`], [`ConfigField::ReportServoRate`],
    /// [`ConfigField::ReportLinkTimeout`] (also for the command delay) or
    /// [`ConfigField::ReportPersistence`].
    pub fn new(
        thrust_tolerance: T,
        angle_tolerance: T,
        servo_rate: T,
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
            command_delay,
            link_timeout: positive(link_timeout, field)?,
            persistence,
        })
    }

    /// The recommended values ([`REPORT_THRUST_TOLERANCE`], [`REPORT_ANGLE_TOLERANCE`],
    /// [`REPORT_SERVO_RATE`], [`REPORT_COMMAND_DELAY`], [`REPORT_LINK_TIMEOUT`],
    /// [`REPORT_PERSISTENCE`]).
    pub fn recommended() -> Self {
        Self {
            thrust_tolerance: lit(REPORT_THRUST_TOLERANCE),
            angle_tolerance: lit(REPORT_ANGLE_TOLERANCE),
            servo_rate: lit(REPORT_SERVO_RATE),
            command_delay: lit(REPORT_COMMAND_DELAY),
            link_timeout: lit(REPORT_LINK_TIMEOUT),
            persistence: REPORT_PERSISTENCE,
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
    /// The model's recent change per period: thrust, angle.
    swing: [T; 2],
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
            swing: [T::zero(); 2],
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
    /// The model starts at the first command in force (non-zero: started).
    started: u8,
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
            started: 0,
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
        self.started = 0;
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
        let step = check.servo_rate * period;
        let half = lit::<T>(0.5);
        let started = self.started != 0;
        self.started = 1;
        let mut verdict = FaultVerdict::Nominal;
        let mut most = 0_u8;
        for (i, (slot, c)) in self.slots.iter_mut().zip(commands).enumerate() {
            // The model starts at the command: no swing from nothing to it.
            let before = if started {
                slot.model
            } else {
                [c.thrust, c.eta_x, c.eta_y]
            };
            slot.model = if started {
                let toward = |m: T, target: T| m + fmin(fmax(target - m, -step), step);
                [
                    before[0] + (c.thrust - before[0]) * closed,
                    toward(before[1], c.eta_x),
                    toward(before[2], c.eta_y),
                ]
            } else {
                [c.thrust, c.eta_x, c.eta_y]
            };
            let [t, x, y] = slot.model;
            let angle_change = fmax((x - before[1]).abs(), (y - before[2]).abs());
            slot.swing = [
                fmax((t - before[0]).abs(), slot.swing[0] * half),
                fmax(angle_change, slot.swing[1] * half),
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
                    Some(_) => (1, reading.thrust() / t),
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

/// What a new report says against the model and the command `c` in force: `None` when it
/// agrees within the allowance. A healthy actuator lies between the model (the slowest
/// healthy one) and the command (the fastest), each quantity apart.
fn disagreement<T: Real>(
    check: &ReportCheck<T>,
    slot: &Slot<T>,
    c: &AgentCommand<T>,
    reading: &AgentReading<T>,
    max_thrust: T,
    period: T,
) -> Option<FaultKind<T>> {
    let [t, x, y] = slot.model;
    // Periods the model is extrapolated back over: the report's age and the command's delay.
    let lead = (reading.age() + check.command_delay) / period + T::one();
    let thrust_allowed = check.thrust_tolerance * max_thrust + slot.swing[0] * lead;
    let angle_allowed = check.angle_tolerance + slot.swing[1] * lead;
    let low = fmin(t, c.thrust);
    if low - reading.thrust() > thrust_allowed {
        // `low > thrust_allowed > 0`: the efficiency is in `[0, 1)`.
        return Some(loss_kind(T::one() - reading.thrust() / low));
    }
    // The distance of a reported angle from the interval between the model and the command.
    let outside = |r: T, m: T, cmd: T| fmax(fmax(fmin(m, cmd) - r, r - fmax(m, cmd)), T::zero());
    let off = fmax(
        outside(reading.eta_x(), x, c.eta_x),
        outside(reading.eta_y(), y, c.eta_y),
    );
    (off > angle_allowed).then_some(FaultKind::StuckGimbal)
}

#[cfg(test)]
#[path = "reports_tests.rs"]
mod tests;
