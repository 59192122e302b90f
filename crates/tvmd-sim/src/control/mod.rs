//! The tvmd controller in the loop: an adapter from [`tvmd_core::Controller`] to
//! [`FlightController`], in f64 or in f32 (the flight configuration).
//!
//! [`TvmdController<T>`] wraps `tvmd_core::Controller<T, 16, AnyAllocator<T, 16>>` unchanged,
//! for `T = f64` or `T = f32` ([`CoreFloat`]); [`AnyTvmdController`] is the one the scenario's
//! `controller_precision` picks. The controller is built from the scenario (module `config`:
//! same agent order, quarter turns, masses, navigator, gains with `K_xi` diagonal in the order
//! `[Omega; v]`, relaxation `s`, controller period, optional controller rate limits and
//! allocator, each rounded to `T`); then at each tick:
//!
//! 1. converts the simulator's state (world velocity `x_dot`, body `Omega`) into the core's
//!    state with the body-frame velocity `v = R^T x_dot`, and the reference likewise, rounding
//!    to `T` (module `convert`: the only place precisions meet);
//! 2. tells the core whether the team is on the ground ([`tvmd_core::Controller::set_landed`],
//!    when it changes): the fed-back centre of mass at most [`LANDED_HEIGHT`] above its rest
//!    height `z = 0`, before take-off and after touchdown (the ground's reaction is not a
//!    disturbance for the offset-free action to learn);
//! 3. passes a changed failure mask (the failures the controller is told of) to
//!    [`tvmd_core::Controller::set_failures`]; if the core refuses it (the remaining team cannot
//!    produce every wrench) the old mask stays and the reason is reported in
//!    [`Diagnostics::failure_note`]; an accepted mask's hover classification is reported in
//!    [`Diagnostics::hover`], and with `failure_response.on_hover_loss = "land"` a team
//!    classified not hover-capable flies a level descent to `z = 0` from then on (module
//!    `landing`);
//! 4. runs one [`tvmd_core::Controller::step`] in `T`; on a [`tvmd_core::CycleError`] it holds
//!    the commands the error carries and reports the error in [`Diagnostics::cycle_error`];
//! 5. converts the commands and every part of [`Diagnostics`] (planner, control law,
//!    allocation, Lyapunov values) back to f64 (exact).

use tvmd_core::FailureMask;

use crate::diagnostics::{Diagnostics, FaultDiagnostics, HoverDiagnostics};
use crate::error::BoxedError;
use crate::flight::{AgentReport, FlightController, FlightInput, FlightOutput};
use crate::SimError;
use tvmd_plant::physics::PlantState;
use tvmd_scenario::{FailureResponse, OnHoverLoss, Precision, Scenario};

mod config;
mod convert;
mod diagnostics;
mod landing;
pub mod wrench;

/// The core's engines, the PIL link and the cycle recorder: crate `tvmd-pil`.
pub use tvmd_pil as pil;
pub use tvmd_pil::{engine, recording};
pub use tvmd_pil::{CoreController, CoreOutput, MAX_AGENTS};

pub use engine::{CoreEngine, CycleAnswer, FailureAnswer, SkippedCycle};
pub use landing::{Landing, Touchdown, LANDED_HEIGHT, TOUCHDOWN_HEIGHT};
pub use wrench::WrenchAllocation;

pub use config::{
    allocator, controller_settings, fault_detection, hover_roll_limit, law_settings, team_config,
    wire_config,
};
pub use convert::{core_reference, core_state, sim_command, CoreFloat};
pub use diagnostics::fault_diagnostics;

/// The core controller of a scenario in `T` and its agent count, as
/// [`TvmdController::from_scenario`] builds it.
pub fn core_of_scenario<T: CoreFloat>(
    scenario: &Scenario,
) -> Result<(CoreController<T>, usize), SimError> {
    let team = config::team_config::<T, MAX_AGENTS>(scenario)?;
    let settings = config::controller_settings::<T>(scenario)?;
    let alloc =
        config::allocator::<T, MAX_AGENTS>(&scenario.allocator, scenario.allocator_max_rounds)?;
    let n = team.len();
    let inner = CoreController::new(team, settings, alloc).map_err(config::config_error)?;
    Ok((inner, n))
}

