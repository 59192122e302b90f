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

pub mod difference;
mod forces;
pub mod latency;
pub mod retention;
pub mod sample;
pub mod summary;

use std::sync::atomic::{AtomicBool, Ordering};

use nalgebra::{Rotation3, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;
use serde::Serialize;

use crate::flight::{FlightController, FlightInput};
use crate::sink::{LoggedTick, SceneRecord, Tick, TickSink};
use crate::SimError;
use tvmd_plant::actuators::{ActuatorBank, ActuatorCommand};
use tvmd_plant::physics::{ExtraWrench, MassError, PhysicsWorld, PlantState, TeamBody};
use tvmd_plant::PhysicsError;
use tvmd_scenario::{Failure, Payload, Scenario, StateNoise};

pub use difference::FlightDifference;
use forces::body_forces;
pub use retention::{SampleRetention, SampleStore, MAX_KEPT_SAMPLES};
pub use sample::Sample;
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

/// A simulation of one scenario.
pub struct Simulation {
    scenario: Scenario,
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

    fn noisy(&mut self, s: &PlantState) -> PlantState {
        let Some((n, rng)) = self.noise.as_mut() else {
            return *s;
        };
        let mut g = |std: f64| -> Vector3<f64> {
            Vector3::new(
                rng.sample::<f64, _>(StandardNormal),
                rng.sample::<f64, _>(StandardNormal),
                rng.sample::<f64, _>(StandardNormal),
            ) * std
        };
        let dp = g(n.position);
        let dv = g(n.velocity);
        let da = g(n.attitude);
        let dw = g(n.angular_velocity);
        PlantState {
            position: s.position + dp,
            rotation: s.rotation * Rotation3::new(da).into_inner(),
            velocity: s.velocity + dv,
            omega: s.omega + dw,
        }
    }

    fn extra_wrench(&self, t: f64) -> ExtraWrench {
        let d = &self.scenario.disturbances;
        let mut w = ExtraWrench {
            force_world: Vector3::from(d.wind),
            ..Default::default()
        };
        if let Some(air) = &d.air {
            let v = self.world.state().velocity;
            w.force_world += Vector3::from(air.force(t, v.into(), self.team.len()));
        }
        if let Some(e) = d.external_wrench.as_ref().filter(|e| e.active(t)) {
            w.force_world += Vector3::from(e.force);
            w.torque_body += Vector3::from(e.torque);
        }
        w
    }

    /// Applies the failures whose time has come; true if any was applied now.
    fn apply_failures(&mut self, t: f64) -> bool {
        let mut any = false;
        for (k, f) in self.failures.iter().enumerate() {
            if !self.applied[k] && f.time <= t + 1e-12 {
                any = true;
                self.applied[k] = true;
                self.actuators.fail(f.agent, f.kind);
                self.failed_true[f.agent] = true;
                if f.controller_informed {
                    self.failed_told[f.agent] = true;
                }
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
        let dt = self.scenario.physics.dt;
        let period = self.scenario.controller_period;
        let settings = self.scenario.log;
        let scene_every = ((settings.scene_period / period).round() as usize).max(1);
        let heavy_every = settings.decimation.max(1);
        let mut held = vec![ActuatorCommand::default(); self.team.len()];
        // Shared with the sink's jobs: one copy per run, not one per scene.
        let team = sink
            .as_deref()
            .is_some_and(|s| s.wants_scenes())
            .then(|| std::sync::Arc::new(self.team.clone()));
        // Reused every physics step: the step allocates nothing of its own.
        let mut forces = Vec::with_capacity(self.team.len());
        // The agents' forces follow the actuator outputs, which actuators without servo or rotor
        // lag change only at a controller tick or a failure: recomputed (two sines and two
        // cosines per agent) only then.
        let memoryless = self.scenario.actuators.is_memoryless();
        let mut forces_stale = true;
        while self.step_index < self.total_steps {
            let k = self.step_index;
            let t = k as f64 * dt;
            if self.apply_failures(t) {
                forces_stale = true;
            }
            self.attach_payloads(t)?;
            if k % self.steps_per_control == 0 {
                if cancel.is_some_and(|c| c.load(Ordering::Relaxed)) {
                    self.interrupted = true;
                    break;
                }
                let truth = self.world.state();
                check_divergence(t, &truth)?;
                let fed = self.noisy(&truth);
                let fed = self.delay.delay(fed);
                let reference = self.scenario.reference.at(t);
                let out = controller
                    .step(&FlightInput::new(t, &fed, &reference, &self.failed_told))
                    .map_err(|source| SimError::Controller { t, source })?;
                if out.commands.len() != self.team.len() {
                    return Err(SimError::Physics(PhysicsError::InvalidCommand {
                        t,
                        reason: format!(
                            "{} commands for {} agents",
                            out.commands.len(),
                            self.team.len()
                        ),
                    }));
                }
                if let Some(i) = out.commands.iter().position(|c| !c.is_finite()) {
                    return Err(SimError::Physics(PhysicsError::InvalidCommand {
                        t,
                        reason: format!("non-finite command for agent {i}"),
                    }));
                }
                held.clone_from(&out.commands);
                forces_stale = true;
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
                if let Some(sink) = sink.as_deref_mut() {
                    // The scene shows the commanded forces: at a tick the actual ones still lag
                    // by one period.
                    let scene = team
                        .clone()
                        .filter(|_| tick % scene_every == 0)
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
                        heavy: tick % heavy_every == 0,
                        scene,
                    })?;
                    sink.pace(t);
                }
            }
            self.actuators.step(&held, dt);
            if forces_stale || !memoryless {
                body_forces(
                    self.actuators.outputs(),
                    &self.team,
                    &self.scenario.plant,
                    &mut forces,
                );
                forces_stale = false;
            }
            let extra = self.extra_wrench(t);
            self.world.step(&forces, &extra)?;
            self.step_index += 1;
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
