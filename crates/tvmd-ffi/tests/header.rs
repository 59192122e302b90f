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
