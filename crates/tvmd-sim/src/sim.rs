//! The digital control loop.
//!
//! Physics runs at `physics.dt`; the controller runs every `controller_period` (an integer
//! number of physics steps) and its commands are held (zero-order hold) until the next call.
//! Actuators, failures and disturbances act at the physics rate. Each controller tick
//! (`t_k = k controller_period`):
//!
//! 1. the true state is read and, if configured, noise is added to the copy fed back;
//! 2. the reference is evaluated at `t_k`;
//! 3. the controller is called with the state, the reference and the failure flags it is
//!    told about (a failure with `controller_informed = false` stays `false` for it);
//! 4. the sample (true state, reference, commands, diagnostics) is recorded and logged.
//!
//! Then `steps_per_control` physics steps follow, each one: failures whose time has come are
//! applied, the actuators move towards the held commands, and the agents' body-frame forces
//! (plus wind and external wrench) are applied for one step.

use nalgebra::{Matrix3, Rotation3, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;
use serde::{Deserialize, Serialize};

use crate::actuators::{agent_force_body, ActuatorBank, AgentCommand};
use crate::error::BoxedError;
use crate::log::{ActuatorsMsg, LogKind, McapLog, Quat, ReferenceMsg, StateMsg};
use crate::math::{roll_pitch_yaw, to_rows};
use crate::physics::{ExtraWrench, PhysicsWorld, RigidState, TeamBody};
use crate::reference::Reference;
use crate::scenario::{Failure, Scenario, StateNoise};
use crate::SimError;

/// Attitude-planner diagnostics (logged on `/planner`).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct PlannerDiagnostics {
    /// Planned attitude `R_d`, row-major.
    pub r_d: [[f64; 3]; 3],
    /// Bisection angle `theta*` (rad); 0 when `R_d = R_r`.
    pub theta: f64,
    /// Thrust scaling `t_Tf`.
    pub t_tf: f64,
    /// Gimbal scaling `t_eta`.
    pub t_eta: f64,
    /// Whether `R_r` itself was feasible.
    pub reference_feasible: bool,
    /// Planned roll `atan2(R_d[2,1], R_d[2,2])` (rad).
    #[serde(default)]
    pub planned_roll: f64,
    /// How the planner reached `R_d` (e.g. `already-feasible`, `planned`).
    #[serde(default)]
    pub status: String,
    /// Bisection iterations used.
    #[serde(default)]
    pub iterations: u32,
}

/// Control-law diagnostics (logged on `/control`).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ControlDiagnostics {
    /// `u_r = [tau; f]` before projection.
    pub u_r: [f64; 6],
    /// `u_d = blockdiag(I, K_f) u_r`.
    pub u_d: [f64; 6],
    /// `e_x` (m).
    pub e_x: [f64; 3],
    /// `e_v` (m/s).
    pub e_v: [f64; 3],
    /// `e_R`.
    pub e_r: [f64; 3],
    /// `e_Omega` (rad/s).
    pub e_omega: [f64; 3],
    /// Thrust scaling `t_Tf` of the force projection.
    #[serde(default)]
    pub t_tf: f64,
    /// Gimbal scaling `t_eta` of the force projection.
    #[serde(default)]
    pub t_eta: f64,
    /// Anything else the controller wants logged.
    #[serde(default, skip_serializing_if = "serde_json::Value::is_null")]
    pub extra: serde_json::Value,
}

/// Allocation diagnostics (logged on `/allocation`).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct AllocationDiagnostics {
    /// Wrench `M f` of the allocated agent forces, `[tau; f]`.
    pub wrench: [f64; 6],
    /// Allocation error `e_f = ||u_fd - u_f||` (N).
    pub e_f: f64,
    /// Per agent: whether the allocator saturated it.
    pub saturated: Vec<bool>,
    /// `||u_d - M f||` over the whole wrench.
    #[serde(default)]
    pub wrench_error: f64,
    /// Solve rounds (pseudo-inverse 1, redistribution up to `n`, Clarabel: iterations).
    #[serde(default)]
    pub rounds: u32,
    /// The allocator fell back to another method.
    #[serde(default)]
    pub fallback: bool,
    /// Allocated agent-frame forces `f_i` (N).
    #[serde(default)]
    pub forces: Vec<[f64; 3]>,
    /// Rotor speeds of the commands (normalised to 1 at maximum thrust unless rotor constants
    /// are given).
    #[serde(default)]
    pub rotor_speeds: Vec<f64>,
}

