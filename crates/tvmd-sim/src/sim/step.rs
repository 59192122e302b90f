//! The steppable entry of the loop: one controller period at a time.
//!
//! At each controller tick `t_k` the simulation offers the tick's [`Observation`] (the
//! failures and payloads due are applied, the state is read, checked for divergence, given the
//! scenario's noise and feedback latency; the reference is evaluated) and waits for the commands
//! of the period: [`Simulation::step_output`] (a controller's output, diagnostics included),
//! [`Simulation::step`] (per-agent gimbal angles and thrusts) or [`Simulation::step_wrench`]
//! (a body wrench that the scenario controller's allocation stage turns into admissible
//! commands). The commands are held for `controller_period`: the actuators, failures,
//! disturbances and payloads act at the physics rate as in [`Simulation::run`], which flies
//! its controller through this same entry. [`Simulation::reset`] starts over.
//!
//! Bad input never panics and never changes the simulation: a wrong number of commands or a
//! non-finite one is an error ([`PhysicsError::InvalidCommand`]), and so is a step past the
//! scenario's duration. A finite command outside the hardware's range is held saturated, as
//! the actuators would fly it ([`Simulation::saturation`] says by how much).

use nalgebra::{Rotation3, Vector3};
use rand::Rng;
use rand_distr::StandardNormal;

use super::reports::AgentReport;
use super::{check_divergence, forces::body_forces, Simulation};
use crate::control::WrenchAllocation;
use crate::flight::{FlightInput, FlightOutput};
use crate::SimError;
use tvmd_plant::actuators::ActuatorCommand;
use tvmd_plant::physics::{ExtraWrench, PlantState};
use tvmd_plant::reference::ReferenceSample;
use tvmd_plant::PhysicsError;
use tvmd_scenario::{Scenario, TeamSpec};

/// What a controller is given at one controller tick: the fed-back state, the reference and
/// the failures it is told of (the inputs of [`crate::FlightController::step`]), and the true
/// state the tick records.
#[derive(Clone, Debug, PartialEq)]
pub struct Observation {
    /// Simulation time `t_k` (s).
    pub t: f64,
    /// The fed-back state: the true state with the scenario's noise and feedback latency.
    pub state: PlantState,
    /// The true state.
    pub truth: PlantState,
    /// The reference at `t_k`.
    pub reference: ReferenceSample,
    /// `failed[i]`: agent `i` failed and the controller is told so.
    pub failed: Vec<bool>,
    /// Per agent, its newest report arrived by `t_k` (`None`: none yet); empty when the
    /// scenario has no `[reports]`.
    pub reports: Vec<Option<AgentReport>>,
}

impl Observation {
    /// The observation as a flight controller's input.
    pub fn input(&self) -> FlightInput<'_> {
        FlightInput::new(self.t, &self.state, &self.reference, &self.failed)
            .with_reports(&self.reports)
    }
}

/// Where a step left the simulation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stepped {
    /// Simulation time after the period (s).
    pub t: f64,
    /// The true state at `t`.
    pub state: PlantState,
    /// The scenario's duration is reached: the next step is an error until a reset.
    pub finished: bool,
}

impl Simulation {
    /// A simulation of the built-in `"hover"` scenario (hold a hover at 1.5 m for 12 s) flown
    /// by `team` (a preset or explicit agents).
    pub fn for_team(team: TeamSpec) -> Result<Self, SimError> {
        let mut scenario = Scenario::builtin("hover")?;
        scenario.team = team;
        Self::new(&scenario)
    }

    /// Starts over: the scenario's initial state, actuators at rest, no failure applied, time
    /// 0, nothing recorded. `seed` reseeds the state noise (the scenario's
    /// `disturbances.state_noise.seed` otherwise) and the draws of the agents' links and
    /// reports (streams of their own derived from it); it has no effect without any of them.
    pub fn reset(&mut self, seed: Option<u64>) -> Result<(), SimError> {
        self.reset_at(seed, None, None)
    }

