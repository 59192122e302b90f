//! Shared fixtures: the reference vectors of `../shared/reference/core_vectors.json`.
#![allow(dead_code)]

use std::path::PathBuf;

use serde_json::Value;

/// `../shared` beside the checkout, or `$TVMD_SHARED`.
pub fn shared_dir() -> PathBuf {
    if let Ok(dir) = std::env::var("TVMD_SHARED") {
        return PathBuf::from(dir);
    }
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared")
}

/// The parsed reference vectors.
pub fn vectors() -> Value {
    let path = shared_dir().join("reference/core_vectors.json");
    let text = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
    serde_json::from_str(&text).expect("core_vectors.json is valid JSON")
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
