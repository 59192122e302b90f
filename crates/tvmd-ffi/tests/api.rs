//! The C entry points called from Rust: creation into caller storage, a cycle, held commands,
//! failure masks and the actuator map (the C program in `tests/c` covers the same from C).

use std::mem::size_of;

use tvmd_ffi::actuator::*;
use tvmd_ffi::handle::*;
use tvmd_ffi::status::*;
use tvmd_ffi::types::*;

fn created() -> Box<TvmdController> {
    created_with(TVMD_ALLOCATOR_REDISTRIBUTED_PSEUDO_INVERSE)
}

/// The paper's controller with one of the `TVMD_ALLOCATOR_*`.
fn created_with(allocator: u32) -> Box<TvmdController> {
    let mut storage = Box::new(TvmdController {
        opaque: [0; TVMD_CONTROLLER_WORDS],
    });
    let mut config: TvmdConfig = unsafe { std::mem::zeroed() };
    config.size = size_of::<TvmdConfig>() as u32;
    // SAFETY: valid pointers to live values.
    unsafe {
        assert_eq!(tvmd_config_paper(&mut config), TVMD_OK);
        // The default allocator, as `AnyAllocator::default()` in Rust.
        assert_eq!(
            config.allocator,
            TVMD_ALLOCATOR_EXACT_BOUNDARY_REDISTRIBUTION
        );
        config.allocator = allocator;
        assert_eq!(
            tvmd_create(&mut *storage, size_of::<TvmdController>(), &config),
            TVMD_OK,
            "allocator {allocator}"
        );
    }
    storage
}

fn identity() -> [f32; 9] {
    [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]
}

fn step(handle: &mut TvmdController, x: f32) -> (TvmdStatus, TvmdOutput) {
    let state = TvmdState {
        size: size_of::<TvmdState>() as u32,
        position: [x, 0.0, 1.5],
        attitude: identity(),
        ..TvmdState::default()
    };
    let reference = TvmdReference {
        size: size_of::<TvmdReference>() as u32,
        position: [0.0, 0.0, 1.5],
        attitude: identity(),
        ..TvmdReference::default()
    };
    let mut out: TvmdOutput = unsafe { std::mem::zeroed() };
    out.size = size_of::<TvmdOutput>() as u32;
    // SAFETY: valid pointers to live values.
    let status = unsafe { tvmd_step(handle, &state, &reference, &mut out) };
    (status, out)
}

#[test]
fn a_refused_cycle_holds_the_previous_commands() {
    let mut handle = created();
    let (status, good) = step(&mut handle, 0.2);
    assert_eq!(status, TVMD_OK);
    assert!(good.commands[..4].iter().all(|c| c.thrust > 0.0));
    let (status, held) = step(&mut handle, f32::NAN);
    assert_eq!((status, held.status), (TVMD_ERR_INPUT_NON_FINITE, status));
    assert_eq!(held.commands, good.commands);
    assert!(held.e_f.is_nan() && held.planner_theta.is_nan());
    // SAFETY: a created handle.
    assert_eq!(unsafe { tvmd_reset(&mut *handle) }, TVMD_OK);
    let (_, idle) = step(&mut handle, f32::INFINITY);
    assert!(idle
        .commands
        .iter()
        .all(|c| *c == TvmdAgentCommand::default()));
}