    /// As [`Simulation::reset`], from another initial pose: the centre of mass at `position`
    /// (m) and the attitude `roll_pitch_yaw` (rad, ZYX), at rest. The pose replaces the
    /// scenario's `initial_position` and `initial_attitude` (later resets start there too); a
    /// pose the scenario's validation refuses is an error that changes nothing.
    pub fn reset_at(
        &mut self,
        seed: Option<u64>,
        position: Option<[f64; 3]>,
        roll_pitch_yaw: Option<[f64; 3]>,
    ) -> Result<(), SimError> {
        let mut scenario = self.scenario.clone();
        if let (Some(seed), Some(noise)) = (seed, scenario.disturbances.state_noise.as_mut()) {
            noise.seed = seed;
        }
        // splitmix64's increment: streams apart from the noise's.
        let stream = |k: u64| seed.map(|s| s.wrapping_add(k.wrapping_mul(0x9E37_79B9_7F4A_7C15)));
        if let (Some(seed), Some(links)) = (stream(1), scenario.links.as_mut()) {
            links.seed = seed;
        }
        if let (Some(seed), Some(reports)) = (stream(2), scenario.reports.as_mut()) {
            reports.seed = seed;
        }
        if let Some(p) = position {
            scenario.initial_position = p;
        }
        if let Some(a) = roll_pitch_yaw {
            scenario.initial_attitude = a;
        }
        *self = Self::with_options(&scenario, self.options)?;
        Ok(())
    }

    /// Simulation time (s): the current controller tick's.
    pub fn time(&self) -> f64 {
        self.step_index as f64 * self.scenario.physics.dt
    }

    /// The true state now.
    pub fn state(&self) -> PlantState {
        self.world.state()
    }

    /// Per agent, what its command link did so far: commands sent, lost, overtaken, and
    /// failsafes (`None`: the scenario has no links).
    pub fn link_stats(&self) -> Option<Vec<super::links::LinkStats>> {
        self.commands.link_stats()
    }

    /// Per agent, the newest report of the current tick's observation as the agent would have
    /// sent it had it not failed: its actuators' healthy twin (the same model given the same
    /// commands, never failed; a lying agent's command) measured with the same noise draws.
    /// Against [`Observation::reports`] it is the failure's effect on the report, without
    /// noise: zero for an agent that has not failed. Empty without `[reports]`.
    pub fn healthy_reports(&self) -> Vec<Option<AgentReport>> {
        self.commands.healthy_reports(self.time())
    }

    /// The number of agents (the length of every step's commands).
    pub fn agents(&self) -> usize {
        self.team.len()
    }

    /// Per agent, by how much the plant clamped the last step's command to the hardware's
    /// range (the command minus what it held: `eta_x`, `eta_y` in rad, thrust in N; zero
    /// inside the range and before the first step). See the module `saturation`.
    pub fn saturation(&self) -> &[ActuatorCommand] {
        self.commands.clamped()
    }

    /// The largest thrust of one agent, `sigma_Tf` (N): the thrust at the normalized rotor
    /// speed 1 (`T = sigma_Tf omega^2`).
    pub fn max_thrust(&self) -> f64 {
        self.max_thrust
    }

    /// The scenario's duration is reached: no tick is left to step.
    pub fn is_finished(&self) -> bool {
        self.step_index >= self.total_steps
    }

    /// The current tick's observation, taken once per tick (the noise is drawn then). At the
    /// end of the run it is the last state's, which no step follows.
    ///
    /// Errors: the state diverged, a payload could not attach.
    pub fn observe(&mut self) -> Result<&Observation, SimError> {
        if self.observed.is_none() {
            self.observed = Some(self.new_observation()?);
        }
        self.observed
            .as_ref()
            .ok_or_else(|| SimError::Internal("no observation".into()))
    }

    /// Holds `commands` (one per agent: gimbal angles and thrust) for one controller period.
    /// The tick is recorded as with a controller that reports no diagnostics.
    pub fn step(&mut self, commands: &[ActuatorCommand]) -> Result<Stepped, SimError> {
        self.step_output(FlightOutput {
            commands: commands.to_vec(),
            diagnostics: Default::default(),
        })
    }

    /// Holds a controller's output for one controller period, recording its diagnostics with
    /// the tick: the step [`Simulation::run`] takes at every tick.
    pub fn step_output(&mut self, out: FlightOutput) -> Result<Stepped, SimError> {
        if self.is_finished() {
            return Err(self.past_the_end());
        }
        self.check_commands(self.time(), &out.commands)?;
        let observation = self.take_observation()?;
        self.apply_output(observation, out, None)?;
        Ok(self.stepped())
    }

