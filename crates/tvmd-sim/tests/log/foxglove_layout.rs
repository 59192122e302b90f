//! `docs/foxglove-layout.json` names only topics and fields a run's log has: every plot path
//! `/topic.field[i]` resolves to a number in the log's messages, the 3D panel shows `/scene`
//! and follows the `team` frame of `/tf`.

use std::collections::BTreeMap;

use mcap::MessageStream;
use prost_reflect::{DescriptorPool, DynamicMessage, SerializeOptions};
use serde_json::Value;
use tvmd_scenario::Scenario;
use tvmd_sim::runner::run_scenario;

/// `value` at the path `field[i].sub` (Foxglove's message path syntax, the subset we use).
fn resolve<'a>(mut value: &'a Value, path: &str) -> Option<&'a Value> {
    for part in path.split('.') {
        let (name, index) = match part.split_once('[') {
            Some((name, rest)) => (name, rest.strip_suffix(']')?.parse::<usize>().ok()),
            None => (part, None),
        };
        value = value.get(name)?;
        if let Some(i) = index {
            value = value.get(i)?;
        }
    }
    Some(value)
}

#[test]
fn the_layout_names_what_the_log_has() {
    let layout: Value = serde_json::from_str(include_str!("../../../../docs/foxglove-layout.json"))
        .expect("the layout is JSON");
    let dir = std::env::temp_dir().join(format!("tvmd-layout-{}", std::process::id()));
    let log = dir.join("run.mcap");
    let scenario = Scenario::from_toml_str("duration = 5.0\n").unwrap();
    run_scenario(&scenario, Some(&log), None).unwrap();
    let bytes = std::fs::read(&log).unwrap();
    // The last message of each topic, decoded with the schema in the file alone, as JSON.
    let mut last: BTreeMap<String, Value> = BTreeMap::new();
    for message in MessageStream::new(&bytes).unwrap() {
        let message = message.unwrap();
        let schema = message.channel.schema.as_ref().expect("a schema");
        assert_eq!(schema.encoding, "protobuf");
        let pool = DescriptorPool::decode(&*schema.data).unwrap();
        let descriptor = pool.get_message_by_name(&schema.name).unwrap();
        let decoded = DynamicMessage::decode(descriptor, &*message.data).unwrap();
        let options = SerializeOptions::new()
            .use_proto_field_name(true)
            .skip_default_fields(false);
        let v = decoded
            .serialize_with_options(serde_json::value::Serializer, &options)
            .unwrap();
        last.insert(message.channel.topic.clone(), v);
    }
    let panels = layout["configById"].as_object().expect("configById");
    let mut plotted = 0;
    for (id, panel) in panels {
        for path in panel["paths"].as_array().into_iter().flatten() {
            let value = path["value"].as_str().unwrap();
            let (topic, field) = value.split_once('.').unwrap();
            let message = last
                .get(topic)
                .unwrap_or_else(|| panic!("{id}: no topic {topic}"));
            let number = resolve(message, field).and_then(Value::as_f64);
            assert!(
                number.is_some(),
                "{id}: {value} is not a number in {message}"
            );
            plotted += 1;
        }
    }
    assert!(plotted >= 10, "{plotted}");
    let three_d = &panels["3D!team"];
    assert_eq!(three_d["followTf"], "team");
    assert!(last.contains_key("/scene") && three_d["topics"]["/scene"]["visible"] == true);
    let tf = &last["/tf"];
    let child = tf
        .get("child_frame_id")
        .or_else(|| tf["transforms"][0].get("child_frame_id"));
    assert_eq!(child.and_then(Value::as_str), Some("team"), "{tf}");
    // Every panel in the tree exists.
    fn leaves(node: &Value, out: &mut Vec<String>) {
        match node {
            Value::String(s) => out.push(s.clone()),
            Value::Object(o) => {
                for key in ["first", "second"] {
                    if let Some(child) = o.get(key) {
                        leaves(child, out);
                    }
                }
            }
            _ => {}
        }
    }
    let mut ids = Vec::new();
    leaves(&layout["layout"], &mut ids);
    assert_eq!(ids.len(), panels.len());
    assert!(ids.iter().all(|id| panels.contains_key(id)), "{ids:?}");
    std::fs::remove_dir_all(&dir).unwrap();
}
