//! Hostile use of the simulator: signals to a running `tvmd-sim run`, path clashes, extreme and
//! malformed scenarios. Each case ends in a clear error or a correct result, never a lost log,
//! a silent clamp or a run that never ends.

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::Duration;

use tvmd_scenario::Scenario;

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_tvmd-sim"))
}

fn tmp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("tvmd-sim-hostile-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Whether `dir` holds an output's temporary file (`tvmd_log::paths::temporary`).
fn has_temporary(dir: &Path) -> bool {
    std::fs::read_dir(dir).is_ok_and(|entries| {
        entries
            .filter_map(Result::ok)
            .any(|e| e.file_name().to_string_lossy().starts_with(".tmp-"))
    })
}

fn failure(out: &Output) -> String {
    assert!(
        !out.status.success(),
        "expected a failure, got {:?}",
        out.status
    );
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// `tvmd-sim run` of a long flight, stopped by `signal` once its log exists: exit 130, the MCAP
/// complete (footer and summary section, so strict readers open it) and the summary JSON
/// written, marked interrupted, covering less than the scenario. The flight has 3e6 controller
/// ticks, more than a run may keep as samples: the command line keeps none (its summary folds
/// every tick), so it starts.
#[cfg(unix)]
fn interrupted_run_keeps_its_log(signal: &str) {
    let dir = tmp_dir(&format!("signal-{signal}"));
    let scenario = dir.join("long.toml");
    std::fs::write(&scenario, "name = \"long\"\nduration = 30000.0\n").unwrap();
    let log = dir.join("long.mcap");
    let mut child = bin()
        .args([
            "run",
            scenario.to_str().unwrap(),
            "--out",
            log.to_str().unwrap(),
        ])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Wait until the flight is under way (its log's temporary file is created when it
    // starts; the log itself appears, whole, when the run ends).
    while !has_temporary(&dir) {
        assert!(child.try_wait().unwrap().is_none(), "the run ended early");
        std::thread::sleep(Duration::from_millis(20));
    }
    std::thread::sleep(Duration::from_millis(300));
    let killed = Command::new("kill")
        .args([format!("-{signal}"), child.id().to_string()])
        .status()
        .unwrap();
    assert!(killed.success());
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(130), "{stderr}");
    assert!(stderr.contains("interrupted"), "{stderr}");
    let bytes = std::fs::read(&log).unwrap();
    let summary = mcap::Summary::read(&bytes).unwrap();
    let stats = summary
        .and_then(|s| s.stats)
        .expect("the log has its summary section");
    assert!(stats.message_count > 0);
    assert!(stats.message_end_time < 1_000_000_000_000, "{stats:?}");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("long.summary.json")).unwrap())
            .unwrap();
    assert_eq!(json["summary"]["interrupted"], true, "{json}");
    assert!(json["summary"]["time"].as_f64().unwrap() < 30000.0);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[cfg(unix)]
#[test]
fn sigint_finalises_the_log_and_summary() {
    interrupted_run_keeps_its_log("INT");
}

#[cfg(unix)]
#[test]
fn sigterm_finalises_the_log_and_summary() {
    interrupted_run_keeps_its_log("TERM");
}

#[test]
fn output_paths_are_checked_before_the_run() {
    let dir = tmp_dir("paths");
    let scenario = dir.join("s.toml");
    std::fs::write(&scenario, "name = \"s\"\nduration = 0.3\n").unwrap();
    let text = std::fs::read_to_string(&scenario).unwrap();
    let run = |args: &[&str]| bin().arg("run").args(args).output().unwrap();
    let s = scenario.to_str().unwrap();
    // The log over its own input: refused, the input intact.
    let e = failure(&run(&[s, "--out", s]));
    assert!(
        e.contains("scenario file") && e.contains("overwritten"),
        "{e}"
    );
    assert_eq!(std::fs::read_to_string(&scenario).unwrap(), text);
    // The log and the summary on one file.
    let same = dir.join("x.out");
    let e = failure(&run(&[
        s,
        "--out",
        same.to_str().unwrap(),
        "--summary",
        same.to_str().unwrap(),
    ]));
    assert!(e.contains("both"), "{e}");
    assert!(!same.exists());
    // A parent that is a file is named as such.
    let blocker = dir.join("blocker");
    std::fs::write(&blocker, "").unwrap();
    let e = failure(&run(&[
        s,
        "--out",
        blocker.join("run.mcap").to_str().unwrap(),
    ]));
    assert!(
        e.contains("is a file, not a directory") && e.contains("blocker"),
        "{e}"
    );
    // A bad summary path fails before the run, not after.
    let e = failure(&run(&[
        s,
        "--no-log",
        "--summary",
        blocker.join("s.json").to_str().unwrap(),
    ]));
    assert!(e.contains("s.json") && e.contains("is a file"), "{e}");
    assert!(!e.contains("simulated time"));
    // Duplicate relaxations would write one log twice.
    let out = bin()
        .args([
            "sweep",
            "--relaxations",
            "0.5,0.5",
            "--scenario",
            s,
            "--logs",
        ])
        .arg(dir.join("dup"))
        .output()
        .unwrap();
    let e = failure(&out);
    assert!(e.contains("output path clash"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A scenario name cannot move the default log out of `out/`.
#[test]
fn scenario_names_stay_inside_the_output_directory() {
    let dir = tmp_dir("names");
    let scenario = dir.join("evil.toml");
    std::fs::write(&scenario, "name = \"../../evil\"\nduration = 0.05\n").unwrap();
    let out = bin()
        .current_dir(&dir)
        .args(["run", scenario.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(dir.join("out").join("_.._evil.mcap").is_file());
    assert!(!dir.join("../../evil.mcap").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

fn rejects(toml: &str, field: &str) {
    match Scenario::from_toml_str(toml) {
        Ok(_) => panic!("accepted: {toml}"),
        Err(e) => {
            let m = e.to_string();
            assert!(m.contains(field), "{toml}: {m}");
        }
    }
}

/// Extreme values: each refused with the field and its range, none left to run until killed
/// or to freeze the body.
#[test]
fn extreme_scenarios_are_refused_naming_the_field() {
    rejects("duration = 1e9\n", "duration");
    rejects("duration = 1e308\n", "duration");
    rejects("duration = 1e-9\n", "duration");
    rejects("[physics]\ndt = 1e-300\n", "physics.dt");
    rejects(
        "controller_period = 1e-300\n[physics]\ndt = 1e-300\n",
        "physics.dt",
    );
    rejects("[physics]\ndt = 10.0\n", "physics.dt");
    rejects("controller_period = 1e300\n", "controller_period");
    rejects(
        "[physics]\nsolver_iterations = 1000000000\n",
        "physics.solver_iterations",
    );
    rejects(
        "[physics]\nsolver_iterations = 0\n",
        "physics.solver_iterations",
    );
    rejects("[physics]\ngravity = 1e300\n", "physics.gravity");
    rejects("[log]\ndecimation = 0\n", "log.decimation");
    rejects("[log]\ndecimation = 1000000000\n", "log.decimation");
    rejects("[log]\nscene_period = nan\n", "log.scene_period");
    rejects("[log]\nscene_period = 0.0\n", "log.scene_period");
    rejects("[team]\nagent_mass = 1e300\n", "team.agent_mass");
    rejects("[team]\nagent_mass = 1e-300\n", "team.agent_mass");
    rejects(
        "[reference]\nkind = \"paper-tilt\"\nascent_height = 1e300\n",
        "reference.ascent_height",
    );
    rejects(
        "[reference]\nkind = \"paper-tilt\"\ntilt = [4.0, 4.0]\n",
        "reference.tilt",
    );
    rejects("initial_position = [0.0, 0.0, -1.0]\n", "initial_position");
    rejects(
        "[disturbances]\nwind = [1e160, 0.0, 0.0]\n",
        "disturbances.wind",
    );
    rejects(
        "[disturbances.external_wrench]\nforce = [1.0, 0.0, 0.0]\nstart = 5.0\nend = 2.0\n",
        "disturbances.external_wrench.end",
    );
    rejects(
        "[actuators.servo]\nnatural_frequency = 1e308\ndamping_ratio = 0.7\nrate_limit = 5.0\n",
        "actuators.servo.natural_frequency",
    );
    // Runs longer than the samples a run may keep are valid scenarios (the samples kept are
    // the caller's choice, `SampleRetention`); physics steps bound them.
    assert!(Scenario::from_toml_str("duration = 100000.0\n").is_ok());
}

/// Files that are not regular scenario files are refused before they are read.
#[cfg(unix)]
#[test]
fn devices_fifos_and_huge_files_are_refused() {
    let dir = tmp_dir("files");
    let link = dir.join("zero.toml");
    std::os::unix::fs::symlink("/dev/zero", &link).unwrap();
    let e = Scenario::load(link.to_str().unwrap())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("not a regular file") && e.contains("zero.toml"),
        "{e}"
    );
    let fifo = dir.join("fifo.toml");
    let made = Command::new("mkfifo").arg(&fifo).status().unwrap();
    assert!(made.success());
    let e = Scenario::load(fifo.to_str().unwrap())
        .unwrap_err()
        .to_string();
    assert!(e.contains("not a regular file"), "{e}");
    let huge = dir.join("huge.toml");
    std::fs::write(&huge, "#".repeat(2 << 20)).unwrap();
    let e = Scenario::load(huge.to_str().unwrap())
        .unwrap_err()
        .to_string();
    assert!(e.contains("bytes") && e.contains("huge.toml"), "{e}");
    let e = Scenario::load(dir.join("missing.toml").to_str().unwrap())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("missing.toml") && e.contains("read the scenario file"),
        "{e}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A state that leaves the physics' valid range ends the run with a clear error instead of
/// flying on at rapier's velocity cap.
#[test]
fn divergence_ends_the_run_with_an_error() {
    let s = Scenario::from_toml_str("duration = 3.0\n[disturbances]\nwind = [9000.0, 0.0, 0.0]\n")
        .unwrap();
    let e = tvmd_sim::runner::run_scenario(&s, None, None).unwrap_err();
    let m = e.to_string();
    assert!(
        matches!(
            e,
            tvmd_sim::SimError::Physics(tvmd_plant::PhysicsError::Diverged { .. })
        ),
        "{m}"
    );
    assert!(m.contains("speed") && m.contains("300"), "{m}");
}

/// A flight that fails while flying still leaves its log and a summary of what was simulated,
/// naming the error.
#[test]
fn a_failed_run_writes_its_summary() {
    let dir = tmp_dir("failed");
    let scenario = dir.join("windy.toml");
    std::fs::write(
        &scenario,
        "name = \"windy\"\nduration = 3.0\n[disturbances]\nwind = [9000.0, 0.0, 0.0]\n",
    )
    .unwrap();
    let log = dir.join("windy.mcap");
    let out = bin()
        .args([
            "run",
            scenario.to_str().unwrap(),
            "--out",
            log.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    let e = failure(&out);
    assert!(e.contains("diverged"), "{e}");
    let bytes = std::fs::read(&log).unwrap();
    assert!(mcap::Summary::read(&bytes).unwrap().is_some());
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("windy.summary.json")).unwrap())
            .unwrap();
    let error = json["summary"]["error"].as_str().unwrap_or_default();
    assert!(error.contains("diverged"), "{json}");
    assert!(json["summary"]["time"].as_f64().unwrap() < 3.0);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Every field of `[reference]` has a default, `kind` included.
#[test]
fn a_reference_table_without_kind_is_the_paper_tilt() {
    let s = Scenario::from_toml_str("[reference]\nascent_height = 1.0\n").unwrap();
    let t = s.reference.at(3.0).position;
    assert!((t[2] - 1.0).abs() < 1e-12, "{t:?}");
}

/// `tvmd-sim px4` with a PX4 tree that does not exist, or is not built: a clear error naming
/// the tree before anything listens or flies, and no log.
#[test]
fn px4_with_a_missing_or_unbuilt_tree_is_refused() {
    let dir = tmp_dir("px4-tree");
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let fly = |tree: &Path| {
        bin()
            .current_dir(&root)
            .args([
                "px4",
                "scripts/px4/quad/scenario.toml",
                "--flight",
                "scripts/px4/quad/flight.toml",
            ])
            .arg("--px4-dir")
            .arg(tree)
            .arg("--out")
            .arg(dir.join("px4.mcap"))
            .output()
            .unwrap()
    };
    let missing = dir.join("no-such-px4");
    let err = failure(&fly(&missing));
    assert!(err.contains("no-such-px4: no such directory"), "{err}");
    let unbuilt = dir.join("unbuilt");
    std::fs::create_dir_all(unbuilt.join("ROMFS/px4fmu_common/init.d-posix")).unwrap();
    std::fs::write(unbuilt.join("ROMFS/px4fmu_common/init.d-posix/rcS"), "").unwrap();
    let err = failure(&fly(&unbuilt));
    assert!(
        err.contains("PX4 SITL is not built") && err.contains("make px4_sitl_default"),
        "{err}"
    );
    assert!(!dir.join("px4.mcap").exists());
    std::fs::remove_dir_all(&dir).ok();
}
