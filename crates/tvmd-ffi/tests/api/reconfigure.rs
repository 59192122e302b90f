//! Reconfiguration from C: validation, an all-or-nothing reconfigure (a refused one leaves the
//! controller stepping exactly as before), the cheap setters, the command seed, and the guards
//! around the storage.

use std::mem::size_of;

use tvmd_ffi::actuator::*;
use tvmd_ffi::config::*;
use tvmd_ffi::handle::*;
use tvmd_ffi::reconfigure::*;
use tvmd_ffi::status::*;
use tvmd_ffi::types::*;

use super::{created_with, step};

fn paper_config() -> TvmdConfig {
    let mut config: TvmdConfig = unsafe { std::mem::zeroed() };
    config.size = size_of::<TvmdConfig>() as u32;
    // SAFETY: a valid pointer to a live value.
    assert_eq!(unsafe { tvmd_config_paper(&mut config) }, TVMD_OK);
    config
}

#[test]
fn a_refused_reconfiguration_leaves_the_controller_stepping_as_before() {
    let mut changed = created_with(TVMD_ALLOCATOR_EXACT_BOUNDARY_REDISTRIBUTION);
    let mut twin = created_with(TVMD_ALLOCATOR_EXACT_BOUNDARY_REDISTRIBUTION);
    for x in [0.3, 0.2] {
        assert_eq!(
            step(&mut changed, x).1.commands,
            step(&mut twin, x).1.commands
        );
    }
    let mut bad = paper_config();
    bad.relaxation = 1.5;
    // SAFETY: valid pointers to live values.
    unsafe {
        assert_eq!(tvmd_validate_config(&bad), TVMD_ERR_CONFIG_RELAXATION);
        assert_eq!(
            tvmd_reconfigure(&mut *changed, &bad),
            TVMD_ERR_CONFIG_RELAXATION
        );
        bad = paper_config();
        bad.agents[0].mass = -1.0;
        assert_eq!(tvmd_reconfigure(&mut *changed, &bad), TVMD_ERR_CONFIG_MASS);
        assert_eq!(
            tvmd_reconfigure(&mut *changed, std::ptr::null()),
            TVMD_ERR_NULL_POINTER
        );
        assert_eq!(tvmd_validate_config(&paper_config()), TVMD_OK);
    }
    for x in [0.15, 0.1, f32::NAN, 0.05] {
        let (a, b) = (step(&mut changed, x), step(&mut twin, x));
        assert_eq!(a.0, b.0);
        assert_eq!(a.1.commands, b.1.commands);
        assert_eq!(
            a.1.planned_attitude.map(f32::to_bits),
            b.1.planned_attitude.map(f32::to_bits)
        );
    }
}

#[test]
fn an_accepted_reconfiguration_keeps_the_mask_and_the_held_commands() {
    let mut handle = created_with(TVMD_ALLOCATOR_EXACT_BOUNDARY_REDISTRIBUTION);
    let mut hover = TvmdHover {
        size: size_of::<TvmdHover>() as u32,
        ..TvmdHover::default()
    };
    // SAFETY: valid pointers to live values.
    unsafe {
        assert_eq!(tvmd_set_failures(&mut *handle, 1 << 3, &mut hover), TVMD_OK);
    }
    let (_, before) = step(&mut handle, 0.1);
    let mut config = paper_config();
    config.relaxation = 0.8;
    // SAFETY: valid pointers to live values.
    unsafe {
        assert_eq!(tvmd_reconfigure(&mut *handle, &config), TVMD_OK);
        let mut now = TvmdHover {
            size: size_of::<TvmdHover>() as u32,
            ..TvmdHover::default()
        };
        assert_eq!(tvmd_hover_capability(&*handle, &mut now), TVMD_OK);
        assert_eq!(now, hover, "the failure mask is kept");
    }
    let (status, held) = step(&mut handle, f32::NAN);
    assert_eq!(status, TVMD_ERR_INPUT_NON_FINITE);
    assert_eq!(held.commands, before.commands, "the held commands are kept");
}