/// Lyapunov candidates (logged on `/lyapunov`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct LyapunovDiagnostics {
    /// `V_x = ||e_x||_{K_x} + ||e_v||_{K_v}`.
    pub v_x: f64,
    /// `V_R = Psi(R, R_d) + ||e_Omega||_{K_Omega}`.
    pub v_r: f64,
}

/// Optional diagnostics returned by a controller; every present part is logged and recorded.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Diagnostics {
    /// Planner.
    pub planner: Option<PlannerDiagnostics>,
    /// Control law.
    pub control: Option<ControlDiagnostics>,
    /// Allocation.
    pub allocation: Option<AllocationDiagnostics>,
    /// Lyapunov candidates.
    pub lyapunov: Option<LyapunovDiagnostics>,
    /// The controller skipped this cycle and held its previous commands, for this reason.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cycle_error: Option<String>,
    /// A note on the failure mask (e.g. the controller could not use the reported failures).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub failure_note: Option<String>,
}

/// What a controller returns at each tick.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ControlOutput {
    /// One command per agent (failed agents included; their commands are ignored as the
    /// failure dictates).
    pub commands: Vec<AgentCommand>,
    /// Diagnostics to log.
    pub diagnostics: Diagnostics,
}

/// A digital flight controller.
///
/// `state` is the (possibly noisy) fed-back state; `failed[i]` is true if agent `i` failed
/// and the controller is told so. Closures with the same signature implement the trait.
pub trait FlightController {
    /// Computes the commands for the next controller period.
    fn step(
        &mut self,
        t: f64,
        state: &RigidState,
        reference: &Reference,
        failed: &[bool],
    ) -> Result<ControlOutput, BoxedError>;
}

impl<F> FlightController for F
where
    F: FnMut(f64, &RigidState, &Reference, &[bool]) -> Result<ControlOutput, BoxedError>,
{
    fn step(
        &mut self,
        t: f64,
        state: &RigidState,
        reference: &Reference,
        failed: &[bool],
    ) -> Result<ControlOutput, BoxedError> {
        self(t, state, reference, failed)
    }
}

/// One recorded sample (at each controller tick, true state).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Sample {
    /// Time (s).
    pub t: f64,
    /// `x` (m).
    pub position: [f64; 3],
    /// `x_dot` (m/s).
    pub velocity: [f64; 3],
    /// `x_r` (m).
    pub reference_position: [f64; 3],
    /// Roll, pitch, yaw of `R` (rad).
    pub roll_pitch_yaw: [f64; 3],
    /// Roll, pitch, yaw of `R_r` (rad).
    pub reference_roll_pitch_yaw: [f64; 3],
    /// `phi_r` (rad).
    pub reference_roll: f64,
    /// Roll of the planned `R_d` (rad), if the controller reported it.
    pub planned_roll: Option<f64>,
    /// Roll, pitch, yaw of the planned `R_d` (rad), if reported.
    pub planned_roll_pitch_yaw: Option<[f64; 3]>,
    /// Angle between `R` and the planned `R_d` (rad), if `R_d` was reported.
    pub attitude_error: Option<f64>,
    /// Planner angle `theta*` (rad), if reported.
    pub theta: Option<f64>,
    /// Allocation error `e_f` (N), if reported.
    pub e_f: Option<f64>,
    /// Number of agents the allocator saturated, if reported.
    pub saturated_agents: Option<usize>,
    /// `V_x`, if reported.
    pub v_x: Option<f64>,
    /// `V_R`, if reported.
    pub v_r: Option<f64>,
    /// The controller skipped this cycle (held its previous commands).
    pub cycle_error: bool,
    /// Commands returned at this tick.
    pub commands: Vec<AgentCommand>,
    /// Actual actuator outputs at this tick (before the new commands act).
    pub actual: Vec<AgentCommand>,
    /// True failure flags.
    pub failed: Vec<bool>,
}

impl Sample {
    /// `||x - x_r||` (m).
    pub fn position_error(&self) -> f64 {
        norm3(&sub3(&self.position, &self.reference_position))
    }

    /// Horizontal position error `||(x - x_r)_{x,y}||` (m).
    pub fn horizontal_error(&self) -> f64 {
        let d = sub3(&self.position, &self.reference_position);
        d[0].hypot(d[1])
    }
}

