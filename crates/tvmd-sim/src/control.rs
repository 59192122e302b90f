//! The tvmd controller in the loop: an adapter from [`tvmd_core::Controller`] to
//! [`FlightController`].
//!
//! [`TvmdController`] wraps `tvmd_core::Controller<f64, 16, AnyAllocator<f64, 16>>` unchanged.
//! It builds the core's [`TeamConfig`] from the scenario (same agent order, quarter turns,
//! masses, navigator), its gains (`K_xi` diagonal in the order `[Omega; v]`), relaxation `s`,
//! controller period, optional controller rate limits and allocator, then at each tick:
//!
//! 1. converts the simulator's state (world velocity `x_dot`, body `Omega`) into the core's
//!    state with the body-frame velocity `v = R^T x_dot`, and the reference likewise;
//! 2. passes a changed failure mask (the failures the controller is told of) to
//!    [`tvmd_core::Controller::set_failures`]; if the core refuses it (the remaining team cannot
//!    produce every wrench) the old mask stays and the reason is reported in
//!    [`Diagnostics::failure_note`];
//! 3. runs one [`tvmd_core::Controller::step`]; on a [`tvmd_core::CycleError`] it holds the
//!    commands the error carries and reports the error in [`Diagnostics::cycle_error`];
//! 4. fills every part of [`Diagnostics`] (planner, control law, allocation, Lyapunov values).

use std::collections::BTreeMap;

use nalgebra::Vector3;
use tvmd_core::error::{ConfigError, ConfigField};
use tvmd_core::{
    AgentLimits, AgentSpec, AnyAllocator, ControllerSettings, FailureMask, Gains, Navigator,
    PlannerStatus, RateLimits, Relaxation, TeamConfig,
};

use crate::actuators::ActuatorCommand;
use crate::diagnostics::{
    AllocationDiagnostics, ControlDiagnostics, Diagnostics, LyapunovDiagnostics, PlannerDiagnostics,
};
use crate::error::BoxedError;
use crate::flight::{FlightController, FlightOutput};
use crate::math::{from_rows, planned_roll, to_rows};
use crate::physics::PlantState;
use crate::reference::ReferenceSample;
use crate::scenario::Scenario;
use crate::SimError;

/// Agent capacity of the controller the simulator runs (the core's const generic `N`).
pub const MAX_AGENTS: usize = 16;

/// The core controller type the simulator runs.
pub type CoreController = tvmd_core::Controller<f64, MAX_AGENTS, AnyAllocator<f64, MAX_AGENTS>>;

/// The core's output of one cycle.
pub type CoreOutput = tvmd_core::ControlOutput<f64, MAX_AGENTS>;

/// [`tvmd_core::Controller`] as a [`FlightController`].
#[derive(Debug)]
pub struct TvmdController {
    inner: CoreController,
    n: usize,
    mask: Vec<bool>,
    failure_note: Option<String>,
    last: Option<CoreOutput>,
}

fn invalid(field: &str, reason: impl Into<String>) -> SimError {
    SimError::InvalidScenario {
        field: field.into(),
        reason: reason.into(),
    }
}

/// The scenario field a core configuration error refers to.
fn config_field(e: &ConfigError) -> &'static str {
    match e {
        ConfigError::TooManyAgents { .. } => return "team.agents",
        ConfigError::UnknownAllocator | ConfigError::AllocatorUnavailable { .. } => {
            return "allocator"
        }
        _ => {}
    }
    match e.field() {
        Some(ConfigField::SigmaX) => "limits.sigma_x",
        Some(ConfigField::SigmaY) => "limits.sigma_y",
        Some(
            ConfigField::MaxThrust
            | ConfigField::MinThrust
            | ConfigField::ThrustCoefficient
            | ConfigField::Rho
            | ConfigField::RotorDiameter
            | ConfigField::LiftCoefficient
            | ConfigField::MaxRotorSpeed,
        ) => "limits.max_thrust",
        Some(ConfigField::Relaxation) => "relaxation",
        Some(ConfigField::NavigatorInertia) if matches!(e, ConfigError::NavigatorInertia) => {
            "team.navigator_inertia"
        }
        Some(ConfigField::GainKx) => "gains.k_x",
        Some(ConfigField::GainKr) => "gains.k_r",
        Some(ConfigField::GainKomega | ConfigField::GainKv) => "gains.k_xi",
        Some(ConfigField::RateLimits) => "controller_rate_limits",
        Some(ConfigField::Period) => "controller_period",
        Some(ConfigField::Gravity) => "physics.gravity",
        Some(
            ConfigField::AllocatorWeights
            | ConfigField::ClarabelLambda
            | ConfigField::ClarabelWeights
            | ConfigField::ClarabelTolerance
            | ConfigField::PlannerTolerance
            | ConfigField::PlannerMaxIterations,
        ) => "allocator",
        _ => "team",
    }
}

