//! The `tvmd-sim` command line: list, show, run, sweep, plot, and errors.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use tvmd_scenario::Scenario;

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_tvmd-sim"))
}

fn tmp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("tvmd-sim-cli-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn ok(out: Output) -> String {
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(
        out.status.success(),
        "exit {:?}\nstdout:\n{stdout}\nstderr:\n{}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    stdout
}

fn short_scenario(dir: &Path) -> PathBuf {
    let path = dir.join("short.toml");
    std::fs::write(&path, "name = \"short\"\nduration = 0.3\n").unwrap();
    path
}

#[test]
fn list_and_show() {
    let list = ok(bin().arg("list").output().unwrap());
    for name in tvmd_scenario::BUILTIN_NAMES {
        assert!(list.contains(name), "{list}");
    }
    let toml = ok(bin()
        .args(["show", "paper-tilt-sigma-y-pi6"])
        .output()
        .unwrap());
    assert_eq!(
        Scenario::from_toml_str(&toml).unwrap(),
        Scenario::builtin("paper-tilt-sigma-y-pi6").unwrap()
    );
    let out = bin().args(["show", "nope"]).output().unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("unknown built-in scenario `nope`"));
}

#[test]
fn malformed_file_fails_naming_the_field() {
    let dir = tmp_dir("bad");
    for (text, field) in [
        ("relaxation = \"half\"\n", "relaxation"),
        ("[physics]\ndt = -1.0\n", "physics.dt"),
        ("[gains]\nk_x = [1.0]\n", "k_x"),
        ("allocator = \"magic\"\n", "allocator"),
        ("[limits]\nsigma_x = 2.0\n", "limits.sigma_x"),
    ] {
        let path = dir.join("bad.toml");
        std::fs::write(&path, text).unwrap();
        let out = bin()
            .args(["run", path.to_str().unwrap(), "--no-log"])
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{text}");
        assert!(
            err.starts_with("error:") && err.contains(field),
            "{text}: {err}"
        );
    }
    let out = bin()
        .args(["run", "missing-file.toml", "--no-log"])
        .output()
        .unwrap();
    assert!(!out.status.success());
}

#[test]
fn run_writes_log_summary_and_figures_then_plot_rereads_the_log() {
    let dir = tmp_dir("run");
    let scenario = short_scenario(&dir);
    let log = dir.join("out/short.mcap");
    let summary = dir.join("out/summary.json");
    let plots = dir.join("plots");
    let stdout = ok(bin()
        .arg("run")
        .arg(&scenario)
        .arg("--out")
        .arg(&log)
        .arg("--summary")
        .arg(&summary)
        .arg("--plots")
        .arg(&plots)
        .output()
        .unwrap());
    assert!(stdout.contains("max planned roll"), "{stdout}");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&summary).unwrap()).unwrap();
    assert_eq!(json["scenario"], "short");
    assert_eq!(json["controller_precision"], "f64");
    assert!((json["summary"]["time"].as_f64().unwrap() - 0.3).abs() < 1e-9);
    for key in [
        "max_position_error",
        "max_position_error_after_4s",
        "final_position_error",
        "max_planned_roll",
        "max_roll",
        "max_e_f",
        "max_e_f_over_weight",
        "final_v_x",
        "min_thrust",
        "max_thrust",
        "max_abs_eta_x",
        "max_abs_eta_y",
        "saturated_periods",
        "wall_time",
        "real_time_factor",
    ] {
        assert!(json["summary"].get(key).is_some(), "{key}");
    }
    assert!(plots.join("short-state.png").is_file());
    assert!(plots.join("short-lyapunov.png").is_file());

    let replot = dir.join("replot");
    ok(bin()
        .arg("plot")
        .arg(&log)
        .arg(&log)
        .arg("--out")
        .arg(&replot)
        .output()
        .unwrap());
    for f in ["short-state.png", "short-lyapunov.png", "relaxation.png"] {
        assert!(replot.join(f).is_file(), "{f}");
    }
}