fn sub3(a: &[f64; 3], b: &[f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn norm3(a: &[f64; 3]) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}

/// Time after which [`RunSummary::max_position_error_after_4s`] is taken (s): the end of
/// the paper's ascent plus its hover (stage A).
pub const SETTLING_TIME: f64 = 4.0;

/// Summary of a run.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RunSummary {
    /// Scenario name.
    pub scenario: String,
    /// Simulated time reached (s).
    pub time: f64,
    /// Final position (m).
    pub final_position: [f64; 3],
    /// Final world velocity (m/s).
    pub final_velocity: [f64; 3],
    /// Final body angular velocity (rad/s).
    pub final_omega: [f64; 3],
    /// Final roll, pitch, yaw (rad).
    pub final_roll_pitch_yaw: [f64; 3],
    /// Largest `||x - x_r||` over the samples (m).
    pub max_position_error: f64,
    /// Largest `||x - x_r||` over the samples at `t >= SETTLING_TIME` (4 s) (m).
    pub max_position_error_after_4s: f64,
    /// `||x - x_r||` at the last sample (m).
    pub final_position_error: f64,
    /// Horizontal error `||(x - x_r)_{x,y}||` at the sample nearest to `t = 4 s` (m).
    pub horizontal_error_at_4s: Option<f64>,
    /// Horizontal error at the sample nearest to `t = 12 s` (m).
    pub horizontal_error_at_12s: Option<f64>,
    /// Largest tilt angle (angle between body z and world z) over the samples (rad).
    pub max_tilt: f64,
    /// Largest actual roll `|phi|` (rad).
    pub max_roll: f64,
    /// Largest planned roll `|phi_d|`, if reported (rad).
    pub max_planned_roll: Option<f64>,
    /// Largest allocation error `e_f`, if reported (N).
    pub max_e_f: Option<f64>,
    /// Time of the largest `e_f` (s).
    pub max_e_f_time: Option<f64>,
    /// Largest `e_f / (m_C g)`, if reported.
    pub max_e_f_over_weight: Option<f64>,
    /// `V_x` at the last sample, if reported.
    pub final_v_x: Option<f64>,
    /// `V_R` at the last sample, if reported.
    pub final_v_r: Option<f64>,
    /// Smallest commanded thrust of a working agent (N).
    pub min_thrust: Option<f64>,
    /// Largest commanded thrust (N).
    pub max_thrust: Option<f64>,
    /// Largest commanded `|eta_x|` (rad).
    pub max_abs_eta_x: f64,
    /// Largest commanded `|eta_y|` (rad).
    pub max_abs_eta_y: f64,
    /// Controller periods in which the allocator saturated at least one agent.
    pub saturated_periods: usize,
    /// Controller periods the controller skipped (held commands).
    pub cycle_errors: usize,
    /// Number of controller calls.
    pub controller_calls: usize,
    /// Number of physics steps.
    pub physics_steps: usize,
    /// Wall-clock time spent in [`Simulation::run`] (s), logging included.
    pub wall_time: f64,
    /// Real-time factor: simulated time over wall time.
    pub real_time_factor: f64,
}

/// Result of a run: the samples and a summary.
#[derive(Clone, Debug, Serialize)]
pub struct RunResult {
    /// Samples at the controller rate.
    pub samples: Vec<Sample>,
    /// Summary.
    pub summary: RunSummary,
}

/// Options that are not part of the scenario.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SimOptions {
    /// Period of `/scene` messages (s); rounded to a multiple of the controller period.
    pub scene_period: f64,
}

