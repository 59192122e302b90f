//! The agents' own reports as an input of the controller's fault detection
//! ([`Controller::set_report`]): the report check ([`crate::fault::reports`]) runs each period
//! beside the residual, and either source's confirmed fault is the controller's verdict
//! ([`crate::FaultReport::source`] says which). No report given: the report check never runs,
//! and the controller is bit for bit the one without it.

use super::Controller;
use crate::allocation::Allocator;
use crate::fault::{AgentReading, FaultKind, FaultReport, FaultSource, FaultVerdict, ReportError};
use crate::foundation::real::Real;

impl<T: Real, const N: usize, A: Allocator<T, N>> Controller<T, N, A> {
    /// Agent `agent`'s newest report: what it measured of its rotor and gimbal
    /// ([`AgentReading`]) and how long ago. Checked at the next [`Self::step`] against the
    /// commands it answers; the controller ages it by the period at each step until the next
    /// report replaces it (a report given again with its age grown is the same report, not a
    /// new one). An agent whose report grows older than the link timeout
    /// ([`crate::fault::ReportCheck::link_timeout`]) is named with
    /// [`crate::FaultKind::LinkLoss`]. Agents that never report are checked by the residual
    /// only.
    ///
    /// Errors (the agent's previous report kept): [`ReportError::Agent`] for an agent not in
    /// the team, [`ReportError::DetectionOff`] without
    /// [`crate::ControllerSettings::fault_detection`].
    pub fn set_report(
        &mut self,
        agent: usize,
        reading: AgentReading<T>,
    ) -> Result<(), ReportError> {
        let len = self.team.len();
        if agent >= len {
            return Err(ReportError::Agent { agent, len });
        }
        let period = self.settings.period;
        if self.fault.is_none() {
            return Err(ReportError::DetectionOff);
        }
        self.reports.set(agent, reading, period);
        Ok(())
    }

    /// [`Self::set_report`] from a rotor speed in the unit of the team's rotor model (as
    /// [`crate::AgentCommand::omega`]; an ESC's rpm times `2 pi / 60` when the limits carry the
    /// rotor constants), the two gimbal angles (rad) and the report's age (s).
    ///
    /// Errors: as [`AgentReading::from_speed`] and [`Self::set_report`].
    pub fn set_report_speed(
        &mut self,
        agent: usize,
        speed: T,
        eta_x: T,
        eta_y: T,
        age: T,
    ) -> Result<(), ReportError> {
        let reading = AgentReading::from_speed(speed, eta_x, eta_y, age, &self.team.limits)?;
        self.set_report(agent, reading)
    }

    /// Agent `agent`'s newest report as the controller holds it (aged to the last step), if
    /// any.
    pub fn report(&self, agent: usize) -> Option<AgentReading<T>> {
        self.fault.as_ref()?;
        self.reports.reading(agent)
    }

    /// Forgets every agent's report (the report check stops until reports come again).
    pub fn clear_reports(&mut self) {
        self.reports.clear();
    }

    /// This period's report check (after the residual's verdict `report` of the same
    /// period): a confirmed fault from the reports replaces the residual's verdict unless the
    /// residual confirmed one too; a suspicion replaces a verdict that names no agent. Nothing
    /// runs while no agent has reported.
    pub(super) fn check_reports(&mut self, report: &mut FaultReport<T>) {
        let Some(monitor) = self.fault.as_mut() else {
            return;
        };
        if !self.reports.any() {
            return;
        }
        let verdict = self.reports.update(
            &monitor.check,
            &monitor.gains,
            &self.previous,
            &self.failures,
        );
        let lost = |k: &FaultKind<T>| matches!(k, FaultKind::Loss | FaultKind::LinkLoss);
        let replaces = match (&verdict, &report.verdict) {
            // Both confirm: the residual's stands unless only the reports' is a loss (which
            // the response masks).
            (FaultVerdict::Confirmed { kind: a, .. }, FaultVerdict::Confirmed { kind: b, .. }) => {
                lost(a) && !lost(b)
            }
            (FaultVerdict::Confirmed { .. }, _) => true,
            (FaultVerdict::Suspected { .. }, v) => {
                matches!(v, FaultVerdict::Nominal | FaultVerdict::Unexplained)
            }
            _ => false,
        };
        if replaces {
            report.verdict = verdict;
            report.source = FaultSource::Reports;
        }
    }
}
