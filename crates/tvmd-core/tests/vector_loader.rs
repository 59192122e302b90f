//! The loader of the reference vectors: the file in the repository by default, the file named by
//! `$TVMD_REFERENCE_VECTORS` when set, and a clear error (naming the path) otherwise.
//!
//! No test sets the variable in this process (tests run in threads); the variable is checked by
//! running this test binary again in a child process with the variable set.

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use common::*;
use serde_json::Value;

/// A fresh scratch directory for one test (pid and name keep parallel runs apart).
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("tvmd-vectors-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The repository's vectors with the first gimbal case's thrust replaced by `thrust`.
fn changed_copy(dir: &Path, thrust: f64) -> PathBuf {
    let mut v = load_vectors(&default_vectors_path()).unwrap();
    v["gimbal"][0]["thrust"] = Value::from(thrust);
    let path = dir.join("changed.json");
    std::fs::write(&path, serde_json::to_string(&v).unwrap()).unwrap();
    path
}

/// Runs the ignored probe below in a child process with `$TVMD_REFERENCE_VECTORS` = `value`.
fn run_probe(value: &Path) -> Output {
    Command::new(std::env::current_exe().unwrap())
        .args([
            "--ignored",
            "--exact",
            "probe_prints_loaded_vectors",
            "--nocapture",
        ])
        .args(["--test-threads", "1"])
        .env(VECTORS_ENV, value)
        .output()
        .unwrap()
}

#[test]
fn default_file_is_in_the_repository_and_complete() {
    let path = default_vectors_path();
    assert!(
        path.ends_with("tests/data/core_vectors.json"),
        "{}",
        path.display()
    );
    let v = load_vectors(&path).unwrap();
    for key in FAMILIES {
        assert!(!cases(&v, key).is_empty(), "{key}");
    }
}

#[test]
fn loader_returns_the_data_of_the_file_it_is_given() {
    let dir = scratch("changed");
    let path = changed_copy(&dir, 12345.5);
    let v = load_vectors(&path).unwrap();
    assert_eq!(f(&cases(&v, "gimbal")[0], "thrust"), 12345.5);
    let original = load_vectors(&default_vectors_path()).unwrap();
    assert_ne!(f(&cases(&original, "gimbal")[0], "thrust"), 12345.5);
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn missing_or_malformed_files_are_errors_naming_the_path() {
    let dir = scratch("bad");
    let missing = dir.join("missing.json");
    let err = load_vectors(&missing).unwrap_err();
    assert!(err.contains(&missing.display().to_string()), "{err}");

    let not_json = dir.join("not-json.json");
    std::fs::write(&not_json, "{ \"gimbal\": [").unwrap();
    let err = load_vectors(&not_json).unwrap_err();
    assert!(
        err.contains(&not_json.display().to_string()) && err.contains("JSON"),
        "{err}"
    );

    let mut v = load_vectors(&default_vectors_path()).unwrap();
    v.as_object_mut().unwrap().remove("attitude_planner");
    let incomplete = dir.join("incomplete.json");
    std::fs::write(&incomplete, serde_json::to_string(&v).unwrap()).unwrap();
    let err = load_vectors(&incomplete).unwrap_err();
    assert!(
        err.contains(&incomplete.display().to_string()) && err.contains("attitude_planner"),
        "{err}"
    );
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn environment_variable_selects_the_file() {
    let dir = scratch("env");
    let path = changed_copy(&dir, 6789.25);
    let out = run_probe(&path);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        stdout.contains(&format!("probe path={}", path.display())),
        "{stdout}"
    );
    assert!(stdout.contains("probe thrust=6789.25"), "{stdout}");
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn environment_variable_naming_a_missing_file_fails_with_its_path() {
    let missing = scratch("env-missing").join("no-such-vectors.json");
    let out = run_probe(&missing);
    let all = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(!out.status.success(), "{all}");
    assert!(
        all.contains(&missing.display().to_string()) && all.contains(VECTORS_ENV),
        "{all}"
    );
    std::fs::remove_dir_all(missing.parent().unwrap()).unwrap();
}

/// Run only by the two tests above, in a child process with the variable set.
#[test]
#[ignore = "run in a subprocess by environment_variable_* with TVMD_REFERENCE_VECTORS set"]
fn probe_prints_loaded_vectors() {
    let v = vectors();
    println!("probe path={}", vectors_path().display());
    println!("probe thrust={}", f(&cases(&v, "gimbal")[0], "thrust"));
}