/// [`tvmd_core::Controller`] in `T` as a [`FlightController`], the core's cycle run by the
/// engine `E` (in process by default; on an emulated target with module `pil`).
#[derive(Debug)]
pub struct TvmdController<T: CoreFloat, E: CoreEngine<T> = CoreController<T>> {
    inner: E,
    n: usize,
    mask: Vec<bool>,
    failure_note: Option<String>,
    last: Option<CoreOutput<T>>,
    response: FailureResponse,
    /// The classification of the mask accepted this tick, reported once.
    hover: Option<HoverDiagnostics>,
    /// The last mask the core refused: reported once, not asked for again until it changes.
    refused: Option<Vec<bool>>,
    landing: Option<Landing>,
    /// The disarm on touchdown after a commanded landing.
    touchdown: Touchdown,
    /// What the core was last told by `set_landed`.
    landed: bool,
    /// The agents the core masked itself (`[fault_detection] response = "mask"`): kept in
    /// every mask passed on, so the scenario's flags do not unmask them.
    detected: Vec<bool>,
    /// The agent of the last self-masking seen ([`tvmd_core::FaultMasking::agent`]).
    masking_seen: Option<usize>,
    /// The agents' reports go to the core ([`Self::for_scenario`]).
    pass_reports: bool,
    /// The core has no fault detection to read the agents' reports.
    reports_unread: bool,
}

impl<T: CoreFloat> TvmdController<T> {
    /// The controller of a scenario in `T` (team, limits, gains, relaxation, period, rate limits
    /// and allocator), whatever the scenario's `controller_precision` (see
    /// [`AnyTvmdController::from_scenario`] for the one it names). Errors name the scenario
    /// field the core rejected.
    pub fn from_scenario(scenario: &Scenario) -> Result<Self, SimError> {
        let (inner, n) = core_of_scenario(scenario)?;
        Ok(Self::new(inner, n).for_scenario(scenario))
    }

    /// The wrapped core controller.
    pub fn core(&self) -> &CoreController<T> {
        &self.inner
    }
}

impl<T: CoreFloat, E: CoreEngine<T>> TvmdController<T, E> {
    /// The same controller with `scenario`'s response to a hover-capability loss, passing the
    /// agents' reports to the core when it has `[reports]` and `[fault_detection]` (an engine
    /// that does not carry them then ends the run with an error; otherwise they are not
    /// passed).
    pub fn for_scenario(mut self, scenario: &Scenario) -> Self {
        self.pass_reports = scenario.reports.is_some() && scenario.fault_detection.is_some();
        self.with_failure_response(scenario.failure_response)
    }

    /// The same controller with another response to a hover-capability loss.
    pub fn with_failure_response(mut self, response: FailureResponse) -> Self {
        self.response = response;
        self
    }

    /// The landing started on a hover-capability loss, if any.
    pub fn landing(&self) -> Option<&Landing> {
        self.landing.as_ref()
    }

    /// Wraps a core controller (or another engine) for a team of `n` agents.
    pub fn new(inner: E, n: usize) -> Self {
        Self {
            inner,
            n,
            mask: vec![false; n],
            failure_note: None,
            last: None,
            response: FailureResponse::default(),
            hover: None,
            refused: None,
            landing: None,
            touchdown: Touchdown::default(),
            landed: false,
            detected: vec![false; n],
            masking_seen: None,
            pass_reports: false,
            reports_unread: false,
        }
    }

    /// The engine running the core's cycle.
    pub fn engine(&self) -> &E {
        &self.inner
    }

    /// The core's output of the last successful cycle.
    pub fn last_output(&self) -> Option<&CoreOutput<T>> {
        self.last.as_ref()
    }

    fn update_failures(
        &mut self,
        t: f64,
        state: &PlantState,
        failed: &[bool],
    ) -> Result<(), BoxedError> {
        let wanted: Vec<bool> = (0..self.n)
            .map(|i| failed.get(i).copied().unwrap_or(false) || self.detected[i])
            .collect();
        if wanted == self.mask || self.refused.as_ref() == Some(&wanted) {
            return Ok(());
        }
        let mut mask = FailureMask::<MAX_AGENTS>::none();
        for (i, f) in wanted.iter().enumerate() {
            // i < n <= MAX_AGENTS, so this cannot fail.
            let _ = mask.set(i, *f);
        }
        match self.inner.set_failures(mask)? {
            Ok(hover) => {
                self.failure_note = None;
                self.refused = None;
                self.accept_hover(t, state, &hover);
            }
            Err(e) => {
                let note = format!(
                    "failure mask {wanted:?} refused, keeping {:?}: {e}",
                    self.mask
                );
                // Reported like a classification (not hover-capable, no margin), so the
                // summary, the table and Python see it, not only the log's note.
                self.hover = Some(HoverDiagnostics {
                    capable: false,
                    margin: 0.0,
                    limiting_agent: None,
                    limit: "refused".into(),
                    landing: false,
                    refused: Some(note.clone()),
                });
                self.failure_note = Some(note);
                self.refused = Some(wanted.clone());
            }
        }
        self.mask = self.inner.failures().as_array()[..self.n].to_vec();
        if self.mask != wanted && self.failure_note.is_none() {
            self.failure_note = Some(format!("failure mask {wanted:?} not applied"));
        }
        Ok(())
    }
}