#[test]
fn setters_and_the_seed_refuse_bad_values() {
    let mut handle = created_with(TVMD_ALLOCATOR_EXACT_BOUNDARY_REDISTRIBUTION);
    let hover = TvmdAgentCommand {
        eta_x: 0.0,
        eta_y: 0.0,
        thrust: 6.9,
        omega: 0.7,
    };
    // SAFETY: valid pointers to live values, or null where the test says so.
    unsafe {
        assert_eq!(tvmd_set_relaxation(&mut *handle, 1.0), TVMD_OK);
        assert_eq!(
            tvmd_set_relaxation(&mut *handle, f32::NAN),
            TVMD_ERR_CONFIG_NON_FINITE
        );
        assert_eq!(
            tvmd_set_relaxation(&mut *handle, 0.0),
            TVMD_ERR_CONFIG_RELAXATION
        );
        let limits = [2.0f32, 2.0];
        assert_eq!(
            tvmd_set_rate_limits(&mut *handle, 1, limits.as_ptr()),
            TVMD_OK
        );
        assert_eq!(
            tvmd_set_rate_limits(&mut *handle, 1, std::ptr::null()),
            TVMD_ERR_NULL_POINTER
        );
        assert_eq!(
            tvmd_set_rate_limits(&mut *handle, 0, std::ptr::null()),
            TVMD_OK
        );
        let bad = [-1.0f32, 2.0];
        assert_ne!(tvmd_set_rate_limits(&mut *handle, 1, bad.as_ptr()), TVMD_OK);
        let mut gains = paper_config().gains;
        assert_eq!(tvmd_set_gains(&mut *handle, &gains), TVMD_OK);
        gains.k_x[0] = -1.0;
        assert_eq!(
            tvmd_set_gains(&mut *handle, &gains),
            TVMD_ERR_CONFIG_NOT_SPD
        );
        assert_eq!(
            tvmd_set_gains(&mut *handle, std::ptr::null()),
            TVMD_ERR_NULL_POINTER
        );

        let seed = [hover; 4];
        assert_eq!(
            tvmd_seed_commands(&mut *handle, seed.as_ptr(), 3),
            TVMD_ERR_SIZE
        );
        let mut tilted = seed;
        tilted[2].eta_y = 1.5;
        assert_eq!(
            tvmd_seed_commands(&mut *handle, tilted.as_ptr(), 4),
            TVMD_ERR_INPUT_OUT_OF_RANGE
        );
        assert_eq!(tvmd_seed_commands(&mut *handle, seed.as_ptr(), 4), TVMD_OK);
    }
    let (status, held) = step(&mut handle, f32::NAN);
    assert_eq!(status, TVMD_ERR_INPUT_NON_FINITE);
    assert_eq!(
        held.commands[..4],
        [hover; 4],
        "a refused period holds the seed"
    );
}

#[test]
fn a_seed_the_actuator_map_would_refuse_is_refused() {
    let mut handle = created_with(TVMD_ALLOCATOR_EXACT_BOUNDARY_REDISTRIBUTION);
    let hover = TvmdAgentCommand {
        eta_x: 0.0,
        eta_y: 0.0,
        thrust: 6.9,
        omega: 0.7,
    };
    let mut map: TvmdActuatorMap = unsafe { std::mem::zeroed() };
    map.size = size_of::<TvmdActuatorMap>() as u32;
    let mut act: TvmdActuatorOutputs = unsafe { std::mem::zeroed() };
    act.size = size_of::<TvmdActuatorOutputs>() as u32;
    // SAFETY: valid pointers to live values.
    unsafe {
        assert_eq!(tvmd_actuator_map_default(&*handle, &mut map), TVMD_OK);
        let mut seed = [hover; 4];
        seed[1].omega = 123.0;
        assert_eq!(
            tvmd_seed_commands(&mut *handle, seed.as_ptr(), 4),
            TVMD_ERR_INPUT_OUT_OF_RANGE
        );
        seed[1].omega = -0.1;
        assert_eq!(
            tvmd_seed_commands(&mut *handle, seed.as_ptr(), 4),
            TVMD_ERR_INPUT_OUT_OF_RANGE
        );
        assert_eq!(
            tvmd_seed_commands(&mut *handle, [hover; 4].as_ptr(), 4),
            TVMD_OK
        );
    }
    // The next refused period holds the seed, and the seed is publishable.
    let (status, held) = step(&mut handle, f32::NAN);
    assert_eq!(status, TVMD_ERR_INPUT_NON_FINITE);
    assert_eq!(held.commands[..4], [hover; 4]);
    // SAFETY: valid pointers to live values; 16 commands.
    let published =
        unsafe { tvmd_actuator_outputs(&*handle, &map, held.commands.as_ptr(), 16, &mut act) };
    assert_eq!(published, TVMD_OK);
}

#[test]
fn an_overrun_storage_is_refused() {
    let mut handle = created_with(TVMD_ALLOCATOR_EXACT_BOUNDARY_REDISTRIBUTION);
    // SAFETY: a created handle.
    assert_eq!(unsafe { tvmd_check(&*handle) }, TVMD_OK);
    let last = handle.opaque.len() - 1;
    handle.opaque[last] ^= 1;
    // SAFETY: a handle whose storage a neighbour overwrote.
    assert_eq!(unsafe { tvmd_check(&*handle) }, TVMD_ERR_CORRUPTED);
    let (status, out) = step(&mut handle, 0.1);
    assert_eq!(status, TVMD_ERR_CORRUPTED);
    assert!(out
        .commands
        .iter()
        .all(|c| *c == TvmdAgentCommand::default()));
    handle.opaque[last] ^= 1;
    handle.opaque[0] = 0;
    // SAFETY: as above.
    assert_eq!(unsafe { tvmd_check(&*handle) }, TVMD_ERR_NOT_INITIALIZED);
}