fn config_error(e: ConfigError) -> SimError {
    invalid(config_field(&e), format!("rejected by the controller: {e}"))
}

fn v3(v: &Vector3<f64>) -> [f64; 3] {
    [v.x, v.y, v.z]
}

/// The core's team configuration of a scenario: agents in the scenario's order, with their
/// quarter turns and masses, the navigator, and the limits (`sigma_x`, `sigma_y`, `sigma_Tf`).
pub fn team_config(scenario: &Scenario) -> Result<TeamConfig<f64, MAX_AGENTS>, SimError> {
    let body = scenario.team_body()?;
    if body.len() > MAX_AGENTS {
        return Err(invalid(
            "team.agents",
            format!(
                "{} agents exceed the controller's capacity of {MAX_AGENTS}",
                body.len()
            ),
        ));
    }
    let agents: Vec<AgentSpec<f64>> = body
        .agents
        .iter()
        .map(|a| AgentSpec::new(a.position_vector(), a.quarter_turns, a.mass))
        .collect();
    let limits = AgentLimits::new(
        scenario.limits.sigma_x,
        scenario.limits.sigma_y,
        scenario.max_thrust()?,
    )
    .map_err(config_error)?;
    let navigator = Navigator {
        mass: body.navigator_mass,
        inertia: from_rows(&body.navigator_inertia),
    };
    TeamConfig::new(&agents, limits, navigator).map_err(config_error)
}

/// The core's controller settings of a scenario: gains, relaxation, gravity, period and the
/// optional controller rate limits.
pub fn controller_settings(scenario: &Scenario) -> Result<ControllerSettings<f64>, SimError> {
    let g = &scenario.gains;
    let gains = Gains::diagonal(g.k_x, g.k_r, g.k_xi).map_err(config_error)?;
    let relaxation = Relaxation::new(scenario.relaxation).map_err(config_error)?;
    let rate_limits = scenario
        .controller_rate_limits
        .map(|[x, y]| RateLimits::new(x, y))
        .transpose()
        .map_err(config_error)?;
    Ok(ControllerSettings {
        gains,
        relaxation,
        gravity: scenario.physics.gravity,
        period: scenario.controller_period,
        rate_limits,
    })
}

/// The allocator named by `scenario.allocator`.
pub fn allocator(name: &str) -> Result<AnyAllocator<f64, MAX_AGENTS>, SimError> {
    AnyAllocator::from_name(name, &Default::default()).map_err(|e| match e {
        ConfigError::UnknownAllocator => invalid(
            "allocator",
            format!(
                "unknown allocator `{name}` (known: {})",
                crate::scenario::ALLOCATOR_NAMES.join(", ")
            ),
        ),
        ConfigError::AllocatorUnavailable { .. } => invalid(
            "allocator",
            "allocator `clarabel` needs tvmd-sim built with the `clarabel` feature \
             (cargo build --features clarabel)",
        ),
        e => config_error(e),
    })
}

/// The core's state: `v = R^T x_dot` (body frame), `Omega` as is.
pub fn core_state(s: &PlantState) -> tvmd_core::RigidState<f64> {
    tvmd_core::RigidState {
        position: s.position,
        attitude: s.rotation,
        angular_velocity: s.omega,
        velocity: s.velocity_body(),
    }
}

/// The core's reference.
pub fn core_reference(r: &ReferenceSample) -> tvmd_core::Reference<f64> {
    tvmd_core::Reference {
        position: r.position,
        velocity: r.velocity,
        acceleration: r.acceleration,
        attitude: r.rotation,
        angular_velocity: r.omega,
        angular_acceleration: r.omega_dot,
    }
}

fn sim_command(c: &tvmd_core::AgentCommand<f64>) -> ActuatorCommand {
    ActuatorCommand {
        eta_x: c.eta_x,
        eta_y: c.eta_y,
        thrust: c.thrust,
    }
}

impl TvmdController {
    /// The controller of a scenario (team, limits, gains, relaxation, period, rate limits and
    /// allocator). Errors name the scenario field the core rejected.
    pub fn from_scenario(scenario: &Scenario) -> Result<Self, SimError> {
        let team = team_config(scenario)?;
        let settings = controller_settings(scenario)?;
        let alloc = allocator(&scenario.allocator)?;
        let n = team.len();
        let inner = CoreController::new(team, settings, alloc).map_err(config_error)?;
        Ok(Self::new(inner, n))
    }

    /// Wraps a core controller for a team of `n` agents.
    pub fn new(inner: CoreController, n: usize) -> Self {
        Self {
            inner,
            n,
            mask: vec![false; n],
            failure_note: None,
            last: None,
        }
    }