#[test]
fn precision_option_flies_f32_and_rejects_other_types() {
    let dir = tmp_dir("precision");
    let scenario = short_scenario(&dir);
    let summary = dir.join("f32.json");
    let stdout = ok(bin()
        .arg("run")
        .arg(&scenario)
        .args(["--precision", "f32", "--no-log", "--summary"])
        .arg(&summary)
        .output()
        .unwrap());
    assert!(
        stdout.contains("controller precision       f32"),
        "{stdout}"
    );
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&summary).unwrap()).unwrap();
    assert_eq!(json["controller_precision"], "f32");
    assert_eq!(json["summary"]["controller_precision"], "f32");
    assert_eq!(json["summary"]["cycle_errors"], 0);
    let table = dir.join("sweep.json");
    ok(bin()
        .args([
            "sweep",
            "--relaxations",
            "1.0",
            "--precision",
            "f32",
            "--scenario",
        ])
        .arg(&scenario)
        .arg("--summary")
        .arg(&table)
        .output()
        .unwrap());
    let rows: Vec<serde_json::Value> =
        serde_json::from_str(&std::fs::read_to_string(&table).unwrap()).unwrap();
    assert_eq!(rows[0]["controller_precision"], "f32");
    for args in [
        &["run", "--precision", "f16", "--no-log"][..],
        &["sweep", "--precision", "double"][..],
    ] {
        let out = bin().args(args).output().unwrap();
        assert!(!out.status.success(), "{args:?}");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(
            stderr.contains("--precision") && stderr.contains("f32"),
            "{stderr}"
        );
    }
    // A scenario file names it too.
    let file = dir.join("f32.toml");
    std::fs::write(
        &file,
        "name = \"f32-file\"\nduration = 0.1\ncontroller_precision = \"f32\"\n",
    )
    .unwrap();
    let stdout = ok(bin()
        .arg("run")
        .arg(&file)
        .arg("--no-log")
        .output()
        .unwrap());
    assert!(
        stdout.contains("controller precision       f32"),
        "{stdout}"
    );
}

#[test]
fn sweep_prints_one_row_per_relaxation() {
    let dir = tmp_dir("sweep");
    let scenario = short_scenario(&dir);
    let table = dir.join("sweep.json");
    let stdout = ok(bin()
        .args(["sweep", "--relaxations", "0.5,1.0", "--scenario"])
        .arg(&scenario)
        .arg("--summary")
        .arg(&table)
        .arg("--plots")
        .arg(&dir)
        .output()
        .unwrap());
    assert!(stdout.contains("atan(c_y)"), "{stdout}");
    let rows: Vec<serde_json::Value> =
        serde_json::from_str(&std::fs::read_to_string(&table).unwrap()).unwrap();
    assert_eq!(rows.len(), 2);
    assert_eq!(rows[0]["relaxation"], 0.5);
    assert!((rows[0]["hover_roll_limit"].as_f64().unwrap() - 0.328708).abs() < 1e-6);
    assert!(dir.join("relaxation.png").is_file());
    assert_eq!(rows[0]["allocator"], "exact-boundary-redistribution");
    // `--allocator` pins another one (the paper's, for its `s = 1` row).
    let stdout = ok(bin()
        .args(["sweep", "--relaxations", "1.0", "--scenario"])
        .arg(&scenario)
        .args(["--allocator", "redistributed-pseudo-inverse", "--summary"])
        .arg(&table)
        .output()
        .unwrap());
    assert!(
        stdout.contains("allocator: redistributed-pseudo-inverse"),
        "{stdout}"
    );
    let rows: Vec<serde_json::Value> =
        serde_json::from_str(&std::fs::read_to_string(&table).unwrap()).unwrap();
    assert_eq!(rows[0]["allocator"], "redistributed-pseudo-inverse");
    let out = bin()
        .args(["sweep", "--relaxations", "1.0", "--allocator", "magic"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("allocator"));
    let out = bin()
        .args(["sweep", "--relaxations", "0.5,1.5"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("relaxation"));
}

#[test]
fn null_space_option_reports_its_margins_and_rejects_bad_objectives() {
    let dir = tmp_dir("null-space");
    let scenario = short_scenario(&dir);
    let summary = dir.join("ns.json");
    let stdout = ok(bin()
        .arg("run")
        .arg(&scenario)
        .args(["--null-space", "margin", "--no-log", "--summary"])
        .arg(&summary)
        .output()
        .unwrap());
    assert!(
        stdout.contains("null-space stage           margin"),
        "{stdout}"
    );
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&summary).unwrap()).unwrap();
    assert_eq!(json["null_space"], "margin");
    assert!(json["summary"]["null_space"]["periods"].as_u64().unwrap() > 0);
    for (spec, needle) in [
        ("sideways", "unknown null-space objective"),
        ("inward-tilt", "null_space.tilt"),
    ] {
        let out = bin()
            .arg("run")
            .arg(&scenario)
            .args(["--null-space", spec, "--no-log"])
            .output()
            .unwrap();
        assert!(!out.status.success(), "{spec}");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(stderr.contains(needle), "{spec}: {stderr}");
    }
}

