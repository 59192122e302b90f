//! The configuration entry points: the library's default configuration (the offset-free law)
//! and the paper's ([`crate::handle::tvmd_create`] turns either into a controller).

use tvmd_core::team::presets;
use tvmd_core::ControllerSettings;

use crate::fault::TvmdFaultDetection;
use crate::handle::checked_size;
use crate::law::TvmdLaw;
use crate::status::*;
use crate::types::*;
use crate::TVMD_MAX_AGENTS;

/// Fills `config` with the paper's team and `settings`' numbers; `law` as given.
///
/// # Safety
/// `config` is null or points to a writable `TvmdConfig`.
unsafe fn fill(
    config: *mut TvmdConfig,
    settings: &ControllerSettings<f32>,
    law: TvmdLaw,
) -> TvmdStatus {
    let Some(config) = config.as_mut() else {
        return TVMD_ERR_NULL_POINTER;
    };
    if let Err(status) = checked_size::<TvmdConfig>(config.size) {
        return status;
    }
    let team = match presets::a4_inc::<f32, TVMD_MAX_AGENTS>() {
        Ok(team) => team,
        Err(e) => return config_status(&e),
    };
    let limits = team.limits();
    let mut agents = [TvmdAgent::default(); TVMD_MAX_AGENTS];
    for (slot, agent) in agents.iter_mut().zip(team.agents()) {
        *slot = TvmdAgent {
            position: agent.position.into(),
            quarter_turns: agent.quarter_turns,
            mass: agent.mass,
            inertia: row_major(&agent.inertia),
        };
    }
    *config = TvmdConfig {
        size: config.size,
        agent_count: u32::try_from(team.len()).unwrap_or(0),
        agents,
        navigator_mass: team.navigator().mass,
        navigator_inertia: row_major(&team.navigator().inertia),
        limits: TvmdLimits {
            sigma_x: limits.sigma_x(),
            sigma_y: limits.sigma_y(),
            max_thrust: limits.max_thrust(),
            min_thrust: limits.min_thrust(),
            rotor_model: TVMD_ROTOR_NORMALIZED,
            ..TvmdLimits::default()
        },
        gains: TvmdGains::from_core(&settings.gains),
        relaxation: settings.relaxation.get(),
        gravity: settings.gravity,
        period: settings.period,
        rate_limited: 0,
        rate_limits: [0.0; 2],
        allocator: TVMD_ALLOCATOR_EXACT_BOUNDARY_REDISTRIBUTION,
        agent_weights: [1.0; TVMD_MAX_AGENTS],
        allocator_round_cap: TVMD_ROUND_CAP_DEFAULT,
        allocator_max_rounds: 0,
        fault: TvmdFaultDetection::recommended_off(),
        law,
    };
    TVMD_OK
}

/// Fills `config` with the library's default: the paper's team "A4 inc, 1 navigator" and
/// settings (as `tvmd_config_paper`) flown with the offset-free law (the core's
/// `ControllerSettings::offset_free_law`): natural gains (1.5 rad/s position with damping 1,
/// 6 rad/s attitude with damping 0.6, scaled by the team's mass and inertia), the disturbance observer
/// (10 rad/s force and torque bandwidths, 5 N m torque bound) and the planned attitude's rates
/// (20 rad/s, 5 rad/s bound), with the exact-boundary redistribution's walk capped at
/// `TVMD_DEFAULT_MAX_ROUNDS` rounds per period (`TVMD_ROUND_CAP_DEFAULT`). This law holds its setpoint under model error and unmodelled
/// forces, where the paper's law leaves a steady error. The caller sets `config->size` first.
///
/// # Safety
/// `config` is null or points to a writable `TvmdConfig`.
#[no_mangle]
pub unsafe extern "C" fn tvmd_config_default(config: *mut TvmdConfig) -> TvmdStatus {
    let settings = ControllerSettings::<f32>::offset_free_law();
    fill(config, &settings, TvmdLaw::from_core(&settings))
}

/// Fills `config` with the paper's team "A4 inc, 1 navigator" (four 0.7 kg agents on a
/// square, `psi = [pi/2, pi/2, 0, 0]`), its limits (`sigma_x = pi/6`, `sigma_y = pi/4`,
/// `sigma_Tf = 2 m_i g`, normalized rotor speed), gains, `s = 0.5`, `g = 9.81`, `dt = 0.01` s,
/// no rate limits, the exact-boundary redistribution (the default allocator, as in the Rust
/// and Python interfaces, its walk capped at `TVMD_DEFAULT_MAX_ROUNDS` rounds) and the paper's
/// law: gains as given, no offset-free action, the
/// reference's rates (every `law` mode off; its numbers are those of `tvmd_config_default`, so
/// switching one mode on starts from the library's values). The caller sets `config->size`
/// first.
///
/// # Safety
/// `config` is null or points to a writable `TvmdConfig`.
#[no_mangle]
pub unsafe extern "C" fn tvmd_config_paper(config: *mut TvmdConfig) -> TvmdStatus {
    fill(
        config,
        &ControllerSettings::<f32>::paper(),
        TvmdLaw::paper(),
    )
}
