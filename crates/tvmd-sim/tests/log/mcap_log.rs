//! MCAP logs: protobuf channels with their schemas in the file, message counts, decimation,
//! and finalisation on drop / error.

use std::collections::BTreeMap;

use crate::common::PdHover;
use foxglove::messages::{FrameTransform, SceneUpdate};
use mcap::{MessageStream, Summary};
use nalgebra::{Matrix3, Vector3};
use prost::Message;
use prost_types::FileDescriptorSet;
use tvmd_log::{proto, LogKind, RunLog};
use tvmd_plant::actuators::ActuatorCommand;
use tvmd_plant::math::rot_x;
use tvmd_plant::physics::TeamBody;
use tvmd_plant::reference::ReferenceConfig;
use tvmd_scenario::LogSettings;
use tvmd_scenario::Scenario;
use tvmd_sim::flight::{FlightInput, FlightOutput};
use tvmd_sim::sim::Simulation;
use tvmd_sim::McapSink;

type BoxedError = Box<dyn std::error::Error + Send + Sync>;

fn tmp(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("tvmd-sim-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

/// Decodes `data` as the message type of `topic`; panics on a decode error.
fn decode(topic: &str, data: &[u8]) {
    let ok = match topic {
        "/state" => proto::State::decode(data).is_ok(),
        "/reference" => proto::Reference::decode(data).is_ok(),
        "/planner" => proto::Planner::decode(data).is_ok(),
        "/control" => proto::Control::decode(data).is_ok(),
        "/allocation" => proto::Allocation::decode(data).is_ok(),
        "/actuators" => proto::Actuators::decode(data).is_ok(),
        "/lyapunov" => proto::Lyapunov::decode(data).is_ok(),
        "/hover" => proto::Hover::decode(data).is_ok(),
        "/tf" => FrameTransform::decode(data).is_ok(),
        "/scene" => SceneUpdate::decode(data).is_ok(),
        other => panic!("unexpected topic {other}"),
    };
    assert!(ok, "{topic}: not its protobuf message");
}

/// Messages per topic; every message decodes, and every channel is protobuf with a schema
/// (a `FileDescriptorSet` that defines the schema's message).
fn counts(bytes: &[u8]) -> BTreeMap<String, usize> {
    let mut by_topic = BTreeMap::new();
    for m in MessageStream::new(bytes).unwrap() {
        let m = m.unwrap();
        assert_eq!(m.channel.message_encoding, "protobuf");
        let schema = m.channel.schema.as_ref().expect("a schema");
        assert_eq!(schema.encoding, "protobuf");
        let set = FileDescriptorSet::decode(&*schema.data).unwrap();
        let (package, name) = schema.name.rsplit_once('.').unwrap();
        assert!(
            set.file
                .iter()
                .any(|f| f.package() == package && f.message_type.iter().any(|d| d.name() == name)),
            "{} is not defined by its schema",
            schema.name
        );
        let kind = LogKind::ALL
            .into_iter()
            .find(|k| k.topic() == m.channel.topic)
            .unwrap();
        assert_eq!(schema.name, kind.schema_name());
        decode(&m.channel.topic, &m.data);
        *by_topic.entry(m.channel.topic.clone()).or_insert(0) += 1;
    }
    by_topic
}

fn write_small(log: &mut RunLog) {
    let team = TeamBody::a4_inc();
    for k in 0..3 {
        let t = k as f64 * 0.01;
        let msg = proto::Lyapunov {
            t,
            v_x: 1.0,
            v_r: 2.0,
        };
        log.write(t, msg).unwrap();
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
    let mut log = RunLog::create(&path).unwrap();
    write_small(&mut log);
    log.finish().unwrap();
    assert_eq!(log.message_count(), 9);
    assert!(log.write(1.0, proto::State::default()).is_err());
    let bytes = std::fs::read(&path).unwrap();
    let summary = Summary::read(&bytes).unwrap().expect("summary present");
    // The channels that carried messages: /lyapunov, /tf and /scene.
    assert_eq!(summary.channels.len(), 3);
    assert_eq!(summary.stats.as_ref().unwrap().message_count, 9);
    let by_topic = counts(&bytes);
    assert_eq!(by_topic["/lyapunov"], 3);
    assert_eq!(by_topic["/tf"], 3);
    assert_eq!(by_topic["/scene"], 3);
    // The Foxglove transform has the expected content, and the log time is the sim time.
    let tf = MessageStream::new(&bytes)
        .unwrap()
        .map(|m| m.unwrap())
        .filter(|m| m.channel.topic == "/tf")
        .nth(1)
        .unwrap();
    assert_eq!(tf.log_time, 10_000_000);
    let v = FrameTransform::decode(&*tf.data).unwrap();
    assert_eq!(v.parent_frame_id, "world");
    assert_eq!(v.child_frame_id, "team");
    assert!(v.rotation.unwrap().w > 0.99);
    assert!((v.translation.unwrap().z - 0.01).abs() < 1e-15);
}

#[test]
fn dropped_log_is_still_valid() {
    let path = tmp("dropped.mcap");
    {
        let mut log = RunLog::create(&path).unwrap();
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
    let mut log = RunLog::create(&path).unwrap();
    let mut sim = Simulation::new(&s).unwrap();
    let mut ctl = PdHover::new(sim.team());
    sim.run(&mut ctl, Some(&mut McapSink::new(&mut log)))
        .unwrap();
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
        let mut log = RunLog::create(&path).unwrap();
        let mut sim = Simulation::new(&s).unwrap();
        let mut ctl = |input: &FlightInput<'_>| -> Result<FlightOutput, BoxedError> {
            let t = input.t;
            if t > 0.25 {
                return Err("controller gave up".into());
            }
            Ok(FlightOutput {
                commands: vec![ActuatorCommand::default(); 4],
                diagnostics: tvmd_sim::diagnostics::Diagnostics {
                    planner: Some(tvmd_sim::diagnostics::PlannerDiagnostics {
                        r_d: tvmd_plant::math::to_rows(&Matrix3::identity()),
                        t_tf: 1.0,
                        t_eta: 1.0,
                        reference_feasible: true,
                        ..Default::default()
                    }),
                    ..Default::default()
                },
            })
        };
        sim.run(&mut ctl, Some(&mut McapSink::new(&mut log)))
    };
    assert!(result.is_err());
    let bytes = std::fs::read(&path).unwrap();
    assert!(Summary::read(&bytes).unwrap().is_some());
    let by_topic = counts(&bytes);
    assert_eq!(by_topic["/state"], 26);
    assert_eq!(by_topic["/planner"], 26);
}

#[test]
fn decimation_thins_the_heavy_topics_only() {
    let base = Scenario {
        duration: 0.5,
        ..Scenario::default()
    };
    let count = |log_settings: LogSettings, name: &str| {
        let s = Scenario {
            log: log_settings,
            ..base.clone()
        };
        let path = tmp(name);
        let spec = tvmd_sim::runner::RunSpec {
            scenario: s,
            log: Some(path.clone()),
            pil: None,
            samples: tvmd_sim::sim::SampleRetention::None,
        };
        let flight = tvmd_sim::runner::fly(&spec, None, None).unwrap();
        assert!(flight.error.is_none());
        counts(&std::fs::read(&path).unwrap())
    };
    let all = count(LogSettings::default(), "all.mcap");
    let thin = count(
        LogSettings {
            decimation: 5,
            scene_period: 0.1,
        },
        "thin.mcap",
    );
    for topic in ["/planner", "/control", "/allocation", "/actuators"] {
        assert_eq!(all[topic], 50, "{topic}");
        assert_eq!(thin[topic], 10, "{topic}");
    }
    for topic in ["/state", "/reference", "/lyapunov", "/tf"] {
        assert_eq!(thin[topic], all[topic], "{topic}");
    }
    assert_eq!((all["/scene"], thin["/scene"]), (10, 5));
}