/// A6-Inc loses agent 0 at 0.5 s in a hover the controller is not told of.
const A6_UNTOLD_LOSS: &str =
    "name = \"loss\"\nduration = 1.2\ninitial_position = [0.0, 0.0, 1.5]\n\
     [team]\npreset = \"a6-inc\"\n[reference]\nkind = \"hover\"\nposition = [0.0, 0.0, 1.5]\n\
     [[failures]]\nagent = 0\ntime = 0.5\nkind = \"no-thrust\"\ncontroller_informed = false\n";

#[test]
fn detect_option_reports_the_fault_and_needs_the_observer() {
    let dir = tmp_dir("detect");
    let path = dir.join("loss.toml");
    std::fs::write(&path, A6_UNTOLD_LOSS).unwrap();
    let summary = dir.join("summary.json");
    ok(bin()
        .args([
            "run",
            path.to_str().unwrap(),
            "--no-log",
            "--detect",
            "mask",
        ])
        .args(["--summary", summary.to_str().unwrap()])
        .output()
        .unwrap());
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&summary).unwrap()).unwrap();
    let fault = &json["summary"]["fault"];
    assert_eq!(fault["masked"]["agent"], 0, "{fault}");
    // Without the option the summary has no detector.
    ok(bin()
        .args(["run", path.to_str().unwrap(), "--no-log"])
        .args(["--summary", summary.to_str().unwrap()])
        .output()
        .unwrap());
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&summary).unwrap()).unwrap();
    assert!(json["summary"].get("fault").is_none(), "{json}");
    // The paper's law has no observer: refused, naming the field.
    let out = bin()
        .args(["run", path.to_str().unwrap(), "--no-log", "--law", "paper"])
        .args(["--detect", "report"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("fault_detection"), "{stderr}");
    assert!(stderr.contains("--law offset-free"), "{stderr}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Issue 60: `--reports` turns on the agents' own reports at the simulator's defaults; with
/// `--detect` the controller names a dead ESC that reports zero speed from its reports (two
/// reports after the first that shows it, 20 ms late), and one that falls silent too.
#[test]
fn reports_option_turns_on_the_agents_reports() {
    let dir = tmp_dir("reports");
    let path = dir.join("loss.toml");
    std::fs::write(&path, A6_UNTOLD_LOSS).unwrap();
    let summary = dir.join("summary.json");
    let masked = |reports: &[&str]| {
        ok(bin()
            .args(["run", path.to_str().unwrap(), "--no-log"])
            .args(["--detect", "mask"])
            .args(reports)
            .args(["--summary", summary.to_str().unwrap()])
            .output()
            .unwrap());
        let json: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&summary).unwrap()).unwrap();
        json["summary"]["fault"]["masked"].clone()
    };
    let zero = masked(&["--reports", "zero"]);
    assert_eq!(zero["agent"], 0, "{zero}");
    assert_eq!(zero["source"], "reports", "{zero}");
    let at = zero["time"].as_f64().unwrap();
    assert!(at > 0.5 && at < 0.55, "{zero}");
    // Without a value: the dead ESC falls silent, and the agent is named all the same.
    let silent = masked(&["--reports"]);
    assert_eq!(silent["agent"], 0, "{silent}");
    assert!(silent["time"].as_f64().unwrap() > at, "{silent} {zero}");
    let out = bin()
        .args([
            "run",
            path.to_str().unwrap(),
            "--no-log",
            "--reports",
            "loud",
        ])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("loud") && stderr.contains("--reports"),
        "{stderr}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// Issue 57: `--detect` on a scenario that flies the paper's law says which law it needs.
#[test]
fn detect_on_a_paper_law_scenario_names_the_law_it_needs() {
    let out = bin()
        .args(["run", "paper-tilt", "--no-log", "--detect", "mask"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("fault_detection") && stderr.contains("add `--law offset-free`"),
        "{stderr}"
    );
}

/// Issue 57: `catalogue --help` says what a row of `catalogue.csv` is (a team and an
/// allocator, over their flights); `plot` of a missing log leaves no figure directory; a FIFO
/// or device given to `plot` is refused before it is opened.
#[test]
fn catalogue_help_and_plot_inputs_checked_first() {
    let help = ok(bin().args(["catalogue", "--help"]).output().unwrap());
    assert!(help.contains("one row per team and allocator"), "{help}");
    assert!(!help.contains("one row per flight"), "{help}");
    let dir = tmp_dir("plot-missing");
    let figures = dir.join("p");
    let out = bin()
        .arg("plot")
        .arg(dir.join("missing.mcap"))
        .arg("--out")
        .arg(&figures)
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(
        !figures.exists(),
        "plot made its output directory for a missing log"
    );
    if Path::new("/dev/zero").exists() {
        let out = bin()
            .args(["plot", "/dev/zero", "--out"])
            .arg(&figures)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(
            !out.status.success() && stderr.contains("not a regular file"),
            "{stderr}"
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
