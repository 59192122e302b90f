//! Tests of the schema ([`super`]): descriptors and round trips.

use super::*;

#[test]
fn the_descriptor_set_names_every_message_and_field_once() {
    let set = FileDescriptorSet::decode(file_descriptor_set()).unwrap();
    assert_eq!(set.file.len(), 1);
    let file = &set.file[0];
    assert_eq!(file.package(), PACKAGE);
    let names: Vec<&str> = file.message_type.iter().map(|m| m.name()).collect();
    for n in [
        "State",
        "Reference",
        "Allocation",
        "Actuators",
        "Hover",
        "Fault",
        "Vec3",
    ] {
        assert!(names.contains(&n), "{n} missing from {names:?}");
    }
    for m in &file.message_type {
        let mut numbers: Vec<i32> = m.field.iter().map(|f| f.number()).collect();
        numbers.sort_unstable();
        numbers.dedup();
        assert_eq!(
            numbers.len(),
            m.field.len(),
            "{}: duplicate field number",
            m.name()
        );
        for f in &m.field {
            if f.r#type() == Type::Message {
                let target = f.type_name().trim_start_matches(".tvmd.");
                assert!(names.contains(&target), "{}.{}", m.name(), f.name());
            }
        }
    }
    let hover = file
        .message_type
        .iter()
        .find(|m| m.name() == "Hover")
        .unwrap();
    let limiting = hover
        .field
        .iter()
        .find(|f| f.name() == "limiting_agent")
        .unwrap();
    assert!(limiting.proto3_optional());
    assert_eq!(hover.oneof_decl[0].name(), "_limiting_agent");
}

#[test]
fn messages_round_trip_and_keep_explicit_presence() {
    let h = Hover {
        t: 1.5,
        capable: true,
        margin: 0.25,
        limiting_agent: Some(0),
        limit: "thrust".into(),
        landing: false,
    };
    let back = Hover::decode(h.encode_to_vec().as_slice()).unwrap();
    assert_eq!(back, h);
    assert_eq!(back.limiting_agent, Some(0));
    let none = Hover {
        limiting_agent: None,
        ..h
    };
    assert_eq!(
        Hover::decode(none.encode_to_vec().as_slice())
            .unwrap()
            .limiting_agent,
        None
    );
}
