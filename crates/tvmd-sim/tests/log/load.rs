//! A run read back from its log ([`tvmd_sim::load_run`]) equals the run: every sample bit for
//! bit up to the sign of zeros (the log's numbers are protobuf doubles), the summary and the
//! paper metrics.

use tvmd_scenario::Scenario;
use tvmd_sim::runner::run_scenario;
use tvmd_sim::{load_run, SimError};

fn tmp(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("tvmd-sim-load-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

/// Equal as JSON values: numbers by `==` (a zero's sign is not kept by protobuf, which omits a
/// scalar field equal to 0), NaN equal to NaN (both `null`).
fn same<T: serde::Serialize>(a: &T, b: &T) -> bool {
    serde_json::to_value(a).unwrap() == serde_json::to_value(b).unwrap()
}

#[test]
fn a_loaded_run_equals_the_run_that_wrote_it() {
    let mut scenario = Scenario::builtin("agent-failure").unwrap();
    scenario.duration = 3.0;
    scenario.failures[0].time = 1.0;
    let path = tmp("agent-failure.mcap");
    let flown = run_scenario(&scenario, Some(&path), None).unwrap();
    let loaded = load_run(&path).unwrap();
    assert_eq!(loaded.scenario.name, scenario.name);
    assert_eq!(loaded.result.sample_stride, 1);
    assert_eq!(loaded.result.samples.len(), flown.samples.len());
    assert!(flown.samples.iter().any(|s| s.hover.is_some()));
    assert!(flown.samples.last().unwrap().failed.iter().any(|f| *f));
    for (k, (a, b)) in flown.samples.iter().zip(&loaded.result.samples).enumerate() {
        assert!(same(a, b), "sample {k}: {a:?} != {b:?}");
        assert_eq!(a.commands, b.commands, "sample {k}");
    }
    let (a, b) = (
        serde_json::to_value(&flown.summary).unwrap(),
        serde_json::to_value(&loaded.result.summary).unwrap(),
    );
    for (k, v) in a.as_object().unwrap() {
        assert_eq!(v, &b[k], "summary.{k}");
    }
    assert!(same(&flown.paper, &loaded.result.paper));
    std::fs::remove_file(&path).unwrap();
}

/// The fault detector's reports (`/fault`) come back too: a loss the controller was not told
/// of, found and masked by the detector.
#[test]
fn a_loaded_run_keeps_the_fault_reports() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../scenarios/faults/loss-hover.toml"
    );
    let mut scenario = Scenario::from_file(path).unwrap();
    scenario.duration = 5.0;
    let log = tmp("fault-loss-hover.mcap");
    let flown = run_scenario(&scenario, Some(&log), None).unwrap();
    let loaded = load_run(&log).unwrap();
    let reports = flown.samples.iter().filter(|s| s.fault.is_some()).count();
    assert!(reports > 100, "{reports} samples with a fault report");
    assert!(
        flown
            .samples
            .iter()
            .any(|s| s.fault.is_some_and(|f| f.masked == Some(0))),
        "the detector masks agent 0"
    );
    for (k, (a, b)) in flown.samples.iter().zip(&loaded.result.samples).enumerate() {
        assert!(
            same(&a.fault, &b.fault),
            "sample {k}: {:?} != {:?}",
            a.fault,
            b.fault
        );
    }
    std::fs::remove_file(&log).unwrap();
}

#[test]
fn a_log_that_is_not_a_run_is_an_error_naming_it() {
    let path = tmp("not-a-run.mcap");
    std::fs::write(&path, b"plain text").unwrap();
    let err = load_run(&path).unwrap_err();
    assert!(matches!(err, SimError::Log(_)), "{err}");
    assert!(err.to_string().contains("not-a-run.mcap"), "{err}");
    std::fs::remove_file(&path).unwrap();
    let err = load_run(tmp("missing.mcap")).unwrap_err().to_string();
    assert!(err.contains("missing.mcap"), "{err}");
}
