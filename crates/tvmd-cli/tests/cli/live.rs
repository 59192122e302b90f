//! `tvmd-sim run SCENARIO --live`: a Foxglove WebSocket client (protocol `foxglove.sdk.v1`)
//! connects to the CLI's server, subscribes to every advertised channel and receives the run's
//! protobuf messages on the expected topics, stamped with simulation time.

use std::collections::{BTreeMap, BTreeSet};
use std::io::{BufRead, BufReader};
use std::process::{Command, Stdio};

use prost::Message as _;
use serde_json::{json, Value};
use tungstenite::client::IntoClientRequest;
use tungstenite::Message;
use tvmd_log::proto;

#[test]
fn a_client_receives_the_live_run() {
    let dir = std::env::temp_dir().join(format!("tvmd-live-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let scenario = dir.join("short.toml");
    std::fs::write(&scenario, "name = \"live\"\nduration = 1.5\n").unwrap();
    let mut child = Command::new(env!("CARGO_BIN_EXE_tvmd-sim"))
        .args(["run", scenario.to_str().unwrap(), "--no-log", "--live"])
        .args(["--live-port", "0", "--live-wait", "60"])
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let mut stdout = BufReader::new(child.stdout.take().unwrap());
    let mut line = String::new();
    let url = loop {
        line.clear();
        assert!(stdout.read_line(&mut line).unwrap() > 0, "no `live:` line");
        if let Some(rest) = line.strip_prefix("live:") {
            break rest.split_whitespace().next().unwrap().to_string();
        }
    };
    assert!(url.starts_with("ws://127.0.0.1:"), "{url}");

    let mut request = url.as_str().into_client_request().unwrap();
    request
        .headers_mut()
        .insert("Sec-WebSocket-Protocol", "foxglove.sdk.v1".parse().unwrap());
    let (mut socket, _) = tungstenite::connect(request).unwrap();

    // serverInfo, then the advertisement of every channel (with its protobuf schema).
    let mut topics: BTreeMap<u64, String> = BTreeMap::new();
    let mut time_capability = false;
    while topics.len() < 10 {
        let Message::Text(text) = socket.read().unwrap() else {
            continue;
        };
        let v: Value = serde_json::from_str(&text).unwrap();
        match v["op"].as_str() {
            Some("serverInfo") => {
                time_capability = v["capabilities"]
                    .as_array()
                    .unwrap()
                    .iter()
                    .any(|c| c == "time");
            }
            Some("advertise") => {
                for c in v["channels"].as_array().unwrap() {
                    assert_eq!(c["encoding"], "protobuf", "{c}");
                    assert!(!c["schema"].as_str().unwrap().is_empty(), "{c}");
                    topics.insert(
                        c["id"].as_u64().unwrap(),
                        c["topic"].as_str().unwrap().into(),
                    );
                }
            }
            _ => {}
        }
    }
    assert!(time_capability);
    let subscriptions: Vec<Value> = topics
        .keys()
        .map(|&id| json!({"id": id, "channelId": id}))
        .collect();
    socket
        .send(Message::text(
            json!({"op": "subscribe", "subscriptions": subscriptions}).to_string(),
        ))
        .unwrap();

    // Message data frames: opcode 1, subscription id (u32 LE), log time (u64 LE), payload.
    let mut received: BTreeSet<String> = BTreeSet::new();
    let mut last_state_time = 0.0;
    while let Ok(message) = socket.read() {
        let Message::Binary(bytes) = message else {
            continue;
        };
        if bytes.first() != Some(&1) {
            continue; // server time (opcode 2)
        }
        let id = u32::from_le_bytes(bytes[1..5].try_into().unwrap());
        let stamp = u64::from_le_bytes(bytes[5..13].try_into().unwrap());
        let topic = &topics[&u64::from(id)];
        if topic == "/state" {
            let s = proto::State::decode(&bytes[13..]).unwrap();
            assert_eq!(s.position.len(), 3);
            assert!((s.t * 1e9 - stamp as f64).abs() < 1.0, "{} vs {stamp}", s.t);
            last_state_time = s.t;
        }
        received.insert(topic.clone());
        if received.len() >= 6 && last_state_time > 1.0 {
            break;
        }
    }
    for topic in [
        "/state",
        "/reference",
        "/tf",
        "/scene",
        "/allocation",
        "/planner",
    ] {
        assert!(
            received.contains(topic),
            "{topic} not received: {received:?}"
        );
    }
    assert!(last_state_time <= 1.5);
    drop(socket);
    let status = child.wait().unwrap();
    assert!(status.success(), "{status}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bad_live_options_are_refused_before_the_flight() {
    for (args, name) in [
        (["--live-speed", "0"], "live speed"),
        (["--live-wait", "nan"], "live wait"),
        (["--live-host", "not a host name"], "live"),
    ] {
        let out = Command::new(env!("CARGO_BIN_EXE_tvmd-sim"))
            .args([
                "run",
                "paper-tilt",
                "--no-log",
                "--live",
                "--live-port",
                "0",
            ])
            .args(args)
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(1), "{args:?}");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(stderr.contains(&format!("`{name}`")), "{args:?}: {stderr}");
        assert!(!String::from_utf8_lossy(&out.stdout).contains("live:"));
    }
}
