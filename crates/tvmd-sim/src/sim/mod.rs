//! The digital control loop.
//!
//! Physics runs at `physics.dt`; the controller runs every `controller_period` (an integer
//! number of physics steps) and its commands are held (zero-order hold) until the next call.
//! Actuators, failures and disturbances act at the physics rate. Each controller tick
//! (`t_k = k controller_period`):
//!
//! 1. the true state is read and, if configured, noise is added to the copy fed back, which
//!    reaches the controller `disturbances.feedback_latency` ticks later ([`latency`]);
//! 2. the reference is evaluated at `t_k`;
//! 3. the controller is called with the state, the reference and the failure flags it is
//!    told about (a failure with `controller_informed = false` stays `false` for it);
//! 4. the sample (true state, reference, commands, diagnostics) is recorded ([`sample`]) and
//!    handed to the run's listener, if any ([`crate::TickSink`]: the MCAP log is one).
//!
//! Then `steps_per_control` physics steps follow, each one: failures whose time has come are
//! applied, the actuators move towards the held commands, and the agents' body-frame forces
//! (plus wind and external wrench) are applied for one step. The summary of a run is folded
//! over every tick's sample ([`summary`]); the run keeps all, a bounded subset or none of the
//! samples ([`retention`]), so memory can stay flat however long the run. Two flights of one
//! scenario are compared sample by sample with [`difference`].
//!
//! The loop is one client of the steppable entry ([`step`]): at each tick it takes the tick's
//! [`Observation`], asks the controller and hands its output to [`Simulation::step_output`], which
//! a caller with its own controller calls too ([`Simulation::step`] with commands,
//! [`Simulation::step_wrench`] with a body wrench).

pub mod batch;
mod command_path;
pub mod difference;
mod forces;
pub mod latency;
pub mod links;
pub mod reports;
pub mod retention;
pub mod sample;
mod saturation;
pub mod step;
pub mod summary;

use std::sync::atomic::{AtomicBool, Ordering};

use nalgebra::Vector3;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use serde::Serialize;

use crate::control::WrenchAllocation;
use crate::flight::{FlightController, FlightOutput};
use crate::sink::{LoggedTick, SceneRecord, Tick, TickSink};
use crate::SimError;
use tvmd_plant::actuators::{ActuatorBank, ActuatorCommand};
use tvmd_plant::physics::{MassError, PhysicsWorld, PlantState, TeamBody};
use tvmd_plant::PhysicsError;
use tvmd_scenario::{Failure, Payload, Scenario, StateNoise};

pub use batch::{BatchAction, SimulationBatch, TeamStep};
pub use difference::FlightDifference;
pub use forces::agent_forces;
use forces::body_forces;
pub use retention::{SampleRetention, SampleStore, MAX_KEPT_SAMPLES};
pub use sample::Sample;
pub use step::{Observation, Stepped};
pub use summary::{
    EfficiencyMetrics, ErrorMetrics, FaultEvent, FaultSummary, FlightMetrics, MagnitudeMetrics,
    NullSpaceSummary, PaperMetrics, RunSummary, RunTotals, SummaryFold, Verdict, VxRise,
};

/// The valid range of the physics: beyond it a run ends with `PhysicsError::Diverged` rather than
/// run on in a state rapier clamps (its default caps speeds) or cannot represent. A team of the
/// simulator's scale is far outside its flight envelope well before these.
pub const MAX_POSITION: f64 = 1e5;
/// Largest speed of the centre of mass (m/s), below rapier's default velocity cap (400 m/s).
pub const MAX_SPEED: f64 = 300.0;
/// Largest body rate (rad/s).
pub const MAX_BODY_RATE: f64 = 200.0;

/// `Err(Diverged)` when the state at `t` is not finite or outside the valid range.
fn check_divergence(t: f64, s: &PlantState) -> Result<(), SimError> {
    let what = if !s.is_finite() {
        Some("the state is not finite".to_string())
    } else if s.position.norm() > MAX_POSITION {
        Some(format!(
            "|position| = {:.3e} m exceeds {MAX_POSITION:e} m",
            s.position.norm()
        ))
    } else if s.velocity.norm() > MAX_SPEED {
        Some(format!(
            "speed {:.3e} m/s exceeds {MAX_SPEED} m/s (rapier caps speeds at 400 m/s)",
            s.velocity.norm()
        ))
    } else if s.omega.norm() > MAX_BODY_RATE {
        Some(format!(
            "body rate {:.3e} rad/s exceeds {MAX_BODY_RATE} rad/s",
            s.omega.norm()
        ))
    } else {
        None
    };
    what.map_or(
        Ok(()),
        |what| Err(PhysicsError::Diverged { t, what }.into()),
    )
}

