//! The law that flies (`[law]`'s default: natural gains, the disturbance observer, the planned
//! rates) against the paper's law in the loop: the steady errors a constant disturbance leaves,
//! the landed hold the loop drives, and the feedback latency.

use nalgebra::Vector3;
use tvmd_plant::physics::PlantState;
use tvmd_plant::ReferenceConfig;
use tvmd_scenario::{LawConfig, Scenario};
use tvmd_sim::control::{TvmdController, LANDED_HEIGHT};
use tvmd_sim::flight::FlightInput;
use tvmd_sim::runner::run_scenario;
use tvmd_sim::sim::RunResult;
use tvmd_sim::FlightController;

fn fly(s: &Scenario) -> RunResult {
    let r = run_scenario(s, None, None).unwrap();
    assert!(r.summary.error.is_none() && !r.summary.interrupted);
    r
}

fn steady_position_error(r: &RunResult) -> f64 {
    r.summary.metrics.position.unwrap().steady_state.unwrap()
}

/// The wind family's first 4 s (a steady 1 m/s wind along x; the gust comes at 4 s): the
/// offset-free law holds the set-point within a centimetre, the paper's law is blown off it.
#[test]
fn the_wind_familys_steady_error_is_removed_by_the_offset_free_law() {
    let wind = Scenario {
        duration: 4.0,
        ..Scenario::builtin("wind").unwrap()
    };
    assert_eq!(wind.law, LawConfig::default());
    let new = steady_position_error(&fly(&wind));
    let paper = steady_position_error(&fly(&Scenario {
        law: LawConfig::paper(),
        ..wind.clone()
    }));
    eprintln!(
        "wind, steady position error over 3-4 s: offset-free {new:.2e} m, paper {paper:.3} m"
    );
    assert!(new < 0.01, "{new}");
    assert!(paper > 0.1, "{paper}");
}

/// An unmodelled mass (+2%): the paper's law sags by `dm g / K_x,z`, the offset-free law
/// does not, with state noise and one period of latency.
#[test]
fn a_noisy_delayed_hover_with_a_mass_error_stays_within_a_centimetre() {
    let mut s = Scenario::builtin("hover").unwrap();
    s.duration = 6.0;
    s.plant.mass_scale = 1.02;
    s.disturbances.feedback_latency = 1;
    s.disturbances.state_noise = Some(tvmd_scenario::StateNoise {
        position: 0.001,
        velocity: 0.01,
        attitude: 0.002,
        angular_velocity: 0.01,
        seed: 5,
    });
    let r = fly(&s);
    let e = steady_position_error(&r);
    eprintln!("hover, mass +2%, noise, latency 1: steady error {e:.2e} m");
    assert!(e < 0.01, "{e}");
    assert!(r.summary.verdict.success, "{:?}", r.summary.verdict);
}

/// The adapter tells the core the team is on the ground while the fed-back centre of mass is
/// within `LANDED_HEIGHT` of its rest height, and that it is not once it is above.
#[test]
fn the_adapter_holds_the_offset_free_state_on_the_ground() {
    let s = Scenario {
        initial_position: [0.0, 0.0, 0.0],
        ..Scenario::default()
    };
    let mut c = TvmdController::<f64>::from_scenario(&s).unwrap();
    let reference = ReferenceConfig::Hover {
        position: [0.0, 0.0, 1.0],
        roll: 0.0,
    }
    .at(0.0);
    let failed = [false; 4];
    let ground = PlantState::at_rest(Vector3::zeros());
    c.step(&FlightInput::new(0.0, &ground, &reference, &failed))
        .unwrap();
    assert!(c.core().landed());
    // A second period on the ground with the reference a metre above: nothing is learnt.
    c.step(&FlightInput::new(0.01, &ground, &reference, &failed))
        .unwrap();
    assert_eq!(c.core().offset_free_compensation().force, Vector3::zeros());
    let air = PlantState::at_rest(Vector3::new(0.0, 0.0, 2.0 * LANDED_HEIGHT));
    c.step(&FlightInput::new(0.02, &air, &reference, &failed))
        .unwrap();
    assert!(!c.core().landed());
}

/// The paper's experiment, modelled: the paper's law keeps a height error and a yaw offset
/// (the tether, the thrust error and the yaw torque); the offset-free law removes both (at
/// most a tenth). Takes off from the ground, so the landed hold is part of the flight.
#[test]
fn paper_experiment_height_and_yaw_errors_fall_tenfold() {
    let errors = |name: &str| {
        let r = fly(&Scenario::builtin(name).unwrap());
        // Means over the steady-state window, the last 4 s of hover.
        let window: Vec<_> = r.samples.iter().filter(|x| x.t >= 16.0).collect();
        let mean = |f: &dyn Fn(&tvmd_sim::sim::Sample) -> f64| {
            window.iter().map(|x| f(x)).sum::<f64>() / window.len() as f64
        };
        let dz = mean(&|x| x.position[2] - x.reference_position[2]).abs();
        let yaw = mean(&|x| x.roll_pitch_yaw[2]).abs();
        eprintln!("{name}: mean height error {dz:.2e} m, mean yaw {yaw:.2e} rad over 16-20 s");
        (dz, yaw)
    };
    let (z_paper, yaw_paper) = errors("paper-experiment");
    let (z_new, yaw_new) = errors("paper-experiment-offset-free");
    assert!(z_paper > 0.1 && yaw_paper > 0.01, "{z_paper} {yaw_paper}");
    assert!(z_new <= 0.1 * z_paper, "{z_new} vs {z_paper}");
    assert!(yaw_new <= 0.1 * yaw_paper, "{yaw_new} vs {yaw_paper}");
}

