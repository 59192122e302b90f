//! The C entry points called from Rust: creation into caller storage, a cycle, held commands,
//! failure masks, the actuator map, the default (offset-free) law against the paper's, the
//! landed hold, and the stages (module `stages`; the C program in `tests/c` covers the same
//! from C).

mod reconfigure;
mod stages;

use std::mem::size_of;

use tvmd_core::nalgebra::Vector3;
use tvmd_core::team::presets;
use tvmd_core::{AnyAllocator, Controller, ControllerSettings, FailureMask, Reference, RigidState};
use tvmd_ffi::actuator::*;
use tvmd_ffi::config::*;
use tvmd_ffi::handle::*;
use tvmd_ffi::law::*;
use tvmd_ffi::status::*;
use tvmd_ffi::types::*;

fn created() -> Box<TvmdController> {
    created_with(TVMD_ALLOCATOR_REDISTRIBUTED_PSEUDO_INVERSE)
}

/// The paper's controller with one of the `TVMD_ALLOCATOR_*`.
pub(crate) fn created_with(allocator: u32) -> Box<TvmdController> {
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

pub(crate) fn identity() -> [f32; 9] {
    [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]
}

pub(crate) fn step(handle: &mut TvmdController, x: f32) -> (TvmdStatus, TvmdOutput) {
    step_state(handle, &RigidState::at_rest(Vector3::new(x, 0.0, 1.5)))
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
        // Agent i on motors [11 - i, 4 + i], servos [i, 4 + i], reversed eta_y.
        for (i, a) in map.agents.iter_mut().take(4).enumerate() {
            a.motor = [11 - i as u32, 4 + i as u32];
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
        let (m0, m1) = (act.motors[11 - i], act.motors[4 + i]);
        let (sx, sy) = (act.servos[i], act.servos[4 + i]);
        if i == 1 {
            // PX4's "stopped" for both motors, the servos at trim.
            assert!(m0.is_nan() && m1.is_nan(), "a failed agent's motors stop");
            assert_eq!((sx, sy), (0.0, 0.0), "a failed agent's gimbal at trim");
            assert_eq!(*b, TvmdAgentCommand::default());
            continue;
        }
        assert_eq!(m0, m1, "agent {i}: one speed for the coaxial pair");
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
    for unused in [0, 1, 2, 3, 12, 13, 14, 15] {
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
        TVMD_ALLOCATOR_CAPPED_REDISTRIBUTION,
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

/// A configuration filled by `fill` (`tvmd_config_default` or `tvmd_config_paper`).
fn config_from(fill: unsafe extern "C" fn(*mut TvmdConfig) -> TvmdStatus) -> TvmdConfig {
    let mut config: TvmdConfig = unsafe { std::mem::zeroed() };
    config.size = size_of::<TvmdConfig>() as u32;
    // SAFETY: a valid pointer to a live value.
    assert_eq!(unsafe { fill(&mut config) }, TVMD_OK);
    config
}

/// `tvmd_create`'s status for `config`, and the handle.
fn create(config: &TvmdConfig) -> (TvmdStatus, Box<TvmdController>) {
    let mut storage = Box::new(TvmdController {
        opaque: [0; TVMD_CONTROLLER_WORDS],
    });
    // SAFETY: valid pointers to live values.
    let status = unsafe { tvmd_create(&mut *storage, size_of::<TvmdController>(), config) };
    (status, storage)
}

/// A crude hover loop: attitude held at identity, the translation integrated from the wrench
/// the commands produce (eq. 4) plus a constant unmodelled force `d` (N, inertial). Returns
/// the last output and the final position error (m); `each` sees every period's output.
fn hover_under(
    handle: &mut TvmdController,
    d: Vector3<f32>,
    periods: usize,
    mut each: impl FnMut(usize, &mut TvmdController, &TvmdOutput),
) -> (TvmdOutput, f32) {
    let team = presets::a4_inc::<f32, 16>().expect("paper team");
    let m = team.effectiveness(&FailureMask::none());
    let (mass, dt, goal) = (team.mass(), 0.01, Vector3::new(0.0, 0.0, 1.5));
    let (mut x, mut v) = (goal, Vector3::<f32>::zeros());
    let mut out: TvmdOutput = unsafe { std::mem::zeroed() };
    out.size = size_of::<TvmdOutput>() as u32;
    let reference = TvmdReference {
        size: size_of::<TvmdReference>() as u32,
        position: goal.into(),
        attitude: identity(),
        ..TvmdReference::default()
    };
    for k in 0..periods {
        let state = TvmdState {
            size: size_of::<TvmdState>() as u32,
            position: x.into(),
            attitude: identity(),
            velocity: v.into(),
            ..TvmdState::default()
        };
        // SAFETY: valid pointers to live values.
        let status = unsafe { tvmd_step(handle, &state, &reference, &mut out) };
        assert_eq!(status, TVMD_OK, "period {k}");
        each(k, handle, &out);
        let mut forces = [Vector3::zeros(); 16];
        for (f, c) in forces.iter_mut().zip(&out.commands) {
            *f = Vector3::from(
                tvmd_core::GimbalCommand {
                    thrust: c.thrust,
                    eta_x: c.eta_x,
                    eta_y: c.eta_y,
                }
                .force(),
            );
        }
        let wrench = m.wrench(&forces);
        let force = Vector3::new(wrench[3], wrench[4], wrench[5]);
        v += (force - Vector3::new(0.0, 0.0, mass * 9.81) + d) / mass * dt;
        x += v * dt;
    }
    (out, (x - goal).norm())
}

#[test]
fn the_default_config_is_the_offset_free_law_and_the_paper_config_the_paper() {
    use tvmd_core::controller::*;
    let default = config_from(tvmd_config_default);
    let paper = config_from(tvmd_config_paper);
    let law = default.law;
    assert_eq!(law.gain_schedule, TVMD_GAINS_NATURAL);
    assert_eq!(law.offset_free, TVMD_OFFSET_FREE_OBSERVER);
    assert_ne!(law.attitude_rate, 0);
    assert_eq!(law.position_frequency, [POSITION_FREQUENCY as f32; 3]);
    assert_eq!(law.attitude_frequency, [ATTITUDE_FREQUENCY as f32; 3]);
    assert_eq!(law.position_damping, [DAMPING_RATIO as f32; 3]);
    assert_eq!(law.attitude_damping, [ATTITUDE_DAMPING as f32; 3]);
    assert_eq!(law.force_bandwidth, OBSERVER_BANDWIDTH as f32);
    assert_eq!(law.torque_bandwidth, OBSERVER_BANDWIDTH as f32);
    assert_eq!(law.max_torque, OFFSET_FREE_MAX_TORQUE as f32);
    assert_eq!(law.attitude_rate_bandwidth, ATTITUDE_RATE_BANDWIDTH as f32);
    assert_eq!(law.attitude_rate_max, ATTITUDE_RATE_MAX as f32);
    // The paper: every mode off; nothing else differs from the default.
    assert_eq!(
        (paper.law.gain_schedule, paper.law.offset_free),
        (TVMD_GAINS_AS_GIVEN, TVMD_OFFSET_FREE_OFF)
    );
    assert_eq!(paper.law.attitude_rate, 0);
    let modes_off = TvmdLaw {
        gain_schedule: TVMD_GAINS_AS_GIVEN,
        offset_free: TVMD_OFFSET_FREE_OFF,
        attitude_rate: 0,
        ..default.law
    };
    assert_eq!(
        TvmdConfig {
            law: modes_off,
            ..default
        },
        paper
    );
}

/// One period of `handle` at `state` (hover reference at 1.5 m).
fn step_state(handle: &mut TvmdController, state: &RigidState<f32>) -> (TvmdStatus, TvmdOutput) {
    let row = |m: &tvmd_core::nalgebra::Matrix3<f32>| -> [f32; 9] {
        std::array::from_fn(|k| m[(k / 3, k % 3)])
    };
    let state = TvmdState {
        size: size_of::<TvmdState>() as u32,
        position: state.position.into(),
        attitude: row(&state.attitude),
        angular_velocity: state.angular_velocity.into(),
        velocity: state.velocity.into(),
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
fn both_configs_step_bit_for_bit_as_the_rust_core() {
    type Fill = unsafe extern "C" fn(*mut TvmdConfig) -> TvmdStatus;
    let cases: [(Fill, ControllerSettings<f32>); 2] = [
        (tvmd_config_paper, ControllerSettings::paper()),
        (tvmd_config_default, ControllerSettings::default()),
    ];
    for (fill, settings) in cases {
        let offset_free = settings.offset_free.is_some();
        let (status, mut handle) = create(&config_from(fill));
        assert_eq!(status, TVMD_OK);
        let team = presets::a4_inc::<f32, 16>().expect("paper team");
        let mut rust = Controller::new(team, settings, AnyAllocator::default()).expect("core");
        let reference = Reference::hover(Vector3::new(0.0, 0.0, 1.5));
        let mut nonzero = 0;
        for i in 0..60 {
            let t = i as f32;
            let mut state =
                RigidState::at_rest(Vector3::new(0.01 * t, -0.004 * t, 1.5 - 0.002 * t));
            state.velocity = Vector3::new(0.02, 0.01 * t, -0.03);
            state.attitude = tvmd_core::rotation::roll(0.003 * t);
            state.angular_velocity = Vector3::new(0.01, -0.02 * t, 0.0);
            let (status, out) = step_state(&mut handle, &state);
            assert_eq!(status, TVMD_OK);
            let core = rust.step(&state, &reference).expect("core step");
            for (c, r) in out.commands.iter().zip(&core.commands) {
                assert_eq!(
                    [c.eta_x, c.eta_y, c.thrust, c.omega].map(f32::to_bits),
                    [r.eta_x, r.eta_y, r.thrust, r.omega].map(f32::to_bits),
                    "period {i}"
                );
            }
            assert_eq!(out.e_f.to_bits(), core.allocation.e_f.to_bits());
            let comp = rust.offset_free_compensation();
            assert_eq!(out.compensation_force, <[f32; 3]>::from(comp.force));
            assert_eq!(out.compensation_torque, <[f32; 3]>::from(comp.torque));
            nonzero += usize::from(out.compensation_force != [0.0; 3]);
        }
        // The paper has no compensation; the default's observer measures these moves.
        assert_eq!(nonzero > 0, offset_free, "offset-free {offset_free}");
    }
}

#[test]
fn the_default_law_cancels_a_constant_unmodelled_force_the_paper_does_not() {
    let d = Vector3::new(0.8, -0.5, -1.5);
    let (_, mut default) = create(&config_from(tvmd_config_default));
    let (out, error) = hover_under(&mut default, d, 600, |_, _, _| {});
    // The observer's estimate is -compensation: it converged to d.
    let compensation = Vector3::from(out.compensation_force);
    assert!((compensation + d).norm() < 0.02, "{compensation:?}");
    assert!(error < 0.01, "default law: {error} m off");
    let (_, mut paper) = create(&config_from(tvmd_config_paper));
    let (out, paper_error) = hover_under(&mut paper, d, 600, |_, _, _| {});
    assert_eq!(out.compensation_force, [0.0; 3]);
    assert!(paper_error > 0.3, "paper law: {paper_error} m off");
}

#[test]
fn landed_holds_the_compensation_at_zero_until_take_off() {
    let d = Vector3::new(0.0, 0.6, -1.0);
    let (_, mut handle) = create(&config_from(tvmd_config_default));
    // SAFETY: a created handle; null and never-created handles are refused.
    unsafe {
        assert_eq!(tvmd_set_landed(&mut *handle, 1), TVMD_OK);
        assert_eq!(
            tvmd_set_landed(std::ptr::null_mut(), 1),
            TVMD_ERR_NULL_POINTER
        );
        let mut blank = TvmdController {
            opaque: [0; TVMD_CONTROLLER_WORDS],
        };
        assert_eq!(tvmd_set_landed(&mut blank, 0), TVMD_ERR_NOT_INITIALIZED);
    }
    let mut landed_zero = 0;
    let (out, _) = hover_under(&mut handle, d, 300, |k, h, out| {
        if k < 100 {
            landed_zero += usize::from(out.compensation_force == [0.0; 3]);
            landed_zero += usize::from(out.compensation_torque == [0.0; 3]);
        }
        if k == 99 {
            // SAFETY: a created handle. Take-off.
            assert_eq!(unsafe { tvmd_set_landed(h, 0) }, TVMD_OK);
        }
    });
    assert_eq!(landed_zero, 200, "zero while landed");
    let compensation = Vector3::from(out.compensation_force);
    assert!(
        (compensation + d).norm() < 0.05,
        "after take-off: {compensation:?}"
    );
    // Landed again: zero at once, and reset keeps the flag.
    // SAFETY: a created handle.
    unsafe {
        assert_eq!(tvmd_set_landed(&mut *handle, 7), TVMD_OK);
        assert_eq!(tvmd_reset(&mut *handle), TVMD_OK);
    }
    let (out, _) = hover_under(&mut handle, d, 20, |_, _, _| {});
    assert_eq!(out.compensation_force, [0.0; 3]);
}

#[test]
fn bad_law_values_are_refused_with_their_status() {
    let default = config_from(tvmd_config_default);
    /// An edit of the law and the status it must give.
    type Case = (fn(&mut TvmdLaw), TvmdStatus);
    let cases: [Case; 10] = [
        (|l| l.gain_schedule = 3, TVMD_ERR_ENUM_VALUE),
        (|l| l.offset_free = 3, TVMD_ERR_ENUM_VALUE),
        (|l| l.position_frequency[2] = 0.0, TVMD_ERR_CONFIG_PARAMETER),
        (|l| l.attitude_damping[0] = -1.0, TVMD_ERR_CONFIG_PARAMETER),
        (
            |l| l.attitude_frequency[1] = f32::NAN,
            TVMD_ERR_CONFIG_NON_FINITE,
        ),
        // Finite, but K_x = m_C w^2 overflows f32.
        (
            |l| l.position_frequency[0] = 1e20,
            TVMD_ERR_CONFIG_NON_FINITE,
        ),
        (|l| l.torque_bandwidth = 0.0, TVMD_ERR_CONFIG_PARAMETER),
        (|l| l.max_torque = -5.0, TVMD_ERR_CONFIG_PARAMETER),
        (
            |l| l.attitude_rate_bandwidth = f32::INFINITY,
            TVMD_ERR_CONFIG_NON_FINITE,
        ),
        (
            |l| l.offset_free = TVMD_OFFSET_FREE_INTEGRAL, // integral gains left at zero
            TVMD_ERR_CONFIG_PARAMETER,
        ),
    ];
    for (i, (edit, expected)) in cases.iter().enumerate() {
        let mut config = default;
        edit(&mut config.law);
        let (status, mut handle) = create(&config);
        assert_eq!(status, *expected, "case {i}");
        // A refused create leaves the handle not initialized.
        // SAFETY: a handle whose create failed.
        assert_eq!(
            unsafe { tvmd_set_landed(&mut *handle, 1) },
            TVMD_ERR_NOT_INITIALIZED
        );
    }
    // Modes that are off ignore their numbers; the integral and team-scaled gains create.
    let mut config = default;
    config.law.gain_schedule = TVMD_GAINS_TEAM_SCALED;
    config.law.position_frequency = [f32::NAN; 3];
    config.law.offset_free = TVMD_OFFSET_FREE_INTEGRAL;
    config.law.integral_k_x = [0.5; 3];
    config.law.integral_k_r = [0.2; 3];
    config.law.force_bandwidth = -1.0;
    config.law.attitude_rate = 0;
    config.law.attitude_rate_max = f32::NAN;
    let (status, mut handle) = create(&config);
    assert_eq!(status, TVMD_OK);
    let (_, out) = step(&mut handle, 0.2);
    assert_eq!(out.status, TVMD_OK);
    // One period of integral action on a 0.2 m error: a non-zero force.
    assert!(out.compensation_force[0] != 0.0);
}
