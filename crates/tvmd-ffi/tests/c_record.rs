//! Replays the record of the C test program (`crates/tvmd-ffi/tests/c/tvmd_test.c`,
//! `law_test.c`) on the Rust API (`tvmd_core::Controller`, the paper's team, f32, 16 agents,
//! with the paper's settings after `create` and the default, offset-free law after
//! `create default`) and compares every output bit for bit, the offset-free compensation
//! included: the C interface adds no arithmetic of its own.
//!
//! `scripts/ffi.sh` builds and runs the C program, then runs this test with
//! `TVMD_FFI_C_RECORD` naming the record file.

use tvmd_core::nalgebra::{Matrix3, Vector3};
use tvmd_core::team::presets;
use tvmd_core::{
    AnyAllocator, Controller, ControllerSettings, FailureMask, HoverLimit, InputError,
    PlannerStatus, Reference, RigidState,
};
use tvmd_ffi::status::*;

type RustController = Controller<f32, 16, AnyAllocator<f32, 16>>;

fn float(word: &str) -> f32 {
    f32::from_bits(u32::from_str_radix(word, 16).unwrap_or_else(|e| panic!("{word}: {e}")))
}

fn v3(x: &[f32]) -> Vector3<f32> {
    Vector3::new(x[0], x[1], x[2])
}

fn m3(x: &[f32]) -> Matrix3<f32> {
    Matrix3::from_row_slice(&x[..9])
}

fn expected_input_status(e: &InputError) -> i32 {
    match e {
        InputError::NonFinite { .. } => TVMD_ERR_INPUT_NON_FINITE,
        InputError::NotRotation { .. } => TVMD_ERR_INPUT_NOT_ROTATION,
        InputError::OutOfRange { .. } => TVMD_ERR_INPUT_OUT_OF_RANGE,
        InputError::Unattainable { .. } => TVMD_ERR_INPUT_UNATTAINABLE,
        InputError::Overflow { .. } => TVMD_ERR_INPUT_OVERFLOW,
    }
}

fn new_controller(settings: ControllerSettings<f32>) -> RustController {
    let team = presets::a4_inc::<f32, 16>().expect("paper team");
    Controller::new(team, settings, AnyAllocator::default()).expect("paper team controller")
}

/// Replays one `step` line; returns (status, planner status) for the summary.
fn replay_step(controller: &mut RustController, words: &[&str], line: usize) -> (i32, u32) {
    let status: i32 = words[1].parse().expect("status");
    let x: Vec<f32> = words[2..words.len() - 2].iter().map(|w| float(w)).collect();
    let planner_status: u32 = words[words.len() - 2].parse().expect("planner status");
    let iterations: u32 = words[words.len() - 1].parse().expect("iterations");
    assert_eq!(
        x.len(),
        18 + 24 + 64 + 1 + 9 + 1 + 6,
        "line {line}: field count"
    );
    let state = RigidState {
        position: v3(&x[0..]),
        attitude: m3(&x[3..]),
        angular_velocity: v3(&x[12..]),
        velocity: v3(&x[15..]),
    };
    let reference = Reference {
        position: v3(&x[18..]),
        velocity: v3(&x[21..]),
        acceleration: v3(&x[24..]),
        attitude: m3(&x[27..]),
        angular_velocity: v3(&x[36..]),
        angular_acceleration: v3(&x[39..]),
    };
    let c_commands = &x[42..106];
    let (e_f, r_d, theta) = (x[106], &x[107..116], x[116]);
    let compensation = &x[117..123];
    let bits = |v: &[f32]| v.iter().map(|f| f.to_bits()).collect::<Vec<_>>();
    let (rust_status, commands) = match controller.step(&state, &reference) {
        Ok(out) => {
            let rd_rows: Vec<f32> = (0..3)
                .flat_map(|r| (0..3).map(move |c| (r, c)))
                .map(|(r, c)| out.planner.r_d[(r, c)])
                .collect();
            assert_eq!(
                e_f.to_bits(),
                out.allocation.e_f.to_bits(),
                "line {line}: e_f"
            );
            assert_eq!(bits(r_d), bits(&rd_rows), "line {line}: R_d");
            assert_eq!(
                theta.to_bits(),
                out.planner.theta.to_bits(),
                "line {line}: theta"
            );
            let code = match out.planner.status {
                PlannerStatus::AlreadyFeasible => 0,
                PlannerStatus::Planned => 1,
                PlannerStatus::ZeroForce => 2,
                PlannerStatus::Unreachable => 3,
            };
            assert_eq!(planner_status, code, "line {line}: planner status");
            assert_eq!(
                iterations, out.planner.iterations,
                "line {line}: iterations"
            );
            let c = controller.offset_free_compensation();
            let rust: Vec<f32> = c.force.iter().chain(c.torque.iter()).copied().collect();
            assert_eq!(bits(compensation), bits(&rust), "line {line}: compensation");
            (TVMD_OK, out.commands)
        }
        Err(held) => {
            assert!(
                e_f.is_nan() && theta.is_nan() && compensation.iter().all(|c| c.is_nan()),
                "line {line}: NaN diagnostics on error"
            );
            (expected_input_status(&held.error), held.commands)
        }
    };
    assert_eq!(status, rust_status, "line {line}: status");
    let rust_commands: Vec<f32> = commands
        .iter()
        .flat_map(|c| [c.eta_x, c.eta_y, c.thrust, c.omega])
        .collect();
    assert_eq!(
        bits(c_commands),
        bits(&rust_commands),
        "line {line}: commands"
    );
    (status, planner_status)
}

