//! The coarse-step mode for batch studies (`physics.dt = 0.002`, half the physics work) and four
//! solver iterations instead of the default one: `paper-tilt`'s reproduction metrics stay
//! within the tolerances README.md and BENCHMARKS.md state against the default 1 ms, one
//! iteration flight, and the two flights differ little at every controller tick.

use tvmd_scenario::Scenario;
use tvmd_sim::runner::run_scenario;
use tvmd_sim::sim::{FlightDifference, RunResult};

/// `paper-tilt` (the paper's manoeuvre with the paper's law) with the TOML `toml` added.
fn fly(toml: &str) -> RunResult {
    let toml = format!("law = \"paper\"\n{toml}");
    run_scenario(&Scenario::from_toml_str(&toml).unwrap(), None, None).unwrap()
}

/// The stated tolerances (about 4x the differences measured with rapier 0.36.1).
fn assert_close(reference: &RunResult, other: &RunResult, what: &str) {
    let (a, b) = (&reference.paper, &other.paper);
    let d = |x: Option<f64>, y: Option<f64>| (x.unwrap() - y.unwrap()).abs();
    let h4 = d(a.horizontal_error_at_4s, b.horizontal_error_at_4s);
    let h12 = d(a.horizontal_error_at_12s, b.horizontal_error_at_12s);
    let roll = d(a.max_planned_roll, b.max_planned_roll);
    let settling = d(a.stage_b_attitude_settling, b.stage_b_attitude_settling);
    eprintln!("{what}: horizontal error at 4 s {h4:.2e} m, at 12 s {h12:.2e} m, planned roll {roll:.2e} rad, settling {settling:.2e} s");
    assert!(h4 < 2e-4 && h12 < 2e-4, "{what}: {h4:e} {h12:e}");
    assert!(roll < 2e-5, "{what}: {roll:e}");
    assert!(settling < 0.015, "{what}: {settling}");
    assert!((reference.summary.max_roll - other.summary.max_roll).abs() < 2e-5);
    let (ra, rb) = (a.max_v_x_rise.unwrap(), b.max_v_x_rise.unwrap());
    assert!(
        (ra.from - rb.from).abs() < 0.015 && (ra.to - rb.to).abs() < 0.015,
        "{what}"
    );
    assert!(
        (ra.from_value - rb.from_value).abs() < 2e-5 && (ra.to_value - rb.to_value).abs() < 2e-5,
        "{what}: {ra:?} {rb:?}"
    );
    let diff = FlightDifference::between(&reference.samples, &other.samples).unwrap();
    eprintln!("{what}: {diff:?}");
    assert_eq!(diff.samples, 1600);
    assert!(diff.position < 5e-3, "{what}: {diff:?}");
    assert!(diff.attitude < 1e-3, "{what}: {diff:?}");
}

#[test]
fn coarse_steps_and_more_iterations_keep_the_paper_metrics() {
    let fine = fly("");
    assert_eq!(fine.summary.physics_steps, 16_000);
    let coarse = fly("[physics]\ndt = 0.002\n");
    assert_eq!(coarse.summary.physics_steps, 8_000);
    assert_close(&fine, &coarse, "dt = 2 ms");
    let iterations = fly("[physics]\nsolver_iterations = 4\n");
    assert_close(&fine, &iterations, "4 solver iterations");
}