/// Result of a run: the kept samples, the summary and the paper's metrics (both of every
/// tick, whichever samples were kept).
#[derive(Clone, Debug, Serialize)]
pub struct RunResult {
    /// The samples kept ([`SimOptions::samples`]): every `sample_stride`-th controller tick.
    pub samples: Vec<Sample>,
    /// Controller ticks between kept samples (1: every tick).
    pub sample_stride: usize,
    /// Summary.
    pub summary: RunSummary,
    /// The paper's reproduction metrics.
    pub paper: PaperMetrics,
}

/// Options that are not part of the scenario.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SimOptions {
    /// Which samples the result keeps (default: all).
    pub samples: SampleRetention,
}

impl Default for SimOptions {
    fn default() -> Self {
        Self {
            samples: SampleRetention::All,
        }
    }
}

/// A simulation of one scenario: run to its end with a controller ([`Simulation::run`]) or
/// stepped one controller period at a time ([`Simulation::step`], module [`step`]).
pub struct Simulation {
    scenario: Scenario,
    options: SimOptions,
    team: TeamBody,
    world: PhysicsWorld,
    actuators: ActuatorBank,
    steps_per_control: usize,
    total_steps: usize,
    failures: Vec<Failure>,
    applied: Vec<bool>,
    /// Payloads not attached yet, latest first.
    payloads: Vec<Payload>,
    failed_true: Vec<bool>,
    failed_told: Vec<bool>,
    noise: Option<(StateNoise, ChaCha8Rng)>,
    delay: latency::FeedbackDelay,
    max_thrust: f64,
    samples: SampleStore,
    fold: SummaryFold,
    step_index: usize,
    controller_calls: usize,
    wall_time: f64,
    interrupted: bool,
    /// The held commands, their saturation and the agents' links.
    commands: command_path::CommandPath,
    /// The agents' body-frame forces, reused every physics step.
    forces: Vec<Vector3<f64>>,
    /// The forces must be recomputed (new commands, a failure, or actuators with memory).
    forces_stale: bool,
    /// The current tick's observation, once taken and until its commands come.
    observed: Option<Observation>,
    /// The allocation stage of [`Simulation::step_wrench`], built on its first call.
    allocation: Option<WrenchAllocation>,
}

impl Simulation {
    /// Builds the simulation: validates the scenario, builds the world with the team resting
    /// at `initial_position` (identity attitude) and the actuators at rest.
    pub fn new(scenario: &Scenario) -> Result<Self, SimError> {
        Self::with_options(scenario, SimOptions::default())
    }

    /// As [`Simulation::new`], with options.
    pub fn with_options(scenario: &Scenario, options: SimOptions) -> Result<Self, SimError> {
        scenario.validate()?;
        let team = scenario.team_body()?;
        let initial = PlantState {
            rotation: tvmd_plant::math::from_roll_pitch_yaw(scenario.initial_attitude),
            ..PlantState::at_rest(Vector3::from(scenario.initial_position))
        };
        let p = &scenario.plant;
        let mass_error = MassError {
            mass_scale: p.mass_scale,
            inertia_scale: p.inertia_scale,
            com_offset: Vector3::from(p.com_offset),
        };
        let world = PhysicsWorld::with_mass_error(&team, &scenario.physics, &initial, &mass_error)?;
        let mut payloads = scenario.payloads.clone();
        payloads.sort_by(|a, b| b.time.total_cmp(&a.time));
        let n = team.len();
        let mut failures = scenario.failures.clone();
        failures.sort_by(|a, b| a.time.total_cmp(&b.time));
        let steps_per_control = scenario.steps_per_control()?;
        let total_steps = (scenario.duration / scenario.physics.dt).round() as usize;
        options
            .samples
            .check(total_steps.div_ceil(steps_per_control))?;
        Ok(Self {
            options,
            commands: command_path::CommandPath::new(scenario, n)?,
            forces: Vec::with_capacity(n),
            forces_stale: true,
            observed: None,
            allocation: None,
            actuators: ActuatorBank::new(scenario.actuators, n),
            applied: vec![false; failures.len()],
            failures,
            payloads,
            failed_true: vec![false; n],
            failed_told: vec![false; n],
            noise: scenario
                .disturbances
                .state_noise
                .map(|s| (s, ChaCha8Rng::seed_from_u64(s.seed))),
            delay: latency::FeedbackDelay::new(scenario.disturbances.feedback_latency),
            max_thrust: scenario.max_thrust()?,
            scenario: scenario.clone(),
            team,
            world,
            steps_per_control,
            total_steps,
            samples: SampleStore::new(options.samples),
            fold: SummaryFold::new(scenario),
            step_index: 0,
            controller_calls: 0,
            wall_time: 0.0,
            interrupted: false,
        })
    }

