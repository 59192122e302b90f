//! What a `TvmdConfig` describes: the team, the settings and the allocator a controller is built
//! from, each checked. Written in place, part by part (each part by a function of its own), so
//! that creation stays within a small stack: the parts' temporaries follow one another instead
//! of adding up.

use core::mem::MaybeUninit;
use core::ptr::addr_of_mut;

use tvmd_core::allocation::{
    AllocatorChoice, AllocatorOptions, CAPPED_REDISTRIBUTION, EXACT_BOUNDARY_REDISTRIBUTION,
    PSEUDO_INVERSE, REDISTRIBUTED_PSEUDO_INVERSE, WEIGHTED_PSEUDO_INVERSE,
};
use tvmd_core::{
    AgentSpec, ConfigError, ControllerSettings, GainSchedule, Navigator, RateLimits, Relaxation,
    RoundCap, TeamConfig,
};

use crate::status::*;
use crate::types::*;
use crate::TVMD_MAX_AGENTS;

/// The parts a controller is built from; the allocator as a checked choice, made in place
/// when the controller is built (it can be kilobytes).
pub(crate) struct Blueprint {
    pub(crate) team: TeamConfig<f32, TVMD_MAX_AGENTS>,
    pub(crate) settings: ControllerSettings<f32>,
    pub(crate) allocator: AllocatorChoice<f32, TVMD_MAX_AGENTS>,
}

impl Blueprint {
    /// The parts `config` describes, written in `slot`; the first error in the order team,
    /// settings, allocator (the controller's own checks run when it is built,
    /// `Controller::check`). On an error `slot` is left partly written and not initialized.
    pub(crate) fn write_in<'b>(
        slot: &'b mut MaybeUninit<Self>,
        config: &TvmdConfig,
    ) -> Result<&'b mut Self, ConvertError> {
        let this = slot.as_mut_ptr();
        // SAFETY: `this` is valid for writes and aligned; each field is written once before
        // `assume_init_mut`, and nothing reads a field before it is written.
        unsafe {
            team(config, addr_of_mut!((*this).team))?;
            settings(config, addr_of_mut!((*this).settings))?;
            allocator(config, addr_of_mut!((*this).allocator))?;
            Ok(slot.assume_init_mut())
        }
    }
}

/// The agents' count, or `TooManyAgents`.
fn count(config: &TvmdConfig) -> Result<usize, ConvertError> {
    let count = usize::try_from(config.agent_count).unwrap_or(usize::MAX);
    if count > TVMD_MAX_AGENTS {
        return Err(ConfigError::TooManyAgents {
            count,
            capacity: TVMD_MAX_AGENTS,
        }
        .into());
    }
    Ok(count)
}

// Each part is written at `at` by a function of its own (not inlined), so its temporaries sit
// on its own frame, not on the caller's.
//
// # Safety (each part)
// `at` is valid for writes and aligned.

#[inline(never)]
unsafe fn team(
    config: &TvmdConfig,
    at: *mut TeamConfig<f32, TVMD_MAX_AGENTS>,
) -> Result<(), ConvertError> {
    let count = count(config)?;
    let mut specs = [AgentSpec::new(vector(&[0.0; 3]), 0, 0.0); TVMD_MAX_AGENTS];
    for (spec, agent) in specs.iter_mut().zip(&config.agents).take(count) {
        *spec = agent.to_core();
    }
    let navigator = Navigator {
        mass: config.navigator_mass,
        inertia: matrix(&config.navigator_inertia),
    };
    let limits = config.limits.to_core()?;
    at.write(TeamConfig::new(
        specs.get(..count).unwrap_or(&[]),
        limits,
        navigator,
    )?);
    Ok(())
}

#[inline(never)]
unsafe fn settings(
    config: &TvmdConfig,
    at: *mut ControllerSettings<f32>,
) -> Result<(), ConvertError> {
    let rate_limits = if config.rate_limited != 0 {
        let [x, y] = config.rate_limits;
        Some(RateLimits::new(x, y)?)
    } else {
        None
    };
    let mut settings = ControllerSettings {
        gains: config.gains.to_core()?,
        relaxation: Relaxation::new(config.relaxation)?,
        gravity: config.gravity,
        period: config.period,
        rate_limits,
        null_space: None,
        gain_schedule: GainSchedule::AsGiven,
        offset_free: None,
        attitude_rate: None,
        fault_detection: config.fault.to_core()?,
    };
    config.law.apply(&mut settings)?;
    at.write(settings);
    Ok(())
}

#[inline(never)]
unsafe fn allocator(
    config: &TvmdConfig,
    at: *mut AllocatorChoice<f32, TVMD_MAX_AGENTS>,
) -> Result<(), ConvertError> {
    let name = match config.allocator {
        TVMD_ALLOCATOR_REDISTRIBUTED_PSEUDO_INVERSE => REDISTRIBUTED_PSEUDO_INVERSE,
        TVMD_ALLOCATOR_PSEUDO_INVERSE => PSEUDO_INVERSE,
        TVMD_ALLOCATOR_WEIGHTED_PSEUDO_INVERSE => WEIGHTED_PSEUDO_INVERSE,
        TVMD_ALLOCATOR_EXACT_BOUNDARY_REDISTRIBUTION => EXACT_BOUNDARY_REDISTRIBUTION,
        TVMD_ALLOCATOR_CAPPED_REDISTRIBUTION => CAPPED_REDISTRIBUTION,
        _ => "",
    };
    let mut options = AllocatorOptions::default();
    if name == WEIGHTED_PSEUDO_INVERSE {
        // Slots beyond the team are unused; the core wants a valid weight in each.
        let mut weights = [1.0; TVMD_MAX_AGENTS];
        let count = count(config)?;
        for (w, given) in weights.iter_mut().zip(&config.agent_weights).take(count) {
            *w = *given;
        }
        options.agent_weights = Some(weights);
    }
    options.max_rounds = match config.allocator_round_cap {
        TVMD_ROUND_CAP_DEFAULT => None,
        TVMD_ROUND_CAP_ROUNDS => Some(RoundCap::Rounds(config.allocator_max_rounds)),
        TVMD_ROUND_CAP_UNCAPPED => Some(RoundCap::Uncapped),
        _ => return Err(ConvertError::EnumValue),
    };
    at.write(AllocatorChoice::new(name, &options)?);
    Ok(())
}
