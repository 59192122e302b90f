//! `include/tvmd.h` is what cbindgen generates from this crate now.
//! Regenerate with `TVMD_BLESS=1 cargo test -p tvmd-ffi --test header`.

use std::path::PathBuf;

#[test]
fn header_is_up_to_date() {
    let crate_dir = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let path = crate_dir.join("../../include/tvmd.h");
    let config = cbindgen::Config::from_file(crate_dir.join("cbindgen.toml"))
        .unwrap_or_else(|e| panic!("cbindgen.toml: {e}"));
    let bindings = cbindgen::Builder::new()
        .with_crate(&crate_dir)
        .with_config(config)
        .generate()
        .unwrap_or_else(|e| panic!("cbindgen failed: {e}"));
    let mut generated = Vec::new();
    bindings.write(&mut generated);
    if std::env::var_os("TVMD_BLESS").is_some() {
        std::fs::write(&path, &generated).unwrap_or_else(|e| panic!("writing {path:?}: {e}"));
        return;
    }
    let committed = std::fs::read(&path).unwrap_or_default();
    assert!(
        committed == generated,
        "include/tvmd.h is stale (or missing): regenerate it with \
         `TVMD_BLESS=1 cargo test -p tvmd-ffi --test header` and commit it"
    );
}

/// Each `TVMD_ERR_MAP_CHANNEL_RANGE` bound the header states is the one the map checks: the
/// motor and servo channels of PX4's topics, not `TVMD_MAX_AGENTS` (issue 57, item 8).
#[test]
fn the_channel_range_error_names_the_channels_the_map_checks() {
    let crate_dir = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let header = std::fs::read_to_string(crate_dir.join("../../include/tvmd.h")).unwrap();
    let at = header.find("#define TVMD_ERR_MAP_CHANNEL_RANGE").unwrap();
    let comment = &header[header[..at].rfind("/*").unwrap()..at];
    let motors = tvmd_ffi::actuator::TVMD_MOTOR_CHANNELS;
    let servos = tvmd_ffi::actuator::TVMD_SERVO_CHANNELS;
    assert!(
        comment.contains(&format!("({motors},")) && comment.contains(&format!("({servos},")),
        "{comment}"
    );
    assert!(!comment.contains("16"), "{comment}");
}