    /// The physics world.
    pub fn world(&self) -> &PhysicsWorld {
        &self.world
    }

    /// The team.
    pub fn team(&self) -> &TeamBody {
        &self.team
    }

    /// The scenario.
    pub fn scenario(&self) -> &Scenario {
        &self.scenario
    }

    /// Samples kept so far (also available after a failed run).
    pub fn samples(&self) -> &[Sample] {
        self.samples.samples()
    }

    /// Moves the samples kept so far out (the simulation keeps none), e.g. to report a
    /// failed run without copying them.
    pub fn take_samples(&mut self) -> Vec<Sample> {
        self.samples.take()
    }

    /// What has been simulated so far, copied (the simulation goes on): the kept samples, the
    /// summary and the paper's metrics.
    pub fn result(&self) -> RunResult {
        RunResult {
            summary: self.summary(),
            paper: self.paper_metrics(),
            sample_stride: self.samples.stride(),
            samples: self.samples().to_vec(),
        }
    }

    /// What has been simulated so far: the kept samples (moved out), the summary and the
    /// paper's metrics.
    pub fn take_result(&mut self) -> RunResult {
        RunResult {
            summary: self.summary(),
            paper: self.paper_metrics(),
            sample_stride: self.samples.stride(),
            samples: self.take_samples(),
        }
    }

    /// Applies the failures whose time has come and tells the controller those whose
    /// `informed_after` has passed; true if any was applied now.
    fn apply_failures(&mut self, t: f64) -> bool {
        let mut any = false;
        for (k, f) in self.failures.iter().enumerate() {
            if !self.applied[k] && f.time <= t + 1e-12 {
                any = true;
                self.applied[k] = true;
                self.actuators.fail(f.agent, f.kind);
                self.commands.fail(f.agent, f.kind, f.time);
                self.failed_true[f.agent] = true;
            }
            if self.applied[k] && f.controller_informed && f.time + f.informed_after <= t + 1e-12 {
                self.failed_told[f.agent] = true;
            }
        }
        any
    }

    fn attach_payloads(&mut self, t: f64) -> Result<(), SimError> {
        while let Some(p) = self.payloads.last().filter(|p| p.time <= t + 1e-12) {
            let (mass, offset) = (p.mass, Vector3::from(p.offset));
            self.payloads.pop();
            self.world.attach_payload(mass, &offset)?;
        }
        Ok(())
    }

    fn forces(&self, actual: &[ActuatorCommand]) -> Vec<Vector3<f64>> {
        let mut out = Vec::with_capacity(actual.len());
        body_forces(actual, &self.team, &self.scenario.plant, &mut out);
        out
    }

    /// Runs the scenario to its end with `controller`, handing every tick to `sink` if given
    /// (a run's MCAP log is `McapSink`).
    ///
    /// On error the samples recorded so far stay available through
    /// [`Simulation::samples`]; the sink has been flushed.
    pub fn run(
        &mut self,
        controller: &mut dyn FlightController,
        sink: Option<&mut dyn TickSink>,
    ) -> Result<RunResult, SimError> {
        self.run_until(controller, sink, None)
    }

    /// As [`Simulation::run`], stopping at the first controller tick after `cancel` is set
    /// (a signal handler's or a caller's flag): the result then holds what was simulated, and
    /// its summary says `interrupted`.
    pub fn run_until(
        &mut self,
        controller: &mut dyn FlightController,
        sink: Option<&mut dyn TickSink>,
        cancel: Option<&AtomicBool>,
    ) -> Result<RunResult, SimError> {
        let start = std::time::Instant::now();
        let result = self.run_loop(controller, sink, cancel);
        self.wall_time += start.elapsed().as_secs_f64();
        result?;
        Ok(self.take_result())
    }

