//! The core's configuration of a scenario, in the controller's float type `T`: team
//! ([`team_config`], at the controller's agent capacity `N`), settings ([`controller_settings`],
//! with the law's [`law_settings`] and the [`fault_detection`]) and allocator ([`allocator`]),
//! with the core's configuration errors mapped to the scenario field they refer to.

use tvmd_core::error::{ConfigError, ConfigField};
use tvmd_core::{
    AgentLimits, AgentSpec, AllocatorOptions, AnyAllocator, AttitudeRateFilter, ControllerSettings,
    DisturbanceObserver, FaultDetection, FaultResponse, GainSchedule, Gains, IntegralAction,
    NaturalGains, Navigator, OffsetFree, RateLimits, Relaxation, RoundCap, TeamConfig,
};
use tvmd_plant::math::from_rows;

use crate::core_float::{matrix_to_core, to_core, vector_to_core, CoreFloat};
use crate::error::invalid;
use crate::{
    AttitudeRateConfig, FaultDetectionConfig, FaultResponseConfig, GainScheduleConfig, LawConfig,
    OffsetFreeConfig, ReportCheckConfig, Scenario, ScenarioError,
};

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
        Some(
            ConfigField::ReportTolerance
            | ConfigField::ReportServoRate
            | ConfigField::ReportLinkTimeout
            | ConfigField::ReportPersistence,
        ) => "fault_detection.report_check",
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

/// A core configuration error as the scenario field it refers to.
pub fn config_error(e: ConfigError) -> ScenarioError {
    invalid(config_field(&e), format!("rejected by the controller: {e}"))
}

/// The core's team configuration of a scenario in `T`: agents in the scenario's order, with
/// their quarter turns and masses, the navigator, and the limits (`sigma_x`, `sigma_y`,
/// `sigma_Tf`).
pub fn team_config<T: CoreFloat, const N: usize>(
    scenario: &Scenario,
) -> Result<TeamConfig<T, N>, ScenarioError> {
    let body = scenario.team_body()?;
    if body.len() > N {
        return Err(invalid(
            "team.agents",
            format!(
                "{} agents exceed the controller's capacity of {N}",
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
) -> Result<ControllerSettings<T>, ScenarioError> {
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

/// The core's fault detection of a scenario's `[fault_detection]` in `T`, with its report
/// check (`[fault_detection.report_check]`; a bad value names its field, also without the
/// scenario's validation, as from Python).
pub fn fault_detection<T: CoreFloat>(
    config: &FaultDetectionConfig,
) -> Result<FaultDetection<T>, ScenarioError> {
    let response = match config.response {
        FaultResponseConfig::Report => FaultResponse::Report,
        FaultResponseConfig::Mask => FaultResponse::Mask,
    };
    let detection = FaultDetection::new(
        to_core(config.model_error),
        to_core(config.threshold),
        config.persistence,
        response,
    )
    .map_err(config_error)?;
    // The recommended check as the core states it (its own constants, bit for bit).
    if config.report_check == ReportCheckConfig::default() {
        return Ok(detection);
    }
    Ok(detection.with_report_check(config.report_check.to_core()?))
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
    ScenarioError,
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
pub fn allocator<T: CoreFloat, const N: usize>(
    name: &str,
    max_rounds: Option<RoundCap>,
) -> Result<AnyAllocator<T, N>, ScenarioError> {
    let options = AllocatorOptions {
        max_rounds,
        ..Default::default()
    };
    AnyAllocator::from_name(name, &options).map_err(|e| match e {
        ConfigError::UnknownAllocator => invalid(
            "allocator",
            format!(
                "unknown allocator `{name}` (known: {})",
                crate::ALLOCATOR_NAMES.join(", ")
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