impl<T: CoreFloat, E: CoreEngine<T>> TvmdController<T, E> {
    /// An accepted mask's classification: reported, and with `on_hover_loss = "land"` a team
    /// not hover-capable starts its landing.
    fn accept_hover(&mut self, t: f64, state: &PlantState, hover: &tvmd_core::HoverCapability<T>) {
        let land = !hover.capable
            && self.response.on_hover_loss == OnHoverLoss::Land
            && self.landing.is_none();
        if land {
            self.landing = Some(Landing::start(
                t,
                &state.position,
                self.response.landing_acceleration,
            ));
        }
        self.hover = Some(HoverDiagnostics {
            capable: hover.capable,
            margin: convert::to_sim(hover.margin),
            limiting_agent: hover.limiting_agent,
            limit: hover.limit.as_str().to_string(),
            landing: land,
            refused: None,
        });
    }

    /// The agents' reports of this tick to the core's fault detection (`[reports]` with
    /// `[fault_detection]`, [`Self::for_scenario`]): each agent's newest. A core without fault detection does not read them: they are not passed
    /// again ([`tvmd_core::ReportError::DetectionOff`]); any other refusal ends the run.
    fn pass_reports(&mut self, reports: &[Option<AgentReport>]) -> Result<(), BoxedError> {
        if !self.pass_reports || self.reports_unread {
            return Ok(());
        }
        for (agent, r) in reports.iter().enumerate().take(self.n) {
            let Some(r) = r else {
                continue;
            };
            match self.inner.set_report(agent, convert::core_reading(r)?)? {
                Ok(()) => {}
                Err(tvmd_core::ReportError::DetectionOff) => {
                    self.reports_unread = true;
                    return Ok(());
                }
                Err(e) => return Err(e.into()),
            }
        }
        Ok(())
    }

    /// The detector's report of the cycle just run, and a mask the core set itself in it:
    /// taken as the simulator's own (kept in later masks, classified, landing on a
    /// hover-capability loss as for an informed failure).
    fn fault_diagnostics(&mut self, t: f64, state: &PlantState) -> Option<FaultDiagnostics> {
        let report = self.inner.fault_report()?;
        let mut out = diagnostics::fault_diagnostics(&report);
        let masking = self
            .inner
            .fault_masking()
            .filter(|m| Some(m.agent) != self.masking_seen);
        if let Some(m) = masking {
            self.masking_seen = Some(m.agent);
            if let Some(flag) = self.detected.get_mut(m.agent) {
                *flag = true;
            }
            match &m.hover {
                Some(hover) => {
                    out.masked = Some(m.agent);
                    self.accept_hover(t, state, hover);
                }
                None => {
                    self.failure_note = Some(format!(
                        "detected loss of agent {} not masked: the remaining team cannot \
                         produce every wrench",
                        m.agent
                    ));
                }
            }
            self.mask = self.inner.failures().as_array()[..self.n].to_vec();
        }
        Some(out)
    }
}

