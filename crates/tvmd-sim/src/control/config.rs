//! The core's configuration of a scenario, in the controller's float type `T`: team
//! ([`team_config`]), settings ([`controller_settings`]) and allocator ([`allocator`]), with
//! the core's configuration errors mapped to the scenario field they refer to.

use tvmd_core::error::{ConfigError, ConfigField};
use tvmd_core::{
    AgentLimits, AgentSpec, AllocatorOptions, AnyAllocator, AttitudeRateFilter, ControllerSettings,
    DisturbanceObserver, FailureMask, FaultDetection, FaultResponse, GainSchedule, Gains,
    IntegralAction, NaturalGains, Navigator, OffsetFree, RateLimits, Relaxation, TeamConfig,
};

use super::convert::{matrix_to_core, to_core, vector_to_core, CoreFloat};
use super::MAX_AGENTS;
use crate::SimError;
use tvmd_plant::math::from_rows;
use tvmd_scenario::{
    AttitudeRateConfig, FaultDetectionConfig, FaultResponseConfig, GainScheduleConfig, LawConfig,
    OffsetFreeConfig, Scenario,
};

pub(super) fn invalid(field: &str, reason: impl Into<String>) -> SimError {
    SimError::invalid_field(field, reason)
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
        Some(ConfigField::NaturalFrequency | ConfigField::DampingRatio) => "law.gains.natural",
        Some(ConfigField::IntegralGain | ConfigField::ObserverBandwidth) => "law.offset_free",
        Some(ConfigField::OffsetFreeTorqueBound) => "law.offset_free.max_torque",
        Some(ConfigField::AttitudeRateBandwidth) => "law.attitude_rate.bandwidth",
        Some(ConfigField::AttitudeRateLimit) => "law.attitude_rate.max_rate",
        Some(ConfigField::FaultNoise) => "fault_detection.model_error",
        Some(ConfigField::FaultThreshold) => "fault_detection.threshold",
        Some(ConfigField::FaultPersistence) => "fault_detection.persistence",
        Some(ConfigField::FaultResidual) => "fault_detection",
        Some(ConfigField::RateLimits) => "controller_rate_limits",
        Some(ConfigField::Period) => "controller_period",
        Some(ConfigField::Gravity) => "physics.gravity",
        Some(
            ConfigField::AllocatorWeights
            | ConfigField::AllocatorMaxRounds
            | ConfigField::ClarabelLambda
            | ConfigField::ClarabelWeights
            | ConfigField::ClarabelTolerance
            | ConfigField::PlannerTolerance
            | ConfigField::PlannerMaxIterations,
        ) => "allocator",
        _ => "team",
    }
}

pub(super) fn config_error(e: ConfigError) -> SimError {
    invalid(config_field(&e), format!("rejected by the controller: {e}"))
}

/// The core's team configuration of a scenario in `T`: agents in the scenario's order, with
/// their quarter turns and masses, the navigator, and the limits (`sigma_x`, `sigma_y`,
/// `sigma_Tf`).
pub fn team_config<T: CoreFloat>(
    scenario: &Scenario,
) -> Result<TeamConfig<T, MAX_AGENTS>, SimError> {
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
    let agents: Vec<AgentSpec<T>> = body
        .agents
        .iter()
        .map(|a| {
            AgentSpec::new(
                vector_to_core(&a.position_vector()),
                a.quarter_turns,
                to_core(a.mass),
            )
        })
        .collect();
    let limits = AgentLimits::new(
        to_core(scenario.limits.sigma_x),
        to_core(scenario.limits.sigma_y),
        to_core(scenario.max_thrust()?),
    )
    .map_err(config_error)?;
    let navigator = Navigator {
        mass: to_core(body.navigator_mass),
        inertia: matrix_to_core(&from_rows(&body.navigator_inertia)),
    };
    TeamConfig::new(&agents, limits, navigator).map_err(config_error)
}

