//! The way of a command from the controller to the actuators: the plant's saturation, then
//! each agent's command link when the scenario has links (`[links]`, or a `link-loss` failure);
//! and of the agents' reports back (`[reports]`), over the same links.

use tvmd_plant::actuators::{ActuatorBank, ActuatorCommand, FailureKind};
use tvmd_scenario::{CommandLinks, Scenario};

use super::links::{LinkStats, Links};
use super::reports::{AgentReport, Reports};
use super::saturation::PlantSaturation;
use crate::SimError;

/// The held (saturated) commands and, with links, what each agent applies.
#[derive(Clone, Debug)]
pub(super) struct CommandPath {
    /// The commands held until the next tick (zero-order hold), saturated by `saturation`.
    held: Vec<ActuatorCommand>,
    saturation: PlantSaturation,
    links: Option<Links>,
    reports: Option<Reports>,
}

impl CommandPath {
    /// The path of `scenario`'s `agents`: links as its `[links]` says, or the default link when
    /// only a `link-loss` failure needs one.
    pub(super) fn new(scenario: &Scenario, agents: usize) -> Result<Self, SimError> {
        let silenced = scenario.failures.iter().any(|f| f.kind.silences_link());
        let spec = scenario
            .links
            .or_else(|| silenced.then(CommandLinks::default));
        Ok(Self {
            held: vec![ActuatorCommand::default(); agents],
            saturation: PlantSaturation::new(scenario, agents)?,
            links: spec.map(|s| Links::new(s, agents)),
            reports: scenario
                .reports
                .as_ref()
                .map(|r| Reports::new(r, agents, scenario.actuators)),
        })
    }

    /// Holds `commands`, saturated, from the tick at `t` on, and sends them down the links.
    pub(super) fn hold(&mut self, t: f64, commands: &[ActuatorCommand]) {
        self.saturation.apply(commands, &mut self.held);
        if let Some(l) = self.links.as_mut() {
            l.send(t, &self.held);
        }
    }

    /// What the actuators are given at physics time `t`, and whether it changed since the
    /// tick's hold (always false without links: the held commands).
    pub(super) fn applied(&mut self, t: f64) -> (&[ActuatorCommand], bool) {
        match self.links.as_mut() {
            Some(l) => l.deliver(t),
            None => (&self.held, false),
        }
    }

    /// Agent `i` fails at `t` with `kind`: a link loss silences its link from then on (other
    /// kinds are the actuators').
    pub(super) fn fail(&mut self, i: usize, kind: FailureKind, t: f64) {
        if let (true, Some(l)) = (kind.silences_link(), self.links.as_mut()) {
            l.silence(i, t);
        }
    }

    /// Samples the agents' reports at physics time `t` when one is due (`bank`: what the
    /// actuators do).
    pub(super) fn sample_reports(&mut self, t: f64, bank: &ActuatorBank) {
        let Some(r) = self.reports.as_mut() else {
            return;
        };
        match self.links.as_ref() {
            Some(l) => r.sample(t, bank, l.applied(), |i| l.is_silent(i, t)),
            None => r.sample(t, bank, &self.held, |_| false),
        }
    }

    /// After the actuators' physics step of `dt`: the agents' healthy twin (with reports) steps
    /// with the same applied commands.
    pub(super) fn step_twin(&mut self, dt: f64) {
        let applied = match self.links.as_ref() {
            Some(l) => l.applied(),
            None => &self.held,
        };
        if let Some(r) = self.reports.as_mut() {
            r.step_twin(applied, dt);
        }
    }

    /// Per agent, the newest report arrived by the last [`CommandPath::reports_at`] as the
    /// agent would have sent it had it not failed, aged to `t` (empty: no reports).
    pub(super) fn healthy_reports(&self, t: f64) -> Vec<Option<AgentReport>> {
        self.reports
            .as_ref()
            .map_or_else(Vec::new, |r| r.healthy_at(t))
    }

    /// Per agent, the newest report arrived by `t` (empty: the scenario has no reports).
    pub(super) fn reports_at(&mut self, t: f64) -> Vec<Option<AgentReport>> {
        self.reports.as_mut().map_or_else(Vec::new, |r| r.at(t))
    }

    /// Per agent, the last held command minus its saturated value.
    pub(super) fn clamped(&self) -> &[ActuatorCommand] {
        self.saturation.clamped()
    }

    /// Per agent, what its link did so far (`None`: no links).
    pub(super) fn link_stats(&self) -> Option<Vec<LinkStats>> {
        self.links.as_ref().map(Links::stats)
    }
}