impl<T: CoreFloat, E: CoreEngine<T>> FlightController for TvmdController<T, E> {
    fn step(&mut self, input: &FlightInput<'_>) -> Result<FlightOutput, BoxedError> {
        let FlightInput {
            t,
            state,
            reference,
            failed,
            reports,
        } = *input;
        let landed = state.position.z <= landing::LANDED_HEIGHT;
        if landed != self.landed {
            self.inner.set_landed(landed)?;
            self.landed = landed;
        }
        self.update_failures(t, state, failed)?;
        self.pass_reports(reports)?;
        let n = self.n;
        let landing_reference = self.landing.as_ref().map(|l| l.reference(t));
        let reference = landing_reference.as_ref().unwrap_or(reference);
        if self.touchdown.update(&state.position, reference) {
            let note = if self.landing.is_some() {
                "landed after a hover-capability loss: rotors idle"
            } else {
                "landed: rotors idle"
            };
            return Ok(FlightOutput {
                commands: vec![sim_command(&tvmd_core::AgentCommand::<T>::idle()); n],
                diagnostics: Diagnostics {
                    failure_note: Some(note.into()),
                    hover: self.hover.take(),
                    ..Default::default()
                },
            });
        }
        let hover = self.hover.take();
        let answer = self.inner.step(
            &convert::core_state(state),
            &convert::core_reference(reference),
        )?;
        let fault = self.fault_diagnostics(t, state);
        // A mask the core set itself this cycle is classified now; reported with this tick.
        let hover = self.hover.take().or(hover);
        match answer {
            Ok(out) => {
                let mut diagnostics =
                    diagnostics::cycle_diagnostics(&out, n, self.failure_note.clone());
                diagnostics.hover = hover;
                diagnostics.fault = fault;
                let commands = out.commands[..n].iter().map(sim_command).collect();
                self.last = Some(out);
                Ok(FlightOutput {
                    commands,
                    diagnostics,
                })
            }
            Err(e) => Ok(FlightOutput {
                commands: e.commands[..n].iter().map(sim_command).collect(),
                diagnostics: Diagnostics {
                    cycle_error: Some(e.message),
                    failure_note: self.failure_note.clone(),
                    hover,
                    ..Default::default()
                },
            }),
        }
    }
}

/// The tvmd controller in the precision a scenario names (`controller_precision`): one
/// [`TvmdController`] type per float, the same logic.
// One per run: the f64 variant's extra 4 kB is not worth a box.
#[allow(clippy::large_enum_variant)]
#[derive(Debug)]
pub enum AnyTvmdController {
    /// `TvmdController<f64>`.
    F64(TvmdController<f64>),
    /// `TvmdController<f32>`, the type a flight controller runs.
    F32(TvmdController<f32>),
    /// The f32 controller executed on an emulated Cortex-M (processor in the loop).
    Pil(TvmdController<f32, pil::PilCore>),
}

impl AnyTvmdController {
    /// The controller of a scenario, in its `controller_precision`. Errors name the scenario
    /// field the core rejected.
    pub fn from_scenario(scenario: &Scenario) -> Result<Self, SimError> {
        Ok(match scenario.controller_precision {
            Precision::F64 => Self::F64(TvmdController::from_scenario(scenario)?),
            Precision::F32 => Self::F32(TvmdController::from_scenario(scenario)?),
        })
    }

    /// The controller of a scenario on `target`: in process ([`Self::from_scenario`]) for
    /// `None`, else the f32 controller on the emulated target ([`pil::PilCore`], which needs
    /// an f32 `controller_precision`: the firmware runs the flight configuration only).
    pub fn from_scenario_on(
        scenario: &Scenario,
        target: Option<pil::PilTarget>,
    ) -> Result<Self, SimError> {
        let Some(target) = target else {
            return Self::from_scenario(scenario);
        };
        if scenario.controller_precision != Precision::F32 {
            return Err(config::invalid(
                "controller_precision",
                format!("the {target} PIL firmware runs the f32 controller only"),
            ));
        }
        let wire = config::wire_config(scenario)?;
        let core = pil::PilCore::start(target, &wire)?;
        Ok(Self::Pil(
            TvmdController::new(core, wire.n).for_scenario(scenario),
        ))
    }

    /// The precision the controller runs in.
    pub fn precision(&self) -> Precision {
        match self {
            Self::F64(_) => Precision::F64,
            Self::F32(_) | Self::Pil(_) => Precision::F32,
        }
    }

    /// Where the controller runs: `"host"`, or the target's label (e.g.
    /// `"cortex-m4 (qemu mps2-an386)"`).
    pub fn target_label(&self) -> String {
        match self {
            Self::F64(_) | Self::F32(_) => HOST_TARGET.to_string(),
            Self::Pil(c) => c.engine().target().label(),
        }
    }

    /// The agents the core currently treats as failed (the mask it accepted).
    pub fn failures(&self) -> FailureMask<MAX_AGENTS> {
        match self {
            Self::F64(c) => CoreEngine::failures(c.engine()),
            Self::F32(c) => CoreEngine::failures(c.engine()),
            Self::Pil(c) => c.engine().failures(),
        }
    }
}

pub use crate::flight::HOST_TARGET;

impl FlightController for AnyTvmdController {
    fn step(&mut self, input: &FlightInput<'_>) -> Result<FlightOutput, BoxedError> {
        match self {
            Self::F64(c) => c.step(input),
            Self::F32(c) => c.step(input),
            Self::Pil(c) => c.step(input),
        }
    }
}
