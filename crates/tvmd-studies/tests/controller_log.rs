//! A short run with the tvmd controller logged to MCAP: every channel present and readable,
//! the scenario metadata, re-plotting from the log, and the adapter's conversions and errors.

use std::collections::BTreeMap;

use mcap::{MessageStream, Summary};
use nalgebra::{Matrix3, Rotation3, Vector3};
use prost::Message;
use tvmd_log::proto;
use tvmd_log::METADATA_SCENARIO;
use tvmd_plant::physics::PlantState;
use tvmd_plant::reference::ReferenceConfig;
use tvmd_scenario::Scenario;
use tvmd_sim::control::{core_reference, core_state, TvmdController};
use tvmd_sim::flight::{FlightController, FlightInput};
use tvmd_sim::runner::run_scenario;
use tvmd_sim::SimError;
use tvmd_studies::plot::{self, PlotSeries};
use tvmd_studies::StudyError;

fn tmp_dir(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("tvmd-sim-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

const TOPICS: [&str; 9] = [
    "/state",
    "/reference",
    "/planner",
    "/control",
    "/allocation",
    "/actuators",
    "/lyapunov",
    "/tf",
    "/scene",
];

#[test]
fn short_run_log_has_every_channel_and_replots() {
    let mut s = Scenario::builtin("paper-tilt").unwrap();
    s.duration = 0.5;
    let dir = tmp_dir("log");
    let path = dir.join("short.mcap");
    let r = run_scenario(&s, Some(&path), None).unwrap();
    assert_eq!(r.samples.len(), 50);

    let bytes = std::fs::read(&path).unwrap();
    let summary = Summary::read(&bytes).unwrap().expect("summary section");
    let mut topics: Vec<&str> = summary
        .channels
        .values()
        .map(|c| c.topic.as_str())
        .collect();
    topics.sort_unstable();
    // Channels appear in the file with their first message: /hover, written only when a
    // failure mask changes, is absent.
    let mut want = TOPICS.to_vec();
    want.sort_unstable();
    assert_eq!(topics, want);

    let mut by_topic: BTreeMap<String, Vec<Vec<u8>>> = BTreeMap::new();
    for m in MessageStream::new(&bytes).unwrap() {
        let m = m.unwrap();
        assert_eq!(m.channel.message_encoding, "protobuf");
        by_topic
            .entry(m.channel.topic.clone())
            .or_default()
            .push(m.data.to_vec());
    }
    for t in TOPICS {
        let n = by_topic.get(t).map_or(0, Vec::len);
        let want = if t == "/scene" { 10 } else { 50 };
        assert_eq!(n, want, "{t}");
    }
    // The controller's diagnostics are in the messages.
    let p = proto::Planner::decode(&*by_topic["/planner"][10]).unwrap();
    assert_eq!(p.status, "already-feasible");
    assert!(p.planned_roll.abs() < 1e-12);
    let a = proto::Allocation::decode(&*by_topic["/allocation"][10]).unwrap();
    assert!(a.e_f < 1e-9);
    assert_eq!(a.forces.len(), 4);
    assert_eq!(a.rounds, 1);
    let c = proto::Control::decode(&*by_topic["/control"][10]).unwrap();
    assert_eq!(c.t_tf, 1.0);
    assert!(c.u_d[5] > 27.0);
    let extra: serde_json::Value = serde_json::from_str(&c.extra_json).unwrap();
    assert_eq!(extra["f_r"].as_array().unwrap().len(), 3);
    let l = proto::Lyapunov::decode(&*by_topic["/lyapunov"][0]).unwrap();
    assert!(l.v_x > 0.09);

    // The scenario is stored as metadata and parses back.
    let idx = summary
        .metadata_indexes
        .iter()
        .find(|i| i.name == METADATA_SCENARIO)
        .expect("scenario metadata");
    let meta = mcap::read::metadata(&bytes, idx).unwrap();
    assert_eq!(meta.metadata["name"], "paper-tilt");
    assert_eq!(Scenario::from_toml_str(&meta.metadata["toml"]).unwrap(), s);

    // Re-plot from the log: the same series as from the samples.
    let from_log = PlotSeries::from_mcap(&bytes).unwrap();
    let from_samples = PlotSeries::from_samples("paper-tilt", Some(0.5), &r.samples);
    assert_eq!(from_log.label, "paper-tilt");
    assert_eq!(from_log.relaxation, Some(0.5));
    assert_eq!(from_log.points.len(), from_samples.points.len());
    for (a, b) in from_log.points.iter().zip(&from_samples.points) {
        assert!((a.t - b.t).abs() < 1e-12);
        for i in 0..3 {
            assert!((a.position[i] - b.position[i]).abs() < 1e-12);
        }
        assert_eq!(a.e_f.is_some(), b.e_f.is_some());
    }
    let figures = plot::write_run_figures(&from_log, &dir, "short").unwrap();
    plot::relaxation_study(&[from_log, from_samples], &dir.join("relaxation.png")).unwrap();
    for f in figures.iter().chain([&dir.join("relaxation.png")]) {
        let png = std::fs::read(f).unwrap();
        assert!(png.starts_with(b"\x89PNG") && png.len() > 10_000, "{f:?}");
    }

    // Not a tvmd-sim log: a clear error.
    assert!(matches!(
        PlotSeries::from_mcap(b"not an mcap"),
        Err(StudyError::Log(tvmd_log::LogError::LogRead(_)))
    ));
}

#[test]
fn state_conversion_uses_body_velocity() {
    let r = Rotation3::from_euler_angles(0.3, -0.2, 1.1).into_inner();
    let s = PlantState {
        position: Vector3::new(1.0, 2.0, 3.0),
        rotation: r,
        velocity: Vector3::new(0.5, -0.1, 0.2),
        omega: Vector3::new(0.01, 0.02, 0.03),
    };
    let c = core_state::<f64>(&s);
    assert!((r * c.velocity - s.velocity).norm() < 1e-15);
    assert_eq!(c.angular_velocity, s.omega);
    assert_eq!(c.attitude, r);
    let reference = ReferenceConfig::default().at(6.0);
    let cr = core_reference::<f64>(&reference);
    assert_eq!(cr.attitude, reference.rotation);
    assert_eq!(cr.velocity, reference.velocity);
}

#[test]
fn scenario_errors_name_the_field() {
    let field_of = |s: &Scenario| match TvmdController::<f64>::from_scenario(s).unwrap_err() {
        SimError::Scenario(tvmd_scenario::ScenarioError::InvalidScenario { field, .. }) => field,
        e => panic!("unexpected error {e}"),
    };
    let mut s = Scenario::default();
    s.limits.sigma_x = 2.0; // the sim accepts up to pi, the core only up to pi/2
    assert_eq!(field_of(&s), "limits.sigma_x");
    let mut s = Scenario::default();
    s.gains.k_xi[4] = 0.0;
    assert_eq!(field_of(&s), "gains.k_xi");
    let mut s = Scenario::default();
    s.gains.k_r[2] = 0.0;
    assert_eq!(field_of(&s), "gains.k_r");
    let s = Scenario {
        allocator: "magic".into(),
        ..Scenario::default()
    };
    assert_eq!(field_of(&s), "allocator");
    // The scenario parser rejects the unknown allocator too, by name.
    let e = Scenario::from_toml_str("allocator = \"magic\"\n").unwrap_err();
    assert!(e.to_string().contains("allocator"), "{e}");
    let e = Scenario::from_toml_str("controller_rate_limits = [1.0, -1.0]\n").unwrap_err();
    assert!(e.to_string().contains("controller_rate_limits[1]"), "{e}");
}

#[test]
fn failures_reach_the_core_and_bad_inputs_hold_the_commands() {
    let s = Scenario::builtin("a6-agent-failure").unwrap();
    let mut ctl = TvmdController::<f64>::from_scenario(&s).unwrap();
    let state = PlantState::at_rest(Vector3::new(0.0, 0.0, 1.5));
    let reference = ReferenceConfig::Hover {
        position: [0.0, 0.0, 1.5],
        roll: 0.0,
    }
    .at(0.0);
    let mut failed = vec![false; 6];
    let healthy = ctl
        .step(&FlightInput::new(0.0, &state, &reference, &failed))
        .unwrap();
    assert!(healthy.diagnostics.cycle_error.is_none());
    failed[3] = true;
    let degraded = ctl
        .step(&FlightInput::new(0.01, &state, &reference, &failed))
        .unwrap();
    assert!(ctl.core().failures().is_failed(3));
    assert_eq!(degraded.commands[3].thrust, 0.0);
    assert!(degraded.diagnostics.allocation.unwrap().e_f < 1e-9);

    // A non-rotation attitude: the cycle is skipped, the previous commands are held.
    let mut bad = state;
    bad.rotation = Matrix3::identity() * 2.0;
    let held = ctl
        .step(&FlightInput::new(0.02, &bad, &reference, &failed))
        .unwrap();
    let why = held.diagnostics.cycle_error.expect("cycle error reported");
    assert!(why.contains("state.attitude"), "{why}");
    assert_eq!(held.commands, degraded.commands);
}