fn replay_failures(controller: &mut RustController, words: &[&str], line: usize) -> i32 {
    let mask = u32::from_str_radix(words[1], 16).expect("mask");
    let status: i32 = words[2].parse().expect("status");
    let mut failures = FailureMask::<16>::none();
    let mut index_error = None;
    for bit in (0..32).filter(|b| mask & (1 << b) != 0) {
        if let Err(e) = failures.set(bit, true) {
            index_error = Some(e);
        }
    }
    let result = match index_error {
        Some(e) => Err(e),
        None => controller.set_failures(failures),
    };
    match result {
        Ok(hover) => {
            assert_eq!(status, TVMD_OK, "line {line}: status");
            if words[3] != "-" {
                assert_eq!(
                    words[3],
                    if hover.capable { "1" } else { "0" },
                    "line {line}"
                );
                assert_eq!(
                    float(words[4]).to_bits(),
                    hover.margin.to_bits(),
                    "line {line}"
                );
                let agent = hover.limiting_agent.map_or(-1, |a| a as i32);
                assert_eq!(
                    words[5].parse::<i32>().expect("agent"),
                    agent,
                    "line {line}"
                );
                let limit = match hover.limit {
                    HoverLimit::MaxThrust => 0,
                    HoverLimit::MinThrust => 1,
                    HoverLimit::GimbalX => 2,
                    HoverLimit::GimbalY => 3,
                };
                assert_eq!(
                    words[6].parse::<u32>().expect("limit"),
                    limit,
                    "line {line}"
                );
                assert_eq!(
                    float(words[7]).to_bits(),
                    hover.weight.to_bits(),
                    "line {line}"
                );
            }
        }
        Err(e) => assert_eq!(status, config_status(&e), "line {line}: status"),
    }
    status
}

#[test]
#[ignore = "needs the C program's record: run by scripts/ffi.sh"]
fn c_outputs_equal_the_rust_api_bit_for_bit() {
    let path = std::env::var("TVMD_FFI_C_RECORD")
        .expect("TVMD_FFI_C_RECORD names the record written by the C test program");
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let mut controller = None;
    let (mut steps, mut errors, mut planned, mut masks) = (0, 0, 0, 0);
    let (mut default_steps, mut landed) = (0, 0);
    for (i, line) in text.lines().enumerate() {
        let words: Vec<&str> = line.split_whitespace().collect();
        let c = || format!("line {}: {line:.60}", i + 1);
        match words[0] {
            "create" => {
                controller = Some(new_controller(match words.get(1) {
                    None => ControllerSettings::paper(),
                    Some(&"default") => ControllerSettings::default(),
                    Some(other) => panic!("{}: unknown configuration {other}", c()),
                }))
            }
            "landed" => {
                let flag: u32 = words[1].parse().expect("landed flag");
                let ctrl = controller
                    .as_mut()
                    .unwrap_or_else(|| panic!("{}: no create", c()));
                ctrl.set_landed(flag != 0);
                landed += 1;
            }
            "step" => {
                let ctrl = controller
                    .as_mut()
                    .unwrap_or_else(|| panic!("{}: no create", c()));
                let (status, planner) = replay_step(ctrl, &words, i + 1);
                steps += 1;
                default_steps += usize::from(ctrl.settings().offset_free.is_some());
                errors += usize::from(status != TVMD_OK);
                planned += usize::from(status == TVMD_OK && planner == 1);
            }
            "failures" => {
                let ctrl = controller
                    .as_mut()
                    .unwrap_or_else(|| panic!("{}: no create", c()));
                masks += usize::from(replay_failures(ctrl, &words, i + 1) == TVMD_OK);
            }
            "reset" => controller.as_mut().expect("create before reset").reset(),
            other => panic!("{}: unknown record {other}", c()),
        }
    }
    println!(
        "replayed {steps} steps ({errors} refused, {planned} planner-saturated, \
         {default_steps} of the offset-free law), {masks} masks, {landed} landed flags"
    );
    // The record covers what the C test is meant to: hover, the saturating planner, refused
    // inputs and masks, the offset-free law and the landed flag.
    assert!(steps >= 10 && errors >= 5 && planned >= 4 && masks >= 2);
    assert!(default_steps >= 600 && landed >= 3);
}