#[test]
fn actuator_channels_follow_the_map_and_round_trip() {
    let mut handle = created();
    let mut hover = TvmdHover {
        size: size_of::<TvmdHover>() as u32,
        ..TvmdHover::default()
    };
    // SAFETY: valid pointers to live values.
    unsafe {
        assert_eq!(tvmd_set_failures(&mut *handle, 1 << 1, &mut hover), TVMD_OK);
    }
    let (status, out) = step(&mut handle, 0.1);
    assert_eq!(status, TVMD_OK);
    let mut map: TvmdActuatorMap = unsafe { std::mem::zeroed() };
    map.size = size_of::<TvmdActuatorMap>() as u32;
    let mut act: TvmdActuatorOutputs = unsafe { std::mem::zeroed() };
    act.size = size_of::<TvmdActuatorOutputs>() as u32;
    let mut back = [TvmdAgentCommand::default(); 16];
    // SAFETY: valid pointers to live values; 16 commands.
    unsafe {
        assert_eq!(tvmd_actuator_map_default(&*handle, &mut map), TVMD_OK);
        // Agent i on motors [15 - i, 8 + i], servos [i, 4 + i], reversed eta_y.
        for (i, a) in map.agents.iter_mut().take(4).enumerate() {
            a.motor = [15 - i as u32, 8 + i as u32];
            a.servo = [i as u32, 4 + i as u32];
            a.servo_direction = [1.0, -1.0];
        }
        assert_eq!(tvmd_actuator_map_validate(&*handle, &map), TVMD_OK);
        let outputs = tvmd_actuator_outputs(&*handle, &map, out.commands.as_ptr(), 16, &mut act);
        assert_eq!(outputs, TVMD_OK);
        let commands = tvmd_actuator_commands(&*handle, &map, &act, back.as_mut_ptr(), 16);
        assert_eq!(commands, TVMD_OK);
    }
    let (sigma_x, sigma_y) = (std::f32::consts::PI / 6.0, std::f32::consts::FRAC_PI_4);
    for (i, (c, b)) in out.commands.iter().zip(&back).enumerate().take(4) {
        let (m0, m1) = (act.motors[15 - i], act.motors[8 + i]);
        let (sx, sy) = (act.servos[i], act.servos[4 + i]);
        assert_eq!(m0, m1, "agent {i}: one speed for the coaxial pair");
        if i == 1 {
            assert_eq!((m0, sx, sy), (0.0, 0.0, 0.0), "a failed agent is safe");
            assert_eq!(*b, TvmdAgentCommand::default());
            continue;
        }
        assert!(
            (m0 - c.omega).abs() <= 1e-6,
            "agent {i}: motor = omega / sigma_omega"
        );
        assert!((sx - c.eta_x / sigma_x).abs() <= 1e-6);
        assert!((sy + c.eta_y / sigma_y).abs() <= 1e-6);
        assert!((b.eta_x - c.eta_x).abs() <= 1e-6);
        assert!((b.eta_y - c.eta_y).abs() <= 1e-6);
        assert!((b.thrust - c.thrust).abs() <= 1e-5 * c.thrust.max(1.0));
    }
    for unused in [0, 1, 2, 3, 4, 5, 6, 7] {
        assert!(act.motors[unused].is_nan());
    }
    for unused in 8..16 {
        assert!(act.servos[unused].is_nan());
    }
    map.agents[2].servo[1] = map.agents[0].servo[0];
    // SAFETY: as above.
    let duplicate = unsafe { tvmd_actuator_map_validate(&*handle, &map) };
    assert_eq!(duplicate, TVMD_ERR_MAP_DUPLICATE_CHANNEL);
}

#[test]
fn every_allocator_constant_creates_a_controller_that_flies() {
    for allocator in [
        TVMD_ALLOCATOR_REDISTRIBUTED_PSEUDO_INVERSE,
        TVMD_ALLOCATOR_PSEUDO_INVERSE,
        TVMD_ALLOCATOR_WEIGHTED_PSEUDO_INVERSE,
        TVMD_ALLOCATOR_EXACT_BOUNDARY_REDISTRIBUTION,
    ] {
        let mut storage = created_with(allocator);
        for x in [0.2, 0.1, 0.0] {
            let (status, out) = step(&mut storage, x);
            assert_eq!(status, TVMD_OK, "allocator {allocator}");
            assert!(
                out.e_f.is_finite() && out.e_f < 1e-3,
                "allocator {allocator}: {}",
                out.e_f
            );
            assert!(out.commands[..4].iter().all(|c| c.thrust > 0.0));
        }
    }
}
