//! Issue 43: every output of every command follows one rule (`tvmd_log::paths`): checked before
//! any work, written whole (a temporary file renamed into place), every I/O error naming its
//! path; and every long command honours SIGINT, keeping (and saying) what finished.

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_tvmd-sim"))
}

fn tmp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("tvmd-sim-outputs-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn failure(out: &Output) -> String {
    assert!(!out.status.success(), "expected a failure: {out:?}");
    String::from_utf8_lossy(&out.stderr).into_owned()
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// A scenario that flies for hours (in a debug build): a check made after the flight would
/// never be reached by these tests.
fn long_scenario(dir: &Path) -> PathBuf {
    let p = dir.join("long.toml");
    std::fs::write(&p, "name = \"long\"\nduration = 30000.0\n").unwrap();
    p
}

/// Item 2: an existing file as the Monte Carlo report directory fails before the first flight,
/// naming the path, and the file is untouched.
#[test]
fn montecarlo_out_over_a_file_fails_before_flying() {
    let dir = tmp_dir("mc-out");
    let f = dir.join("f");
    std::fs::write(&f, "keep").unwrap();
    let out = bin()
        .args(["montecarlo", "hover", "--runs", "1000", "--out", s(&f)])
        .output()
        .unwrap();
    let e = failure(&out);
    assert!(e.contains(s(&f)) && e.contains("is a file"), "{e}");
    assert_eq!(std::fs::read_to_string(&f).unwrap(), "keep");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Items 6 and 11: I/O errors name their path, and outputs are checked before the work.
#[test]
fn io_errors_name_their_path_before_any_work() {
    let dir = tmp_dir("io");
    let missing = dir.join("missing.mcap");
    let e = failure(
        &bin()
            .args(["plot", s(&missing), "--out"])
            .arg(dir.join("p"))
            .output()
            .unwrap(),
    );
    assert!(e.contains("missing.mcap"), "{e}");
    let file = dir.join("existing-file");
    std::fs::write(&file, "keep").unwrap();
    let e = failure(
        &bin()
            .args(["plot", s(&missing), "--out", s(&file)])
            .output()
            .unwrap(),
    );
    // The logs are read before any output is made (issue 57): the missing input is named and
    // the file in the way of `--out` is untouched.
    assert!(e.contains("missing.mcap"), "{e}");
    assert_eq!(std::fs::read_to_string(&file).unwrap(), "keep");
    let long = long_scenario(&dir);
    #[cfg(target_os = "linux")]
    {
        let e = failure(
            &bin()
                .args(["record-cycles", "paper-tilt", "--out", "/proc/x.cycles"])
                .output()
                .unwrap(),
        );
        assert!(e.contains("/proc/x.cycles"), "{e}");
        let e = failure(
            &bin()
                .args(["run", s(&long), "--no-log", "--summary", "/proc/s.json"])
                .output()
                .unwrap(),
        );
        assert!(
            e.contains("/proc/s.json") && !e.contains("simulated"),
            "{e}"
        );
        let e = failure(
            &bin()
                .args([
                    "afs",
                    "a4-inc",
                    "--directions",
                    "3600",
                    "--json",
                    "/proc/x.json",
                ])
                .output()
                .unwrap(),
        );
        assert!(
            e.contains("/proc/x.json") && !e.contains("plot error"),
            "{e}"
        );
    }
    // A sweep's figure directory over a file: before the flights.
    let e = failure(
        &bin()
            .args([
                "sweep",
                "--relaxations",
                "0.5",
                "--scenario",
                s(&long),
                "--plots",
                s(&file),
            ])
            .output()
            .unwrap(),
    );
    assert!(e.contains("existing-file"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Sends SIGINT to `child` after `after`, then waits (at most `limit`) for its exit.
#[cfg(unix)]
fn interrupt(mut child: Child, after: Duration, limit: Duration) -> Output {
    std::thread::sleep(after);
    assert!(
        child.try_wait().unwrap().is_none(),
        "it ended before the signal"
    );
    let killed = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(killed.success());
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > limit {
            let _ = child.kill();
            panic!("still running {limit:?} after SIGINT");
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    child.wait_with_output().unwrap()
}

/// Item 3: SIGINT stops a Monte Carlo study that would fly for many minutes: exit 130, and the
/// flights that finished are in the report, which says it is partial.
#[cfg(unix)]
#[test]
fn sigint_stops_a_monte_carlo_study_and_keeps_what_finished() {
    let dir = tmp_dir("mc-sigint");
    let scenario = dir.join("hover.toml");
    let mut hover = tvmd_scenario::Scenario::builtin("hover").unwrap();
    hover.duration = 1.0;
    hover.success.steady_state_window = 0.5;
    std::fs::write(&scenario, hover.to_toml_string().unwrap()).unwrap();
    let out_dir = dir.join("report");
    let child = bin()
        .args([
            "montecarlo",
            s(&scenario),
            "--runs",
            "100000",
            "--jobs",
            "1",
        ])
        .args(["--out", s(&out_dir)])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let out = interrupt(child, Duration::from_secs(8), Duration::from_secs(60));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(130), "{stderr}");
    assert!(
        stderr.contains("interrupted") && stderr.contains("100000"),
        "{stderr}"
    );
    if stderr.contains("partial") {
        let rows = std::fs::read_to_string(out_dir.join("flights.csv")).unwrap();
        let n = rows.lines().count() - 1;
        assert!((1..100_000).contains(&n), "{n}");
    } else {
        assert!(stderr.contains("nothing written"), "{stderr}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Item 3: SIGINT stops the atlas (minutes at 3600 directions and 200 heights) within a ray:
/// exit 130, nothing written.
#[cfg(unix)]
#[test]
fn sigint_stops_the_atlas() {
    let dir = tmp_dir("afs-sigint");
    let json = dir.join("atlas.json");
    let child = bin()
        .args([
            "afs",
            "a8-inc",
            "--directions",
            "3600",
            "--certify-heights",
            "200",
        ])
        .args(["--json", s(&json)])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let out = interrupt(child, Duration::from_secs(2), Duration::from_secs(60));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(130), "{stderr}");
    assert!(stderr.contains("interrupted") && !json.exists(), "{stderr}");
    std::fs::remove_dir_all(&dir).unwrap();
}
