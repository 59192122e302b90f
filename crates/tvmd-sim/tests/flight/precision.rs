//! The f32 controller in the loop (the flight configuration): it is the core type a flight
//! controller runs, its boundary conversions never produce a NaN, and its flight of the paper's
//! scenario stays within a measured bound of the f64 flight.

use nalgebra::Vector3;
use tvmd_core::AnyAllocator;
use tvmd_plant::physics::PlantState;
use tvmd_plant::reference::ReferenceConfig;
use tvmd_scenario::{Precision, Scenario};
use tvmd_sim::control::{AnyTvmdController, MAX_AGENTS};
use tvmd_sim::flight::{FlightController, FlightInput};
use tvmd_sim::runner::run_scenario;
use tvmd_sim::sim::FlightDifference;

fn paper_tilt_in(precision: Precision) -> tvmd_sim::sim::RunResult {
    let s = Scenario {
        controller_precision: precision,
        ..Scenario::builtin("paper-tilt").unwrap()
    };
    run_scenario(&s, None, None).unwrap()
}

#[test]
fn f32_scenario_flies_the_flight_controller_type() {
    let s = Scenario::from_toml_str("controller_precision = \"f32\"\n").unwrap();
    let ctl = AnyTvmdController::from_scenario(&s).unwrap();
    assert_eq!(ctl.precision(), Precision::F32);
    let AnyTvmdController::F32(c) = &ctl else {
        panic!("an f32 scenario built {ctl:?}")
    };
    // The very type a flight controller embeds.
    let _: &tvmd_core::Controller<f32, MAX_AGENTS, AnyAllocator<f32, MAX_AGENTS>> = c.core();
    let d = AnyTvmdController::from_scenario(&Scenario::default()).unwrap();
    assert!(matches!(d, AnyTvmdController::F64(_)));
}

#[test]
fn f32_out_of_range_input_holds_the_commands_without_nan() {
    let s = Scenario {
        controller_precision: Precision::F32,
        ..Scenario::default()
    };
    let mut ctl = AnyTvmdController::from_scenario(&s).unwrap();
    let reference = ReferenceConfig::Hover {
        position: [0.0, 0.0, 1.5],
        roll: 0.0,
    }
    .at(0.0);
    let state = PlantState::at_rest(Vector3::new(0.0, 0.0, 1.5));
    let failed = [false; 4];
    let good = ctl
        .step(&FlightInput::new(0.0, &state, &reference, &failed))
        .unwrap();
    assert!(good.diagnostics.cycle_error.is_none());
    assert!(good.commands.iter().all(|c| c.thrust > 0.0));
    // Finite in f64, beyond f32's range: rounds to infinity, which the core rejects.
    let mut far = state;
    far.position.x = 1e39;
    let held = ctl
        .step(&FlightInput::new(0.01, &far, &reference, &failed))
        .unwrap();
    let why = held.diagnostics.cycle_error.expect("cycle error reported");
    assert!(why.contains("state.position"), "{why}");
    assert_eq!(held.commands, good.commands);
    let values = held
        .commands
        .iter()
        .flat_map(|c| [c.eta_x, c.eta_y, c.thrust]);
    assert!(values.into_iter().all(f64::is_finite));
}

/// Last sample time of `paper-tilt` before its touchdown (t = 14.37 s): the flight before it is
/// the controller's alone; from touchdown on, contact onset amplifies any difference.
const AIRBORNE_UNTIL: f64 = 14.3;

/// The f32 and the f64 controllers fly `paper-tilt` to the same reproduction metrics, and the
/// flights differ little at every sample.
#[test]
fn f32_and_f64_flights_of_paper_tilt_agree() {
    let a = paper_tilt_in(Precision::F64);
    let b = paper_tilt_in(Precision::F32);
    assert_eq!(b.summary.controller_precision, Precision::F32);
    let d = FlightDifference::between(&a.samples, &b.samples).expect("matching samples");
    eprintln!("f32 vs f64, paper-tilt: {d:#?}");
    assert_eq!(d.samples, 1600);
    let air = a.samples.partition_point(|s| s.t <= AIRBORNE_UNTIL);
    let d_air = FlightDifference::between(&a.samples[..air], &b.samples[..air]).unwrap();
    eprintln!("f32 vs f64, paper-tilt until t = {AIRBORNE_UNTIL} s: {d_air:#?}");
    // Bounds about 10x the measured differences (README, "Reproduction"). In the air: position
    // 5.0e-7 m, attitude 3.0e-7 rad, gimbal angles 5.8e-7 rad, thrust 7.4e-6 N.
    assert!(d_air.position < 5e-6, "{d_air:?}");
    assert!(d_air.attitude < 3e-6, "{d_air:?}");
    assert!(d_air.gimbal < 6e-6, "{d_air:?}");
    assert!(d_air.thrust < 1e-4, "{d_air:?}");
    // The whole flight, landing included: position 4.1e-4 m (sliding on the ground at the
    // end), attitude 3.9e-5 rad, gimbal angles 3.5e-5 rad, thrust 9.4e-3 N (of 6.9 N, at touchdown,
    // t = 14.39 s).
    assert!(d.position < 4e-3, "{d:?}");
    assert!(d.attitude < 4e-4, "{d:?}");
    assert!(d.gimbal < 4e-4, "{d:?}");
    assert!(d.thrust < 0.1, "{d:?}");
    // The reproduction metrics agree to the same order.
    let (sa, sb) = (&a.summary, &b.summary);
    let planned = (sa.max_planned_roll.unwrap() - sb.max_planned_roll.unwrap()).abs();
    assert!(planned < 1e-4, "max planned roll differs by {planned}");
    assert!((sa.max_roll - sb.max_roll).abs() < 1e-4);
}
