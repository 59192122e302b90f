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
//! Proven (by the construction: `low_k <= min(model_j, c_j) + r (k - j) dt` for every earlier
//! period `j`): a report, within the tolerance, of an actuator that was when measured between
//! the model and any command sent within the report's age and the stated delay (plus a period)
//! is never named, whatever the commands did; a report that does not arrive is named only
//! after the link timeout. Measured, not proven: how fast real faults are named and that the
//! model and the allowances cover the real actuators' lag and the command link's jitter (the
//! simulator's fault study, `docs/fault-detection.md`). What the reports cannot see: a
//! damaged propeller at full speed (the ESC measures speed, not thrust), a report that lies;
//! the residual ([`crate::fault::FaultState`]) keeps running for those.

use super::reading::AgentReading;
use super::report_check::{ReportCheck, ReportGains};
use super::{loss_kind, FaultKind, FaultVerdict};
use crate::agent::command::AgentCommand;
use crate::agent::failure::FailureMask;
use crate::foundation::real::{lit, Real};

/// The smaller of two finite numbers (a comparison: `f32::min` is a `libm` call on a
/// Cortex-M4F).
#[inline(always)]
fn lower<T: Real>(a: T, b: T) -> T {
    if b < a {
        b
    } else {
        a
    }
}

/// The larger of two finite numbers.
#[inline(always)]
fn upper<T: Real>(a: T, b: T) -> T {
    if b > a {
        b
    } else {
        a
    }
}

/// One agent's report, model and count: plain numbers only (every bit pattern is a value, so
/// a controller in memory a stray write changed, [`crate::Controller::storage_intact`], holds
/// no invalid tag here; a wrong number is a wrong reading, never undefined behaviour).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Slot<T: Real> {
    /// Thrust, `eta_x`, `eta_y`, age of the newest report; no report while the age is not
    /// finite (NaN).
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
    /// Some agent reported since the last clear (non-zero): the check runs.
    reported: u8,
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
            reported: 0,
        }
    }

    /// Whether any agent has reported.
    pub fn any(&self) -> bool {
        self.reported != 0
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
        self.reported = 1;
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

    /// One period (`gains`: of the check at the controller's period) whose commands in force
    /// were `commands`: advances the models of the agents that report, checks the new reports,
    /// ages every report by the period and returns the verdict (the first confirmed agent,
    /// else the suspected one with the most disagreeing reports, else
    /// [`FaultVerdict::Nominal`]). Agents `failures` masks are skipped and their counts
    /// forgotten. An agent that
    /// has not reported is skipped: its model starts from rest at its first report (from rest
    /// to the command, a healthy actuator of any speed is never named while the model catches
    /// up).
    pub fn update(
        &mut self,
        check: &ReportCheck<T>,
        gains: &ReportGains<T>,
        commands: &[AgentCommand<T>; N],
        failures: &FailureMask<N>,
    ) -> FaultVerdict<T> {
        let g = gains;
        let (forget_t, forget_a) = (g.forget_thrust, g.forget_angle);
        let neg_step = -g.step;
        let mut verdict = FaultVerdict::Nominal;
        let mut most = 0_u8;
        for (i, (slot, c)) in self.slots.iter_mut().zip(commands).enumerate() {
            let age = slot.reading[3];
            if !age.is_finite() {
                continue;
            }
            let before = slot.model;
            let toward =
                |m: T, target: T| m + lower(upper((target - m) * g.servo, neg_step), g.step);
            let (t, x, y) = (
                before[0] + (c.thrust - before[0]) * g.rotor,
                toward(before[1], c.eta_x),
                toward(before[2], c.eta_y),
            );
            slot.model = [t, x, y];
            let [low, x_low, x_high, y_low, y_high] = slot.envelope;
            slot.envelope = [
                lower(lower(t, c.thrust), low + forget_t),
                lower(lower(x, c.eta_x), x_low + forget_a),
                upper(upper(x, c.eta_x), x_high - forget_a),
                lower(lower(y, c.eta_y), y_low + forget_a),
                upper(upper(y, c.eta_y), y_high - forget_a),
            ];
            let fresh = core::mem::take(&mut slot.fresh) != 0;
            if failures.is_failed(i) {
                slot.strikes = 0;
                continue;
            }
            let confirmed = matches!(verdict, FaultVerdict::Confirmed { .. });
            if age > check.link_timeout() {
                // No longer aged: past the timeout its age says all (and stays finite).
                slot.strikes = 0;
                if !confirmed {
                    verdict = FaultVerdict::Confirmed {
                        agent: i,
                        kind: FaultKind::LinkLoss,
                    };
                }
                continue;
            }
            slot.reading[3] = age + g.period;
            if fresh {
                let (kind, efficiency) = disagreement(g, slot, c, age);
                (slot.kind, slot.efficiency) = (kind, efficiency);
                slot.strikes = if kind == 0 {
                    0
                } else {
                    slot.strikes.saturating_add(1)
                };
            }
            if slot.strikes == 0 {
                continue;
            }
            let Some(kind) = slot.kind() else {
                continue;
            };
            if slot.strikes >= check.persistence() {
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

/// What a new report of age `age` says against the envelopes (`c`: the command in force), as
/// [`Slot::kind`]'s code and efficiency: 0 when it agrees within the allowance.
#[inline(always)]
fn disagreement<T: Real>(
    g: &ReportGains<T>,
    slot: &Slot<T>,
    c: &AgentCommand<T>,
    age: T,
) -> (u8, T) {
    let [thrust, eta_x, eta_y, _] = slot.reading;
    let [low, x_low, x_high, y_low, y_high] = slot.envelope;
    if low - thrust > g.thrust_base + g.thrust_rate * age {
        // `min(T_model, T_c) >= low > allowance > 0`: the efficiency is in `[0, 1)`.
        return (1, thrust / lower(slot.model[0], c.thrust));
    }
    let allowed = g.angle_base + g.angle_rate * age;
    let off = x_low - eta_x > allowed
        || eta_x - x_high > allowed
        || y_low - eta_y > allowed
        || eta_y - y_high > allowed;
    if off {
        (2, T::zero())
    } else {
        (0, T::zero())
    }
}

#[cfg(test)]
#[path = "reports_tests.rs"]
mod tests;
