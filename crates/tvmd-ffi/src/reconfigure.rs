//! Changing a running controller from C without losing it: `tvmd_validate_config` (a
//! configuration checked, nothing created), `tvmd_reconfigure` (all or nothing: the running
//! controller keeps flying unchanged when the new configuration is refused), the cheap setters
//! `tvmd_set_gains`, `tvmd_set_relaxation`, `tvmd_set_rate_limits`, and `tvmd_seed_commands`
//! for a mode switch.

use tvmd_core::{AgentCommand, AnyAllocator, RateLimits, Relaxation};

use core::mem::MaybeUninit;

use crate::actuator::admissible;
use crate::blueprint::Blueprint;
use crate::handle::{checked_size, inner_mut, FfiController, TvmdController};
use crate::status::*;
use crate::types::*;
use crate::TVMD_MAX_AGENTS;

/// Checks `config` as `tvmd_create` would (every field, the team's rank, the law), without
/// creating anything: `TVMD_OK` or the status `tvmd_create` would return. Builds the
/// controller on the stack to check it, so it costs what `tvmd_create` costs: call it before
/// flight or from a task with that stack, not from the control loop.
///
/// # Safety
/// `config` is null or points to a `TvmdConfig`.
#[no_mangle]
pub unsafe extern "C" fn tvmd_validate_config(config: *const TvmdConfig) -> TvmdStatus {
    let Some(config) = config.as_ref() else {
        return TVMD_ERR_NULL_POINTER;
    };
    if let Err(status) = checked_size::<TvmdConfig>(config.size) {
        return status;
    }
    match Blueprint::write_in(&mut MaybeUninit::uninit(), config) {
        Ok(b) => match FfiController::check(&b.team, &b.settings) {
            Ok(()) => TVMD_OK,
            Err(e) => config_status(&e),
        },
        Err(e) => e.status(),
    }
}

/// Replaces the running controller's configuration, all or nothing: the new controller is
/// built and given the running one's failure mask, landed flag, held commands (agent by agent,
/// where admissible for the new configuration; otherwise idle) and offset-free estimate (when
/// both run the same kind of action); only then does it replace the running one. On any error
/// the running controller is untouched and steps exactly as before. As `tvmd_validate_config`,
/// it costs what `tvmd_create` costs.
///
/// # Safety
/// `handle` as for `tvmd_step`; `config` is null or points to a `TvmdConfig`.
#[no_mangle]
pub unsafe extern "C" fn tvmd_reconfigure(
    handle: *mut TvmdController,
    config: *const TvmdConfig,
) -> TvmdStatus {
    let Some(config) = config.as_ref() else {
        return TVMD_ERR_NULL_POINTER;
    };
    if let Err(status) = checked_size::<TvmdConfig>(config.size) {
        return status;
    }
    let inner = match inner_mut(handle) {
        Ok(inner) => inner,
        Err(status) => return status,
    };
    let mut next = MaybeUninit::uninit();
    let next = match Blueprint::write_in(&mut next, config) {
        Ok(next) => next,
        Err(e) => return e.status(),
    };
    match inner
        .controller
        .reconfigure(&next.team, &next.settings, || {
            AnyAllocator::from_choice(next.allocator.clone())
        }) {
        Ok(()) => TVMD_OK,
        Err(e) => config_status(&e),
    }
}

/// New gains of eq. (12) for the running controller (resolved by its law's gain schedule).
/// A gain that is not symmetric positive definite is refused and nothing changes.
///
/// # Safety
/// `handle` as for `tvmd_step`; `gains` is null or points to a `TvmdGains`.
#[no_mangle]
pub unsafe extern "C" fn tvmd_set_gains(
    handle: *mut TvmdController,
    gains: *const TvmdGains,
) -> TvmdStatus {
    let Some(gains) = gains.as_ref() else {
        return TVMD_ERR_NULL_POINTER;
    };
    let inner = match inner_mut(handle) {
        Ok(inner) => inner,
        Err(status) => return status,
    };
    match gains.to_core().and_then(|g| inner.controller.set_gains(g)) {
        Ok(()) => TVMD_OK,
        Err(e) => config_status(&e),
    }
}

