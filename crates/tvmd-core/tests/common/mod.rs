//! Shared fixtures: the reference vectors of `tests/data/core_vectors.json` (provenance and
//! format in `tests/data/README.md`), or the file named by `$TVMD_REFERENCE_VECTORS`.
#![allow(dead_code)]

use std::path::{Path, PathBuf};

use serde_json::Value;

/// Names another vector file of the same format for the Rust and the Python suites.
pub const VECTORS_ENV: &str = "TVMD_REFERENCE_VECTORS";

/// The vector families every file must hold, each a non-empty array of cases.
pub const FAMILIES: [&str; 5] = [
    "gimbal",
    "effectiveness",
    "afs_semi_axes",
    "force_projection",
    "attitude_planner",
];

/// The vectors kept in the repository.
pub fn default_vectors_path() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/core_vectors.json")
}

/// `$TVMD_REFERENCE_VECTORS` when set and not empty, else [`default_vectors_path`].
pub fn vectors_path() -> PathBuf {
    match std::env::var_os(VECTORS_ENV) {
        Some(p) if !p.is_empty() => PathBuf::from(p),
        _ => default_vectors_path(),
    }
}

/// Reads and checks a vector file; the error names the file.
pub fn load_vectors(path: &Path) -> Result<Value, String> {
    let what = format!("reference vectors {}", path.display());
    let text = std::fs::read_to_string(path).map_err(|e| format!("cannot read {what}: {e}"))?;
    let v: Value =
        serde_json::from_str(&text).map_err(|e| format!("{what} are not valid JSON: {e}"))?;
    for key in FAMILIES {
        match v.get(key).and_then(Value::as_array) {
            Some(a) if !a.is_empty() => {}
            _ => return Err(format!("{what}: `{key}` is not a non-empty array of cases")),
        }
    }
    Ok(v)
}

/// The parsed vectors of [`vectors_path`]; panics with the loader's message.
pub fn vectors() -> Value {
    let path = vectors_path();
    let source = if path == default_vectors_path() {
        format!("the repository's file; {VECTORS_ENV} may name another")
    } else {
        format!("named by {VECTORS_ENV}")
    };
    load_vectors(&path).unwrap_or_else(|e| panic!("{e} ({source})"))
}

/// The cases under `key`.
pub fn cases<'a>(v: &'a Value, key: &str) -> &'a Vec<Value> {
    v[key].as_array().unwrap_or_else(|| panic!("missing {key}"))
}

pub fn f(v: &Value, key: &str) -> f64 {
    v[key]
        .as_f64()
        .unwrap_or_else(|| panic!("missing number {key}"))
}

pub fn u(v: &Value, key: &str) -> usize {
    v[key]
        .as_u64()
        .unwrap_or_else(|| panic!("missing count {key}")) as usize
}

pub fn vec3(v: &Value) -> [f64; 3] {
    let a = v.as_array().expect("array");
    [
        a[0].as_f64().unwrap(),
        a[1].as_f64().unwrap(),
        a[2].as_f64().unwrap(),
    ]
}

pub fn list(v: &Value) -> Vec<f64> {
    v.as_array()
        .expect("array")
        .iter()
        .map(|x| x.as_f64().expect("number"))
        .collect()
}

pub fn ints(v: &Value) -> Vec<i32> {
    v.as_array()
        .expect("array")
        .iter()
        .map(|x| x.as_i64().expect("integer") as i32)
        .collect()
}

/// Row-major nested list -> rows.
pub fn rows(v: &Value) -> Vec<Vec<f64>> {
    v.as_array().expect("array").iter().map(list).collect()
}

/// `|a - b| <= rel * max(|b|_inf over the whole expected vector, tiny)`, element-wise.
pub fn assert_close(got: &[f64], want: &[f64], rel: f64, what: &str) {
    assert_eq!(got.len(), want.len(), "{what}: length");
    let scale = want.iter().fold(0.0f64, |m, x| m.max(x.abs())).max(1e-12);
    for (i, (g, w)) in got.iter().zip(want).enumerate() {
        assert!(
            (g - w).abs() <= rel * scale,
            "{what}[{i}]: got {g}, want {w} (rel tol {rel}, scale {scale})"
        );
    }
}