/// The PIL configuration words and the cycle recording carry the law: the controller built
/// from the words of the default scenario (the offset-free law), of a table law and of
/// paper-tilt has the f32 settings the simulator builds, and an unknown kind word is refused.
#[test]
fn the_wire_configuration_carries_the_law() {
    use tvmd_sim::control::{controller_settings, wire_config};
    let table = Scenario::from_toml_str(
        "[law]\ngains = \"team-scaled\"\nattitude_rate = \"off\"\n\
         offset_free = { kind = \"integral\", k_x = [1.0, 2.0, 3.0], k_r = [0.5, 0.5, 0.25], max_torque = 4.0 }\n",
    )
    .unwrap();
    assert_eq!(table.law.name(), "custom");
    for s in [
        Scenario::default(),
        table,
        Scenario::builtin("paper-tilt").unwrap(),
    ] {
        let words = wire_config(&s).unwrap();
        let built = words.build().unwrap();
        let want = controller_settings::<f32>(&s).unwrap();
        let got = built.settings();
        assert_eq!(
            (got.gain_schedule, got.offset_free, got.attitude_rate),
            (want.gain_schedule, want.offset_free, want.attitude_rate),
            "{}",
            s.law.name()
        );
    }
    let mut words = wire_config(&Scenario::default()).unwrap();
    words.law.offset_free = 7;
    assert!(words.build().is_err());
}

/// The scenario's round cap reaches the allocator in process and through the words (PIL and
/// the recorder build the same capped allocator).
#[test]
fn the_allocators_round_cap_is_flown_in_process_and_carried_by_the_words() {
    use tvmd_core::{AnyAllocator, RoundCap};
    use tvmd_sim::control::{core_of_scenario, wire_config};
    let mut s = Scenario {
        allocator_max_rounds: Some(RoundCap::Rounds(3)),
        ..Scenario::default()
    };
    let (controller, _) = core_of_scenario::<f32>(&s).unwrap();
    let AnyAllocator::ExactBoundaryRedistribution(a) = controller.allocator() else {
        panic!("the default allocator is the exact-boundary redistribution");
    };
    assert_eq!(a.round_cap(), RoundCap::Rounds(3));
    let words = wire_config(&s).unwrap();
    assert_eq!(words.max_rounds, RoundCap::Rounds(3));
    let built = words.build().unwrap();
    let AnyAllocator::ExactBoundaryRedistribution(a) = built.allocator() else {
        panic!("the words build the exact-boundary redistribution");
    };
    assert_eq!(a.round_cap(), RoundCap::Rounds(3));
    // No cap named: the library's default, resolved in the words; "uncapped" as named.
    s.allocator_max_rounds = None;
    assert_eq!(wire_config(&s).unwrap().max_rounds, RoundCap::default());
    assert_eq!(RoundCap::default(), RoundCap::Rounds(2));
    s.allocator_max_rounds = Some(RoundCap::Uncapped);
    let words = wire_config(&s).unwrap();
    assert_eq!(words.max_rounds, RoundCap::Uncapped);
    let built = words.build().unwrap();
    let AnyAllocator::ExactBoundaryRedistribution(a) = built.allocator() else {
        panic!("the words build the exact-boundary redistribution");
    };
    assert_eq!(a.round_cap(), RoundCap::Uncapped);
}

/// Issue 59: the library's default caps the walk, the paper's scenarios name the uncapped
/// walk they were first flown with (so their bits and recordings stay), and a scenario file
/// says either.
#[test]
fn the_default_is_capped_and_the_papers_scenarios_fly_uncapped() {
    use tvmd_core::RoundCap;
    for name in [
        "paper-tilt",
        "relaxation-1.0",
        "agent-failure",
        "paper-experiment",
    ] {
        let s = Scenario::builtin(name).unwrap();
        assert_eq!(s.allocator_max_rounds, Some(RoundCap::Uncapped), "{name}");
    }
    for name in ["hover", "turbulence", "initial-attitude-1.5"] {
        let s = Scenario::builtin(name).unwrap();
        assert_eq!(s.allocator_max_rounds, None, "{name}");
    }
    let file = |text: &str| Scenario::from_toml_str(text).map(|s| s.allocator_max_rounds);
    assert_eq!(
        file("allocator_max_rounds = \"uncapped\"\n").unwrap(),
        Some(RoundCap::Uncapped)
    );
    assert_eq!(
        file("allocator_max_rounds = 0\n").unwrap(),
        Some(RoundCap::Rounds(0))
    );
    let e = file("allocator_max_rounds = \"none\"\n")
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("allocator_max_rounds") && e.contains("uncapped"),
        "{e}"
    );
    // And it round-trips through the scenario's TOML (the log's metadata).
    let s = Scenario::builtin("paper-tilt").unwrap();
    let back = Scenario::from_toml_str(&s.to_toml_string().unwrap()).unwrap();
    assert_eq!(back.allocator_max_rounds, Some(RoundCap::Uncapped));
}