/// A new AFS relaxation `s` in `(0, 1]` for the planner, from the next period on. Anything
/// else is refused (`TVMD_ERR_CONFIG_RELAXATION`) and nothing changes.
///
/// # Safety
/// `handle` as for `tvmd_step`.
#[no_mangle]
pub unsafe extern "C" fn tvmd_set_relaxation(
    handle: *mut TvmdController,
    relaxation: f32,
) -> TvmdStatus {
    let inner = match inner_mut(handle) {
        Ok(inner) => inner,
        Err(status) => return status,
    };
    match Relaxation::new(relaxation) {
        Ok(s) => {
            inner.controller.set_relaxation(s);
            TVMD_OK
        }
        Err(e) => config_status(&e),
    }
}

/// Gimbal rate limits `[eta_x, eta_y]` (rad/s, positive) from the next period on when
/// `enabled` is non-zero (`limits` then points to 2 floats), none when it is zero (`limits`
/// may be null). A bad limit is refused and nothing changes.
///
/// # Safety
/// `handle` as for `tvmd_step`; `limits` is null or points to 2 floats.
#[no_mangle]
pub unsafe extern "C" fn tvmd_set_rate_limits(
    handle: *mut TvmdController,
    enabled: u32,
    limits: *const f32,
) -> TvmdStatus {
    let inner = match inner_mut(handle) {
        Ok(inner) => inner,
        Err(status) => return status,
    };
    if enabled == 0 {
        inner.controller.set_rate_limits(None);
        return TVMD_OK;
    }
    let Some([x, y]) = limits.cast::<[f32; 2]>().as_ref() else {
        return TVMD_ERR_NULL_POINTER;
    };
    match RateLimits::new(*x, *y) {
        Ok(r) => {
            inner.controller.set_rate_limits(Some(r));
            TVMD_OK
        }
        Err(e) => config_status(&e),
    }
}

/// The commands the vehicle flies now (at a switch from another controller) become the held
/// ones: what a refused period repeats and where the rate limits start. `commands` holds
/// `count` entries, `count` = the team's agent count; each working agent's command must lie in
/// its admissible set (gimbal and thrust limits, the rotor speed within `[0, sigma_omega]`:
/// what `tvmd_actuator_outputs` outputs), a failed agent's must be all zero. A bad
/// command is refused (`TVMD_ERR_INPUT_NON_FINITE`, `TVMD_ERR_INPUT_OUT_OF_RANGE`; a wrong
/// `count`: `TVMD_ERR_SIZE`) and the held commands stay.
///
/// # Safety
/// `handle` as for `tvmd_step`; `commands` is null or points to `count` `TvmdAgentCommand`s.
#[no_mangle]
pub unsafe extern "C" fn tvmd_seed_commands(
    handle: *mut TvmdController,
    commands: *const TvmdAgentCommand,
    count: u32,
) -> TvmdStatus {
    if commands.is_null() {
        return TVMD_ERR_NULL_POINTER;
    }
    let inner = match inner_mut(handle) {
        Ok(inner) => inner,
        Err(status) => return status,
    };
    let n = inner.controller.team().len();
    if usize::try_from(count).ok() != Some(n) {
        return TVMD_ERR_SIZE;
    }
    let given = core::slice::from_raw_parts(commands, n);
    // What the actuator map would refuse to output is refused here (a rotor speed beyond the
    // largest, which the core's gimbal and thrust check does not read): a held command must
    // stay publishable. Non-finite values are the core's refusal.
    let limits = inner.controller.team().limits();
    let finite = |c: &TvmdAgentCommand| {
        [c.eta_x, c.eta_y, c.thrust, c.omega]
            .iter()
            .all(|x| x.is_finite())
    };
    if given.iter().any(|c| finite(c) && !admissible(limits, c)) {
        return TVMD_ERR_INPUT_OUT_OF_RANGE;
    }
    let mut seeded = [AgentCommand::<f32>::idle(); TVMD_MAX_AGENTS];
    for (slot, c) in seeded.iter_mut().zip(given) {
        *slot = AgentCommand {
            eta_x: c.eta_x,
            eta_y: c.eta_y,
            thrust: c.thrust,
            omega: c.omega,
        };
    }
    match inner.controller.seed_commands(&seeded) {
        Ok(()) => TVMD_OK,
        Err(e) => input_status(&e),
    }
}
