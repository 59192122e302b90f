//! MCAP logs: channels, schemas, message counts, and finalisation on drop / error.

mod common;

use std::collections::BTreeMap;

use common::PdHover;
use mcap::{MessageStream, Summary};
use nalgebra::{Matrix3, Vector3};
use tvmd_sim::actuators::ActuatorCommand;
use tvmd_sim::flight::FlightOutput;
use tvmd_sim::log::{LogKind, McapLog};
use tvmd_sim::math::rot_x;
use tvmd_sim::physics::{PlantState, TeamBody};
use tvmd_sim::reference::{ReferenceConfig, ReferenceSample};
use tvmd_sim::scenario::Scenario;
use tvmd_sim::sim::Simulation;

type BoxedError = Box<dyn std::error::Error + Send + Sync>;

fn tmp(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("tvmd-sim-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

fn counts(bytes: &[u8]) -> BTreeMap<String, usize> {
    let mut by_topic = BTreeMap::new();
    for m in MessageStream::new(bytes).unwrap() {
        let m = m.unwrap();
        // Every message is valid JSON.
        let _: serde_json::Value = serde_json::from_slice(&m.data).unwrap();
        *by_topic.entry(m.channel.topic.clone()).or_insert(0) += 1;
    }
    by_topic
}

fn write_small(log: &mut McapLog) {
    let team = TeamBody::a4_inc();
    for k in 0..3 {
        let t = k as f64 * 0.01;
        log.write(
            LogKind::Lyapunov,
            t,
            &serde_json::json!({"v_x": 1.0, "v_r": 2.0}),
        )
        .unwrap();
        log.write_frame_transform(t, &Vector3::new(0.0, 0.0, t), &rot_x(0.1))
            .unwrap();
        let f = vec![Vector3::new(0.0, 1.0, 7.0); 4];
        log.write_scene(t, &team, &f, &[false, true, false, false], 13.7)
            .unwrap();
    }
}

#[test]
fn small_log_reads_back() {
    let path = tmp("small.mcap");
    let mut log = McapLog::create(&path).unwrap();
    write_small(&mut log);
    assert_eq!(log.message_count(), 9);
    log.finish().unwrap();
    assert!(log.write(LogKind::State, 1.0, &1.0).is_err());
    let bytes = std::fs::read(&path).unwrap();
    let summary = Summary::read(&bytes).unwrap().expect("summary present");
    // LogKind::ALL (8, /hover included), /tf and /scene.
    assert_eq!(summary.channels.len(), 10);
    assert_eq!(summary.stats.as_ref().unwrap().message_count, 9);
    let mut schema_names: Vec<_> = summary
        .schemas
        .values()
        .map(|s| (s.name.clone(), s.encoding.clone()))
        .collect();
    schema_names.sort();
    assert!(schema_names.contains(&("foxglove.FrameTransform".into(), "jsonschema".into())));
    assert!(schema_names.contains(&("foxglove.SceneUpdate".into(), "jsonschema".into())));
    for c in summary.channels.values() {
        assert_eq!(c.message_encoding, "json");
    }
    let by_topic = counts(&bytes);
    assert_eq!(by_topic["/lyapunov"], 3);
    assert_eq!(by_topic["/tf"], 3);
    assert_eq!(by_topic["/scene"], 3);
    // The Foxglove transform has the expected shape.
    let tf = MessageStream::new(&bytes)
        .unwrap()
        .map(|m| m.unwrap())
        .find(|m| m.channel.topic == "/tf")
        .unwrap();
    let v: serde_json::Value = serde_json::from_slice(&tf.data).unwrap();
    assert_eq!(v["parent_frame_id"], "world");
    assert_eq!(v["child_frame_id"], "team");
    assert!(v["rotation"]["w"].as_f64().unwrap() > 0.99);
}

#[test]
fn dropped_log_is_still_valid() {
    let path = tmp("dropped.mcap");
    {
        let mut log = McapLog::create(&path).unwrap();
        write_small(&mut log);
        // No finish(): Drop finalises.
    }
    let bytes = std::fs::read(&path).unwrap();
    let summary = Summary::read(&bytes).unwrap().expect("summary present");
    assert_eq!(summary.stats.unwrap().message_count, 9);
    assert_eq!(counts(&bytes).values().sum::<usize>(), 9);
}

#[test]
fn a_run_logs_every_kind_and_a_failed_run_leaves_a_valid_file() {
    let s = Scenario {
        duration: 0.5,
        initial_position: [0.0, 0.0, 0.0],
        reference: ReferenceConfig::Hover {
            position: [0.0, 0.0, 0.5],
            roll: 0.0,
        },
        ..Scenario::default()
    };
    // Successful run with the PD controller (it reports only the Lyapunov diagnostics).
    let path = tmp("run.mcap");
    let mut log = McapLog::create(&path).unwrap();
    let mut sim = Simulation::new(&s).unwrap();
    let mut ctl = PdHover::new(sim.team());
    sim.run(&mut ctl, Some(&mut log)).unwrap();
    log.finish().unwrap();
    let by_topic = counts(&std::fs::read(&path).unwrap());
    for topic in ["/state", "/reference", "/actuators", "/lyapunov", "/tf"] {
        assert_eq!(by_topic[topic], 50, "{topic}");
    }
    assert_eq!(by_topic["/scene"], 10);
    assert!(!by_topic.contains_key("/planner"));

    // A run whose controller fails at t = 0.25 s: the caller drops the log on the error path.
    let path = tmp("failed.mcap");
    let result = {
        let mut log = McapLog::create(&path).unwrap();
        let mut sim = Simulation::new(&s).unwrap();
        let mut ctl = |t: f64,
                       _: &PlantState,
                       _: &ReferenceSample,
                       _: &[bool]|
         -> Result<FlightOutput, BoxedError> {
            if t > 0.25 {
                return Err("controller gave up".into());
            }
            Ok(FlightOutput {
                commands: vec![ActuatorCommand::default(); 4],
                diagnostics: tvmd_sim::diagnostics::Diagnostics {
                    planner: Some(tvmd_sim::diagnostics::PlannerDiagnostics {
                        r_d: tvmd_sim::math::to_rows(&Matrix3::identity()),
                        t_tf: 1.0,
                        t_eta: 1.0,
                        reference_feasible: true,
                        ..Default::default()
                    }),
                    ..Default::default()
                },
            })
        };
        sim.run(&mut ctl, Some(&mut log))
    };
    assert!(result.is_err());
    let bytes = std::fs::read(&path).unwrap();
    assert!(Summary::read(&bytes).unwrap().is_some());
    let by_topic = counts(&bytes);
    assert_eq!(by_topic["/state"], 26);
    assert_eq!(by_topic["/planner"], 26);
}