impl Default for SimOptions {
    fn default() -> Self {
        Self { scene_period: 0.05 }
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
    failed_true: Vec<bool>,
    failed_told: Vec<bool>,
    noise: Option<(StateNoise, ChaCha8Rng)>,
    max_thrust: f64,
    options: SimOptions,
    samples: Vec<Sample>,
    step_index: usize,
    controller_calls: usize,
    wall_time: f64,
}

fn arr(v: &Vector3<f64>) -> [f64; 3] {
    [v.x, v.y, v.z]
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
        let initial = RigidState::at_rest(Vector3::from(scenario.initial_position));
        let world = PhysicsWorld::new(&team, &scenario.physics, &initial)?;
        let n = team.len();
        let mut failures = scenario.failures.clone();
        failures.sort_by(|a, b| a.time.total_cmp(&b.time));
        let steps_per_control = scenario.steps_per_control()?;
        let total_steps = (scenario.duration / scenario.physics.dt).round() as usize;
        Ok(Self {
            actuators: ActuatorBank::new(scenario.actuators, n),
            applied: vec![false; failures.len()],
            failures,
            failed_true: vec![false; n],
            failed_told: vec![false; n],
            noise: scenario
                .disturbances
                .state_noise
                .map(|s| (s, ChaCha8Rng::seed_from_u64(s.seed))),
            max_thrust: scenario.max_thrust()?,
            scenario: scenario.clone(),
            team,
            world,
            steps_per_control,
            total_steps,
            options,
            samples: Vec::new(),
            step_index: 0,
            controller_calls: 0,
            wall_time: 0.0,
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

    /// Samples recorded so far (also available after a failed run).
    pub fn samples(&self) -> &[Sample] {
        &self.samples
    }

    fn noisy(&mut self, s: &RigidState) -> RigidState {
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
        RigidState {
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
        if let Some(e) = d.external_wrench.as_ref().filter(|e| e.active(t)) {
            w.force_world += Vector3::from(e.force);
            w.torque_body += Vector3::from(e.torque);
        }
        w
    }

    fn apply_failures(&mut self, t: f64) {
        for (k, f) in self.failures.iter().enumerate() {
            if !self.applied[k] && f.time <= t + 1e-12 {
                self.applied[k] = true;
                self.actuators.fail(f.agent, f.kind);
                self.failed_true[f.agent] = true;
                if f.controller_informed {
                    self.failed_told[f.agent] = true;
                }
            }
        }
    }

    fn forces(&self, actual: &[AgentCommand]) -> Vec<Vector3<f64>> {
        actual
            .iter()
            .zip(&self.team.agents)
            .map(|(c, a)| agent_force_body(c, a.quarter_turns))
            .collect()
    }

    /// Runs the scenario to its end with `controller`, logging to `log` if given.
    ///
    /// On error the samples recorded so far stay available through
    /// [`Simulation::samples`]; the caller's log stays valid (finalised on drop).
    pub fn run(
        &mut self,
        controller: &mut dyn FlightController,
        log: Option<&mut McapLog>,
    ) -> Result<RunResult, SimError> {
        let start = std::time::Instant::now();
        let result = self.run_loop(controller, log);
        self.wall_time += start.elapsed().as_secs_f64();
        result?;
        Ok(RunResult {
            samples: self.samples.clone(),
            summary: self.summary(),
        })
    }

    fn run_loop(
        &mut self,
        controller: &mut dyn FlightController,
        mut log: Option<&mut McapLog>,
    ) -> Result<(), SimError> {
        let dt = self.scenario.physics.dt;
        let period = self.scenario.controller_period;
        let scene_every = ((self.options.scene_period / period).round() as usize).max(1);
        let mut held = vec![AgentCommand::default(); self.team.len()];
        while self.step_index < self.total_steps {
            let k = self.step_index;
            let t = k as f64 * dt;
            self.apply_failures(t);
            if k % self.steps_per_control == 0 {
                let truth = self.world.state();
                let fed = self.noisy(&truth);
                let reference = self.scenario.reference.at(t);
                let out = controller
                    .step(t, &fed, &reference, &self.failed_told)
                    .map_err(|source| SimError::Controller { t, source })?;
                if out.commands.len() != self.team.len() {
                    return Err(SimError::InvalidCommand {
                        t,
                        reason: format!(
                            "{} commands for {} agents",
                            out.commands.len(),
                            self.team.len()
                        ),
                    });
                }
                if let Some(i) = out.commands.iter().position(|c| !c.is_finite()) {
                    return Err(SimError::InvalidCommand {
                        t,
                        reason: format!("non-finite command for agent {i}"),
                    });
                }
                held.clone_from(&out.commands);
                let tick = self.controller_calls;
                self.controller_calls += 1;
                self.record(t, &truth, &reference, &out);
                if let Some(log) = log.as_deref_mut() {
                    self.log_tick(log, t, &truth, &reference, &out, tick % scene_every == 0)?;
                }
            }
            let actual = self.actuators.step(&held, dt);
            let forces = self.forces(&actual);
            let extra = self.extra_wrench(t);
            self.world.step(&forces, &extra)?;
            self.step_index += 1;
        }
        Ok(())
    }

    fn record(&mut self, t: f64, s: &RigidState, r: &Reference, out: &ControlOutput) {
        let d = &out.diagnostics;
        let r_d = d.planner.as_ref().map(|p| crate::math::from_rows(&p.r_d));
        self.samples.push(Sample {
            t,
            position: arr(&s.position),
            velocity: arr(&s.velocity),
            reference_position: arr(&r.position),
            roll_pitch_yaw: roll_pitch_yaw(&s.rotation),
            reference_roll_pitch_yaw: roll_pitch_yaw(&r.rotation),
            reference_roll: r.roll,
            planned_roll: r_d.as_ref().map(crate::control::planned_roll),
            planned_roll_pitch_yaw: r_d.as_ref().map(roll_pitch_yaw),
            attitude_error: r_d
                .as_ref()
                .map(|m| crate::math::rotation_distance(&s.rotation, m)),
            theta: d.planner.as_ref().map(|p| p.theta),
            e_f: d.allocation.as_ref().map(|a| a.e_f),
            saturated_agents: d
                .allocation
                .as_ref()
                .map(|a| a.saturated.iter().filter(|x| **x).count()),
            v_x: d.lyapunov.map(|l| l.v_x),
            v_r: d.lyapunov.map(|l| l.v_r),
            cycle_error: d.cycle_error.is_some(),
            commands: out.commands.clone(),
            actual: self.actuators.actual(),
            failed: self.failed_true.clone(),
        });
    }

    fn log_tick(
        &self,
        log: &mut McapLog,
        t: f64,
        s: &RigidState,
        r: &Reference,
        out: &ControlOutput,
        scene: bool,
    ) -> Result<(), SimError> {
        log.write(
            LogKind::State,
            t,
            &StateMsg {
                t,
                position: arr(&s.position),
                velocity: arr(&s.velocity),
                velocity_body: arr(&s.velocity_body()),
                orientation: Quat::from_matrix(&s.rotation),
                rotation: to_rows(&s.rotation),
                roll_pitch_yaw: roll_pitch_yaw(&s.rotation),
                omega: arr(&s.omega),
            },
        )?;
        log.write(
            LogKind::Reference,
            t,
            &ReferenceMsg {
                t,
                position: arr(&r.position),
                velocity: arr(&r.velocity),
                acceleration: arr(&r.acceleration),
                rotation: to_rows(&r.rotation),
                omega: arr(&r.omega),
                roll: r.roll,
                roll_rate: r.roll_rate,
            },
        )?;
        let d = &out.diagnostics;
        if let Some(p) = &d.planner {
            #[derive(Serialize)]
            struct P<'a> {
                #[serde(flatten)]
                p: &'a PlannerDiagnostics,
                planned_roll_pitch_yaw: [f64; 3],
            }
            let rpy = roll_pitch_yaw(&crate::math::from_rows(&p.r_d));
            log.write(
                LogKind::Planner,
                t,
                &P {
                    p,
                    planned_roll_pitch_yaw: rpy,
                },
            )?;
        }
        if let Some(c) = &d.control {
            log.write(LogKind::Control, t, c)?;
        }
        if d.cycle_error.is_some() || d.failure_note.is_some() {
            // A skipped cycle has no law output: log why on the control channel.
            log.write(
                LogKind::Control,
                t,
                &serde_json::json!({"extra": {
                    "cycle_error": d.cycle_error, "failure_note": d.failure_note}}),
            )?;
        }
        if let Some(a) = &d.allocation {
            log.write(LogKind::Allocation, t, a)?;
        }
        if let Some(l) = &d.lyapunov {
            log.write(LogKind::Lyapunov, t, l)?;
        }
        let actual = self.actuators.actual();
        let forces = self.forces(&actual);
        log.write(
            LogKind::Actuators,
            t,
            &ActuatorsMsg {
                t,
                commanded: out.commands.clone(),
                actual,
                failed: self.failed_true.clone(),
                forces_body: forces.iter().map(arr).collect(),
            },
        )?;
        log.write_frame_transform(t, &s.position, &s.rotation)?;
        if scene {
            // Show the commanded forces: at a tick the actual ones still lag by one period.
            let cmd_forces = self.forces(&out.commands);
            log.write_scene(
                t,
                &self.team,
                &cmd_forces,
                &self.failed_true,
                self.max_thrust,
            )?;
        }
        Ok(())
    }

    /// Summary of the run so far (final state from the physics, extremes from the samples).
    pub fn summary(&self) -> RunSummary {
        let s = self.world.state();
        let samples = &self.samples;
        let max_of = |it: &mut dyn Iterator<Item = f64>| {
            it.fold(None, |m: Option<f64>, v| Some(m.map_or(v, |m| m.max(v))))
        };
        let tilt = |x: &Sample| {
            let [r, p, _] = x.roll_pitch_yaw;
            (r.cos() * p.cos()).clamp(-1.0, 1.0).acos()
        };
        let nearest = |t: f64| {
            samples
                .iter()
                .min_by(|a, b| (a.t - t).abs().total_cmp(&(b.t - t).abs()))
                .filter(|x| (x.t - t).abs() <= self.scenario.controller_period)
                .map(Sample::horizontal_error)
        };
        let weight = self.team.mass() * self.scenario.physics.gravity;
        let e_f_max = samples.iter().filter_map(|x| x.e_f.map(|e| (x.t, e))).fold(
            None,
            |m: Option<(f64, f64)>, (t, e)| match m {
                Some((_, me)) if me >= e => m,
                _ => Some((t, e)),
            },
        );
        let working_thrusts = || {
            samples.iter().flat_map(|x| {
                x.commands
                    .iter()
                    .zip(&x.failed)
                    .filter(|(_, f)| !**f)
                    .map(|(c, _)| c.thrust)
            })
        };
        let commands = || samples.iter().flat_map(|x| x.commands.iter());
        let time = self.world.time();
        RunSummary {
            scenario: self.scenario.name.clone(),
            time,
            final_position: arr(&s.position),
            final_velocity: arr(&s.velocity),
            final_omega: arr(&s.omega),
            final_roll_pitch_yaw: roll_pitch_yaw(&s.rotation),
            max_position_error: samples
                .iter()
                .map(Sample::position_error)
                .fold(0.0, f64::max),
            max_position_error_after_4s: samples
                .iter()
                .filter(|x| x.t >= SETTLING_TIME - 1e-9)
                .map(Sample::position_error)
                .fold(0.0, f64::max),
            final_position_error: samples.last().map(Sample::position_error).unwrap_or(0.0),
            horizontal_error_at_4s: nearest(4.0),
            horizontal_error_at_12s: nearest(12.0),
            max_tilt: samples.iter().map(tilt).fold(0.0, f64::max),
            max_roll: samples
                .iter()
                .map(|x| x.roll_pitch_yaw[0].abs())
                .fold(0.0, f64::max),
            max_planned_roll: max_of(
                &mut samples.iter().filter_map(|x| x.planned_roll.map(f64::abs)),
            ),
            max_e_f: e_f_max.map(|(_, e)| e),
            max_e_f_time: e_f_max.map(|(t, _)| t),
            max_e_f_over_weight: e_f_max.map(|(_, e)| e / weight),
            final_v_x: samples.last().and_then(|x| x.v_x),
            final_v_r: samples.last().and_then(|x| x.v_r),
            min_thrust: working_thrusts()
                .fold(None, |m: Option<f64>, v| Some(m.map_or(v, |m| m.min(v)))),
            max_thrust: max_of(&mut working_thrusts()),
            max_abs_eta_x: commands().map(|c| c.eta_x.abs()).fold(0.0, f64::max),
            max_abs_eta_y: commands().map(|c| c.eta_y.abs()).fold(0.0, f64::max),
            saturated_periods: samples
                .iter()
                .filter(|x| x.saturated_agents.is_some_and(|n| n > 0))
                .count(),
            cycle_errors: samples.iter().filter(|x| x.cycle_error).count(),
            controller_calls: self.controller_calls,
            physics_steps: self.step_index,
            wall_time: self.wall_time,
            real_time_factor: if self.wall_time > 0.0 {
                time / self.wall_time
            } else {
                f64::INFINITY
            },
        }
    }
}

/// Tilt of a rotation: angle between body z and world z (rad).
pub fn tilt_angle(r: &Matrix3<f64>) -> f64 {
    r[(2, 2)].clamp(-1.0, 1.0).acos()
}
