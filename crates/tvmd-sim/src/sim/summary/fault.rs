//! The fault detector's run summary ([`FaultSummary`]): when it first suspected, confirmed and
//! called a loss, which agent, and the largest statistic, folded over the ticks' `/fault`
//! reports.

use serde::{Deserialize, Serialize};

use crate::diagnostics::{FaultDiagnostics, FaultKindName, FaultSourceName, FaultVerdictName};

/// One event of the detector: its time, the agent and the kind it reported.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct FaultEvent {
    /// Time (s) of the controller tick.
    pub time: f64,
    /// The agent.
    pub agent: usize,
    /// What its residual (or its reports) looked like then.
    pub kind: Option<FaultKindName>,
    /// The check that named it (`None` in summaries written before the agents' reports).
    #[serde(default)]
    pub source: Option<FaultSourceName>,
}

/// What the fault detector reported over a run (present when the controller runs one).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct FaultSummary {
    /// The first tick whose statistic exceeded the threshold (any verdict but nominal).
    pub first_alarm: Option<f64>,
    /// The first tick an agent was suspected or confirmed.
    pub first_suspected: Option<FaultEvent>,
    /// The first confirmation (isolation).
    pub first_confirmed: Option<FaultEvent>,
    /// The first confirmation of a loss (the `"mask"` response acts on it).
    pub first_loss: Option<FaultEvent>,
    /// The agent the controller masked itself, and when.
    pub masked: Option<FaultEvent>,
    /// Ticks with a confirmed verdict.
    pub confirmed_ticks: usize,
    /// The largest statistic (noise units) and the threshold.
    pub max_statistic: f64,
    /// The threshold `k`.
    pub threshold: f64,
}

impl FaultSummary {
    /// Folds one tick's report.
    pub fn push(&mut self, t: f64, f: &FaultDiagnostics) {
        if f.statistic.is_finite() {
            self.max_statistic = self.max_statistic.max(f.statistic);
        }
        self.threshold = f.threshold;
        let event = f.agent.map(|agent| FaultEvent {
            time: t,
            agent,
            kind: f.kind,
            source: f.source,
        });
        if f.verdict != FaultVerdictName::Nominal && self.first_alarm.is_none() {
            self.first_alarm = Some(t);
        }
        if self.first_suspected.is_none() {
            self.first_suspected = event;
        }
        if f.verdict == FaultVerdictName::Confirmed {
            self.confirmed_ticks += 1;
            if self.first_confirmed.is_none() {
                self.first_confirmed = event;
            }
            if self.first_loss.is_none() && f.kind == Some(FaultKindName::Loss) {
                self.first_loss = event;
            }
        }
        if let (None, Some(agent)) = (self.masked, f.masked) {
            // The response masks a loss or a link loss, named this tick.
            self.masked = Some(FaultEvent {
                time: t,
                agent,
                kind: f.kind.or(Some(FaultKindName::Loss)),
                source: f.source,
            });
        }
    }
}
