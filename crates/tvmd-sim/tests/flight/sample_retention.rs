//! Sample retention: the summary and the paper's metrics fold every controller tick, so a run
//! that keeps fewer samples (or none) reports the same numbers; a run that keeps none is not
//! bounded by the memory its samples would take.

use tvmd_scenario::Scenario;
use tvmd_sim::runner::{fly, Flight, RunSpec};
use tvmd_sim::sim::{RunResult, SampleRetention, SimOptions, Simulation, MAX_KEPT_SAMPLES};

fn flown(samples: SampleRetention) -> RunResult {
    let scenario = Scenario::builtin("paper-tilt").unwrap();
    let mut spec = RunSpec::on_target(scenario, None, None, None).unwrap();
    spec.samples = samples;
    let Flight { result, error } = fly(&spec, None, None).unwrap();
    assert!(error.is_none(), "{error:?}");
    result
}

/// The summary as JSON without its wall-clock fields (which differ run to run).
fn summary_json(r: &RunResult) -> serde_json::Value {
    let mut s = r.summary.clone();
    s.wall_time = 0.0;
    s.real_time_factor = 0.0;
    serde_json::to_value(s).unwrap()
}

#[test]
fn every_retention_reports_the_same_summary_and_paper_metrics() {
    let all = flown(SampleRetention::All);
    let seven = flown(SampleRetention::AtMost(7));
    let none = flown(SampleRetention::None);
    let ticks = all.summary.controller_calls;
    assert_eq!(all.samples.len(), ticks);
    assert_eq!(all.sample_stride, 1);
    assert!(none.samples.is_empty());

    // 1601 ticks into 7 samples: every 256th tick (the smallest power of two that fits).
    let stride = seven.sample_stride;
    assert!(stride.is_power_of_two() && ticks.div_ceil(stride) <= 7);
    assert!(
        ticks.div_ceil(stride / 2) > 7,
        "stride {stride} is not the smallest"
    );
    let every_stride: Vec<_> = all.samples.iter().step_by(stride).cloned().collect();
    assert_eq!(seven.samples, every_stride);

    let reference = summary_json(&all);
    assert_eq!(summary_json(&seven), reference);
    assert_eq!(summary_json(&none), reference);
    let paper = serde_json::to_value(&all.paper).unwrap();
    assert_eq!(serde_json::to_value(&seven.paper).unwrap(), paper);
    assert_eq!(serde_json::to_value(&none.paper).unwrap(), paper);
    // The metrics are not vacuous: the paper's tilt saturates and is settled by 12 s.
    assert!(all.summary.max_e_f.is_some_and(|e| e > 0.0));
    assert!(all.summary.horizontal_error_at_12s.is_some());
}

#[test]
fn only_kept_samples_bound_a_run_length() {
    // Longer than MAX_KEPT_SAMPLES controller ticks (0.01 s each).
    let s = Scenario {
        duration: (MAX_KEPT_SAMPLES as f64 + 10.0) * 0.01,
        ..Scenario::builtin("paper-tilt").unwrap()
    };
    let options = |samples| SimOptions { samples };
    let Err(e) = Simulation::with_options(&s, options(SampleRetention::All)) else {
        panic!("a run that keeps every one of its ticks is bounded");
    };
    let message = e.to_string();
    assert!(
        message.contains("duration") && message.contains("max_samples"),
        "{message}"
    );
    assert!(Simulation::with_options(&s, options(SampleRetention::None)).is_ok());
    assert!(Simulation::with_options(&s, options(SampleRetention::AtMost(1000))).is_ok());
}