    fn run_loop(
        &mut self,
        controller: &mut dyn FlightController,
        mut sink: Option<&mut dyn TickSink>,
        cancel: Option<&AtomicBool>,
    ) -> Result<(), SimError> {
        let flown = self.fly_steps(controller, sink.as_deref_mut(), cancel);
        // What was flown is handed on whatever ended the loop (an error, an interrupt, the end).
        let flushed = match sink {
            Some(sink) => sink.flush(),
            None => Ok(()),
        };
        flown.and(flushed)
    }

    fn fly_steps(
        &mut self,
        controller: &mut dyn FlightController,
        mut sink: Option<&mut (dyn TickSink + '_)>,
        cancel: Option<&AtomicBool>,
    ) -> Result<(), SimError> {
        let plan = SinkPlan::new(self, sink.as_deref());
        while !self.is_finished() {
            if cancel.is_some_and(|c| c.load(Ordering::Relaxed)) {
                self.interrupted = true;
                break;
            }
            let observation = self.take_observation()?;
            let out =
                controller
                    .step(&observation.input())
                    .map_err(|source| SimError::Controller {
                        t: observation.t,
                        source,
                    })?;
            let sink = sink.as_deref_mut().map(|s| (s, &plan));
            self.apply_output(observation, out, sink)?;
        }
        Ok(())
    }

    /// Records the tick of `observation` with the controller's `out` (sample, summary, sink)
    /// and flies the control period with its commands held.
    fn apply_output(
        &mut self,
        observation: Observation,
        out: FlightOutput,
        sink: Option<(&mut (dyn TickSink + '_), &SinkPlan)>,
    ) -> Result<(), SimError> {
        self.check_commands(observation.t, &out.commands)?;
        self.commands.hold(observation.t, &out.commands);
        self.forces_stale = true;
        self.record(observation, out, sink)?;
        self.advance_period()
    }

    /// The sample of a tick, into the summary and the kept samples, and the tick to the sink.
    fn record(
        &mut self,
        observation: Observation,
        out: FlightOutput,
        sink: Option<(&mut (dyn TickSink + '_), &SinkPlan)>,
    ) -> Result<(), SimError> {
        let Observation {
            t,
            truth,
            reference,
            ..
        } = observation;
        let tick = self.controller_calls;
        self.controller_calls += 1;
        let actual = self.actuators.actual();
        let sample = Sample::record(
            t,
            &truth,
            &reference,
            &out,
            actual.clone(),
            self.failed_true.clone(),
        );
        self.fold.push(&sample);
        self.samples.push(tick, || sample);
        if let Some((sink, plan)) = sink {
            // The scene shows the commanded forces: at a tick the actual ones still lag by one
            // period.
            let scene = plan
                .team
                .clone()
                .filter(|_| tick % plan.scene_every == 0)
                .map(|team| SceneRecord {
                    team,
                    forces_body: self.forces(&out.commands),
                    max_thrust: self.max_thrust,
                });
            sink.tick(LoggedTick {
                tick: Tick {
                    t,
                    state: truth,
                    reference,
                    forces_body: self.forces(&actual),
                    output: out,
                    actual,
                    failed: self.failed_true.clone(),
                },
                heavy: tick % plan.heavy_every == 0,
                scene,
            })?;
            sink.pace(t);
        }
        Ok(())
    }

    /// The paper's metrics of the run so far (every tick, kept or not).
    pub fn paper_metrics(&self) -> PaperMetrics {
        self.fold.paper()
    }

    /// Summary of the run so far (final state from the physics, extremes over every tick).
    pub fn summary(&self) -> RunSummary {
        let totals = RunTotals {
            time: self.world.time(),
            final_state: self.world.state(),
            mass: self.team.mass(),
            controller_calls: self.controller_calls,
            physics_steps: self.step_index,
            wall_time: self.wall_time,
            interrupted: self.interrupted,
        };
        self.fold.summary(&self.scenario, &totals)
    }
}

/// What the loop's sink needs beyond a tick: which ticks draw a scene or write the heavy
/// topics, and the team to draw (one copy per run, shared with the sink's jobs).
struct SinkPlan {
    scene_every: usize,
    heavy_every: usize,
    team: Option<std::sync::Arc<TeamBody>>,
}

impl SinkPlan {
    fn new(sim: &Simulation, sink: Option<&(dyn TickSink + '_)>) -> Self {
        let settings = sim.scenario.log;
        let period = sim.scenario.controller_period;
        Self {
            scene_every: ((settings.scene_period / period).round() as usize).max(1),
            heavy_every: settings.decimation.max(1),
            team: sink
                .is_some_and(|s| s.wants_scenes())
                .then(|| std::sync::Arc::new(sim.team.clone())),
        }
    }
}