    /// Holds the commands of the body wrench `wrench = [u_tau; u_f]` (N m, N; body frame,
    /// about the centre of mass) for one controller period: the scenario controller's
    /// allocation stage (its allocator, limits, rate limits, null-space stage; in f64) turns it
    /// into admissible commands, the failed agents the controller is told of idle
    /// ([`WrenchAllocation`]).
    pub fn step_wrench(&mut self, wrench: &[f64; 6]) -> Result<Stepped, SimError> {
        if self.is_finished() {
            return Err(self.past_the_end());
        }
        // The tick's failures are applied with its observation: the allocation knows them.
        self.observe()?;
        let failed = self.failed_told.clone();
        let t = self.time();
        let allocation = match self.allocation.as_mut() {
            Some(a) => a,
            None => self
                .allocation
                .insert(WrenchAllocation::from_scenario(&self.scenario)?),
        };
        let commands = allocation.commands(t, wrench, &failed)?;
        self.step(&commands)
    }

    fn stepped(&self) -> Stepped {
        Stepped {
            t: self.time(),
            state: self.state(),
            finished: self.is_finished(),
        }
    }

    fn past_the_end(&self) -> SimError {
        SimError::InvalidArgument {
            name: "step".into(),
            reason: format!(
                "the scenario's duration ({} s) is reached; reset the simulation",
                self.scenario.duration
            ),
        }
    }

    /// The current tick's observation, moved out (taken now if not yet).
    pub(super) fn take_observation(&mut self) -> Result<Observation, SimError> {
        match self.observed.take() {
            Some(o) => Ok(o),
            None => self.new_observation(),
        }
    }

    fn new_observation(&mut self) -> Result<Observation, SimError> {
        let t = self.time();
        if self.apply_failures(t) {
            self.forces_stale = true;
        }
        self.attach_payloads(t)?;
        let truth = self.world.state();
        check_divergence(t, &truth)?;
        let fed = self.noisy(&truth);
        let state = self.delay.delay(fed);
        Ok(Observation {
            t,
            state,
            truth,
            reference: self.scenario.reference.at(t),
            failed: self.failed_told.clone(),
            reports: self.commands.reports_at(t),
        })
    }

    /// `Err` unless there is one finite command per agent.
    pub(super) fn check_commands(
        &self,
        t: f64,
        commands: &[ActuatorCommand],
    ) -> Result<(), SimError> {
        let invalid =
            |reason: String| SimError::Physics(PhysicsError::InvalidCommand { t, reason });
        if commands.len() != self.team.len() {
            return Err(invalid(format!(
                "{} commands for {} agents",
                commands.len(),
                self.team.len()
            )));
        }
        if let Some(i) = commands.iter().position(|c| !c.is_finite()) {
            return Err(invalid(format!("non-finite command for agent {i}")));
        }
        Ok(())
    }

    /// The physics steps of one controller period (fewer at the end of the run) with the held
    /// commands; the tick's failures and payloads were applied by its observation.
    pub(super) fn advance_period(&mut self) -> Result<(), SimError> {
        let dt = self.scenario.physics.dt;
        // The agents' forces follow the actuator outputs, which actuators without servo or
        // rotor lag change only at a controller tick or a failure: recomputed (two sines and
        // two cosines per agent) only then.
        let memoryless = self.scenario.actuators.is_memoryless();
        let first = self.step_index;
        let end = (first + self.steps_per_control).min(self.total_steps);
        while self.step_index < end {
            let t = self.step_index as f64 * dt;
            if self.step_index != first {
                if self.apply_failures(t) {
                    self.forces_stale = true;
                }
                self.attach_payloads(t)?;
            }
            self.commands.sample_reports(t, &self.actuators);
            let (applied, changed) = self.commands.applied(t);
            self.forces_stale |= changed;
            self.actuators.step(applied, dt);
            self.commands.step_twin(dt);
            if self.forces_stale || !memoryless {
                body_forces(
                    self.actuators.outputs(),
                    &self.team,
                    &self.scenario.plant,
                    &mut self.forces,
                );
                self.forces_stale = false;
            }
            let extra = self.extra_wrench(t);
            self.world.step(&self.forces, &extra)?;
            self.step_index += 1;
        }
        Ok(())
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
}