/// The core's controller settings of a scenario in `T`: gains, relaxation, gravity, period,
/// the optional controller rate limits and null-space stage, and the law's settings
/// (`[law]`: gain schedule, offset-free action, planned rates; [`law_settings`]).
pub fn controller_settings<T: CoreFloat>(
    scenario: &Scenario,
) -> Result<ControllerSettings<T>, SimError> {
    let g = &scenario.gains;
    let gains = Gains::diagonal(g.k_x.map(to_core), g.k_r.map(to_core), g.k_xi.map(to_core))
        .map_err(config_error)?;
    let relaxation = Relaxation::new(to_core(scenario.relaxation)).map_err(config_error)?;
    let rate_limits = scenario
        .controller_rate_limits
        .map(|[x, y]| RateLimits::new(to_core(x), to_core(y)))
        .transpose()
        .map_err(config_error)?;
    let (gain_schedule, offset_free, attitude_rate) = law_settings(&scenario.law)?;
    Ok(ControllerSettings {
        gains,
        relaxation,
        gravity: to_core(scenario.physics.gravity),
        period: to_core(scenario.controller_period),
        rate_limits,
        null_space: scenario
            .null_space
            .as_ref()
            .map(|n| n.stage::<T>())
            .transpose()?,
        gain_schedule,
        offset_free,
        attitude_rate,
        fault_detection: scenario
            .fault_detection
            .as_ref()
            .map(fault_detection)
            .transpose()?,
    })
}

/// The core's fault detection of a scenario's `[fault_detection]` in `T`.
pub fn fault_detection<T: CoreFloat>(
    config: &FaultDetectionConfig,
) -> Result<FaultDetection<T>, SimError> {
    let response = match config.response {
        FaultResponseConfig::Report => FaultResponse::Report,
        FaultResponseConfig::Mask => FaultResponse::Mask,
    };
    FaultDetection::new(
        to_core(config.model_error),
        to_core(config.threshold),
        config.persistence,
        response,
    )
    .map_err(config_error)
}

/// The core's settings of the scenario's `[law]` in `T`: the gain schedule, the offset-free
/// action and the planned-rate filter. `law = "paper"` gives `AsGiven`, `None`, `None`: the
/// paper's cycle bit for bit.
#[allow(clippy::type_complexity)]
pub fn law_settings<T: CoreFloat>(
    law: &LawConfig,
) -> Result<
    (
        GainSchedule<T>,
        Option<OffsetFree<T>>,
        Option<AttitudeRateFilter<T>>,
    ),
    SimError,
> {
    let gain_schedule = match &law.gains {
        GainScheduleConfig::Paper => GainSchedule::AsGiven,
        GainScheduleConfig::TeamScaled => GainSchedule::TeamScaled,
        GainScheduleConfig::Natural(n) => GainSchedule::Natural(
            NaturalGains::new(
                n.position_frequency.map(to_core),
                n.position_damping.map(to_core),
                n.attitude_frequency.map(to_core),
                n.attitude_damping.map(to_core),
            )
            .map_err(config_error)?,
        ),
    };
    let offset_free = match law.offset_free {
        OffsetFreeConfig::Off => None,
        OffsetFreeConfig::Observer {
            force_bandwidth,
            torque_bandwidth,
            max_torque,
        } => Some(OffsetFree::Observer(
            DisturbanceObserver::new(
                to_core(force_bandwidth),
                to_core(torque_bandwidth),
                to_core(max_torque),
            )
            .map_err(config_error)?,
        )),
        OffsetFreeConfig::Integral {
            k_x,
            k_r,
            max_torque,
        } => Some(OffsetFree::Integral(
            IntegralAction::new(k_x.map(to_core), k_r.map(to_core), to_core(max_torque))
                .map_err(config_error)?,
        )),
    };
    let attitude_rate = match law.attitude_rate {
        AttitudeRateConfig::Off => None,
        AttitudeRateConfig::Filter {
            bandwidth,
            max_rate,
        } => Some(
            AttitudeRateFilter::new(to_core(bandwidth), to_core(max_rate)).map_err(config_error)?,
        ),
    };
    Ok((gain_schedule, offset_free, attitude_rate))
}

