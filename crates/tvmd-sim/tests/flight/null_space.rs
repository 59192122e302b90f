//! The scenario's null-space stage (`null_space`): parsed from its string and table forms,
//! round-tripped through TOML, refused with a named field when wrong, and in the loop on the
//! saturated `s = 1` paper-tilt flight (both precisions): the allocation error is unchanged (the
//! stage moves forces inside `null(M)` only), the mean smallest margin to the admissible boundary
//! rises and fewer periods end with an agent on a boundary.

use tvmd_scenario::ScenarioError;
use tvmd_scenario::{NullSpaceKind, Precision, Scenario};
use tvmd_sim::runner::run_scenario;

fn field(text: &str) -> String {
    match Scenario::from_toml_str(text) {
        Err(ScenarioError::InvalidScenario { field, .. }) => field,
        other => panic!("{text}: {other:?}"),
    }
}

#[test]
fn both_forms_parse_round_trip_and_bad_ones_name_the_field() {
    let s = Scenario::from_toml_str("null_space = \"margin\"\n").unwrap();
    assert_eq!(s.null_space.unwrap().objective, NullSpaceKind::Margin);
    let text = "null_space = { objective = \"inward-tilt\", tilt = 0.12, iterations = 5 }\n";
    let t = Scenario::from_toml_str(text).unwrap();
    let n = t.null_space.unwrap();
    assert_eq!(
        (n.objective, n.tilt, n.iterations),
        (NullSpaceKind::InwardTilt, Some(0.12), 5)
    );
    let back = Scenario::from_toml_str(&t.to_toml_string().unwrap()).unwrap();
    assert_eq!(back, t);
    assert!(Scenario::default().null_space.is_none());
    assert_eq!(field("null_space = \"inward-tilt\"\n"), "null_space.tilt");
    assert_eq!(
        field("null_space = \"inward-tilt=1.6\"\n"),
        "null_space.tilt"
    );
    assert_eq!(
        field("null_space = { objective = \"margin\", tilt = 0.1 }\n"),
        "null_space.tilt"
    );
    assert_eq!(
        field("null_space = { objective = \"margin\", iterations = 65 }\n"),
        "null_space.iterations"
    );
    // An unknown objective is a parse error naming the key.
    let e = Scenario::from_toml_str("null_space = \"sideways\"\n").unwrap_err();
    assert!(e.to_string().contains("null_space"), "{e}");
}

fn saturated_flight(precision: Precision) {
    let mut plain = Scenario::builtin("paper-tilt").unwrap();
    plain.relaxation = 1.0;
    plain.controller_precision = precision;
    // Through the end of the tilt (4-10 s), where the allocator saturates.
    plain.duration = 10.5;
    let mut staged = plain.clone();
    staged.null_space = Some("margin".parse().unwrap());
    let a = run_scenario(&plain, None, None).unwrap().summary;
    let b = run_scenario(&staged, None, None).unwrap().summary;
    assert!(a.null_space.is_none());
    let ns = b.null_space.expect("the stage ran");
    assert!(ns.periods >= 1050 && ns.raised_periods > 100, "{ns:?}");
    assert!(ns.mean_margin_after > ns.mean_margin_before, "{ns:?}");
    // Some periods have no null-space direction that frees every agent, so the flight's lowest
    // margin stays about zero; it never falls.
    assert!(ns.min_margin_after >= ns.min_margin_before, "{ns:?}");
    // Fewer periods end with an agent on a boundary (the whole 16 s flight, measured: 276 -> 26 in f64, 70 in f32).
    assert!(
        b.saturated_periods < a.saturated_periods,
        "{} {}",
        a.saturated_periods,
        b.saturated_periods
    );
    let (ea, eb) = (a.max_e_f.unwrap(), b.max_e_f.unwrap());
    assert!((ea - eb).abs() <= 1e-4 * ea.max(1.0), "{ea} {eb}");
    assert_eq!(b.cycle_errors, 0);
}

#[test]
fn the_margin_stage_on_the_saturated_flight_in_f64() {
    saturated_flight(Precision::F64);
}

#[test]
fn the_margin_stage_on_the_saturated_flight_in_f32() {
    saturated_flight(Precision::F32);
}