    /// The wrapped core controller.
    pub fn core(&self) -> &CoreController {
        &self.inner
    }

    /// The core's output of the last successful cycle.
    pub fn last_output(&self) -> Option<&CoreOutput> {
        self.last.as_ref()
    }

    fn update_failures(&mut self, failed: &[bool]) {
        let wanted: Vec<bool> = (0..self.n)
            .map(|i| failed.get(i).copied().unwrap_or(false))
            .collect();
        if wanted == self.mask {
            return;
        }
        let mut mask = FailureMask::<MAX_AGENTS>::none();
        for (i, f) in wanted.iter().enumerate() {
            // i < n <= MAX_AGENTS, so this cannot fail.
            let _ = mask.set(i, *f);
        }
        match self.inner.set_failures(mask) {
            Ok(()) => {
                self.failure_note = None;
            }
            Err(e) => {
                self.failure_note = Some(format!(
                    "failure mask {wanted:?} refused, keeping {:?}: {e}",
                    self.mask
                ));
            }
        }
        self.mask = self.inner.failures().as_array()[..self.n].to_vec();
        if self.mask != wanted && self.failure_note.is_none() {
            self.failure_note = Some(format!("failure mask {wanted:?} not applied"));
        }
    }

    fn diagnostics(&self, out: &CoreOutput) -> Diagnostics {
        let r_d = out.planner.r_d;
        let law = &out.law;
        let e = &law.e_xi;
        let n = self.n;
        let alloc = &out.allocation;
        let mut extra = BTreeMap::new();
        extra.insert("f_r", serde_json::json!(v3(&out.f_r)));
        extra.insert("command_clamp", serde_json::json!(out.command_clamp));
        Diagnostics {
            planner: Some(PlannerDiagnostics {
                r_d: to_rows(&r_d),
                theta: out.planner.theta,
                t_tf: out.projection.t_tf,
                t_eta: out.projection.t_eta,
                reference_feasible: out.planner.status == PlannerStatus::AlreadyFeasible,
                planned_roll: planned_roll(&r_d),
                status: out.planner.status.as_str().to_string(),
                iterations: out.planner.iterations,
            }),
            control: Some(ControlDiagnostics {
                u_r: law.u_r.into(),
                u_d: law.u_d.into(),
                e_x: v3(&law.e_x),
                e_v: [e[3], e[4], e[5]],
                e_r: v3(&law.e_r),
                e_omega: [e[0], e[1], e[2]],
                t_tf: out.projection.t_tf,
                t_eta: out.projection.t_eta,
                extra: serde_json::json!(extra),
            }),
            allocation: Some(AllocationDiagnostics {
                wrench: alloc.wrench.into(),
                e_f: alloc.e_f,
                saturated: alloc.saturated[..n].to_vec(),
                wrench_error: alloc.wrench_error,
                rounds: alloc.rounds,
                fallback: alloc.fallback,
                forces: alloc.forces[..n].iter().map(v3).collect(),
                rotor_speeds: out.commands[..n].iter().map(|c| c.omega).collect(),
            }),
            lyapunov: Some(LyapunovDiagnostics {
                v_x: law.v_x,
                v_r: law.v_r,
            }),
            cycle_error: None,
            failure_note: self.failure_note.clone(),
        }
    }
}

impl FlightController for TvmdController {
    fn step(
        &mut self,
        _t: f64,
        state: &PlantState,
        reference: &ReferenceSample,
        failed: &[bool],
    ) -> Result<FlightOutput, BoxedError> {
        self.update_failures(failed);
        match self
            .inner
            .step(&core_state(state), &core_reference(reference))
        {
            Ok(out) => {
                let diagnostics = self.diagnostics(&out);
                let commands = out.commands[..self.n].iter().map(sim_command).collect();
                self.last = Some(out);
                Ok(FlightOutput {
                    commands,
                    diagnostics,
                })
            }
            Err(e) => Ok(FlightOutput {
                commands: e.commands[..self.n].iter().map(sim_command).collect(),
                diagnostics: Diagnostics {
                    cycle_error: Some(e.to_string()),
                    failure_note: self.failure_note.clone(),
                    ..Default::default()
                },
            }),
        }
    }
}

/// `atan(c_y(1, s))`: the planned roll at which the planner saturates in hover for the
/// scenario's team, limits and relaxation `s` (a reproduction target, see `docs/method.md`).
pub fn hover_roll_limit(scenario: &Scenario, s: f64) -> Result<f64, SimError> {
    let team = team_config(scenario)?;
    let afs = team.afs(&FailureMask::none()).map_err(config_error)?;
    let s = Relaxation::new(s).map_err(config_error)?;
    Ok(afs.semi_axes(1.0, s).c_y.atan())
}