/// The allocator named by `scenario.allocator`, in `T`, with the round cap
/// `scenario.allocator_max_rounds`.
pub fn allocator<T: CoreFloat>(
    name: &str,
    max_rounds: Option<u32>,
) -> Result<AnyAllocator<T, MAX_AGENTS>, SimError> {
    let options = AllocatorOptions {
        max_rounds,
        ..Default::default()
    };
    AnyAllocator::from_name(name, &options).map_err(|e| match e {
        ConfigError::UnknownAllocator => invalid(
            "allocator",
            format!(
                "unknown allocator `{name}` (known: {})",
                tvmd_scenario::ALLOCATOR_NAMES.join(", ")
            ),
        ),
        ConfigError::AllocatorUnavailable { .. } => invalid(
            "allocator",
            format!(
                "allocator `{name}` needs tvmd-sim built with the `clarabel` feature \
                 (cargo build --features clarabel)"
            ),
        ),
        e => config_error(e),
    })
}

/// `atan(c_y(1, s))`: the planned roll at which the planner saturates in hover for the
/// scenario's team, limits and relaxation `s` (a reproduction target, see `docs/method.md`),
/// computed in f64 whatever the scenario's precision.
pub fn hover_roll_limit(scenario: &Scenario, s: f64) -> Result<f64, SimError> {
    let team = team_config::<f64>(scenario)?;
    let afs = team.afs(&FailureMask::none()).map_err(config_error)?;
    let s = Relaxation::new(s).map_err(config_error)?;
    Ok(afs.semi_axes(1.0, s).c_y.atan())
}

/// The f32 controller's configuration of a scenario as the words an f32 target builds it from
/// ([`tvmd_wire::CoreConfig`]): every value rounded exactly as [`team_config`],
/// [`controller_settings`] and [`allocator`] round it. Errors name the scenario field, as
/// [`super::TvmdController::from_scenario`]'s do. The law (`[law]`) crosses as
/// [`tvmd_wire::LawWords`] of the f32 settings, with the fault detection and the allocator's
/// round cap: every setting the f32 controller flies with.
pub fn wire_config(scenario: &Scenario) -> Result<tvmd_wire::CoreConfig, SimError> {
    use tvmd_wire::{CoreConfig, LawWords, AGENTS, ALLOCATOR_NAME_BYTES};
    // Refused rather than flown without it: the target's firmware is built without the stage
    // (tvmd-core without its `null-space` feature, as the C interface).
    if scenario.null_space.is_some() {
        return Err(invalid(
            "null_space",
            "the null-space stage is not built into the target's firmware: fly it in process",
        ));
    }
    team_config::<f32>(scenario)?;
    let settings = controller_settings::<f32>(scenario)?;
    allocator::<f32>(&scenario.allocator, scenario.allocator_max_rounds)?;
    let body = scenario.team_body()?;
    let mut agents = [([0.0f32; 3], 0, 0.0f32); AGENTS];
    for (slot, a) in agents.iter_mut().zip(&body.agents) {
        let p = vector_to_core::<f32>(&a.position_vector());
        *slot = ([p.x, p.y, p.z], a.quarter_turns, to_core(a.mass));
    }
    let name = scenario.allocator.as_bytes();
    let mut allocator = [0u8; ALLOCATOR_NAME_BYTES];
    allocator
        .get_mut(..name.len())
        .ok_or_else(|| invalid("allocator", "name longer than 32 bytes"))?
        .copy_from_slice(name);
    let inertia = matrix_to_core::<f32>(&from_rows(&body.navigator_inertia));
    let g = &scenario.gains;
    Ok(CoreConfig {
        n: body.len(),
        agents,
        limits: [
            to_core(scenario.limits.sigma_x),
            to_core(scenario.limits.sigma_y),
            to_core(scenario.max_thrust()?),
        ],
        navigator: (
            to_core(body.navigator_mass),
            core::array::from_fn(|k| inertia[(k / 3, k % 3)]),
        ),
        gains: (g.k_x.map(to_core), g.k_r.map(to_core), g.k_xi.map(to_core)),
        relaxation: to_core(scenario.relaxation),
        gravity: to_core(scenario.physics.gravity),
        period: to_core(scenario.controller_period),
        rate_limits: scenario.controller_rate_limits.map(|r| r.map(to_core)),
        allocator,
        law: LawWords::of(&settings),
        fault_detection: settings.fault_detection,
        max_rounds: scenario.allocator_max_rounds,
    })
}
