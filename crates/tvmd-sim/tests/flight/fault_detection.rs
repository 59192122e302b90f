//! The agent fault detector in the loop (issue 47): an agent loss the controller is not told
//! of is detected, isolated and masked by the controller itself, the simulator takes the mask
//! as its own (the hover classification and the landing of `failure_response` run as for an
//! informed failure), and the detector's report reaches the summary and the `/fault` channel.

use mcap::MessageStream;
use tvmd_scenario::{FaultDetectionConfig, FaultResponseConfig, LawConfig, OnHoverLoss, Scenario};
use tvmd_sim::runner::run_scenario;
use tvmd_sim::sim::RunResult;

/// `name` with the offset-free law, its failures not told to the controller, and detection
/// with `response` (none for `None`).
fn uninformed(name: &str, response: Option<FaultResponseConfig>) -> Scenario {
    let mut s = Scenario::builtin(name).unwrap();
    s.law = LawConfig::default();
    for f in &mut s.failures {
        f.controller_informed = false;
    }
    s.fault_detection = response.map(FaultDetectionConfig::with_response);
    s
}

/// The largest position error from `from` on.
fn peak_after(r: &RunResult, from: f64) -> f64 {
    r.samples
        .iter()
        .filter(|s| s.t >= from)
        .map(|s| {
            (0..3)
                .map(|i| (s.position[i] - s.reference_position[i]).powi(2))
                .sum::<f64>()
                .sqrt()
        })
        .fold(0.0, f64::max)
}

#[test]
fn an_uninformed_a6_loss_is_masked_by_the_controller_and_hover_is_held() {
    let s = uninformed("a6-agent-failure", Some(FaultResponseConfig::Mask));
    let t_f = s.failures[0].time;
    let r = run_scenario(&s, None, None).unwrap();
    let fault = r.summary.fault.expect("the detector reports");
    assert!(fault.first_alarm.is_some_and(|t| t >= t_f), "{fault:?}");
    let masked = fault.masked.expect("the loss is masked");
    assert_eq!(masked.agent, 0);
    // The observer's bandwidth (10 rad/s) and the persistence bound the delay; the issue's
    // worst case is 0.5 s.
    assert!(masked.time > t_f && masked.time - t_f <= 0.5, "{masked:?}");
    // The simulator classifies the mask the controller set (A6 minus one is hover-capable).
    let c = &r.summary.hover_classifications;
    assert_eq!(c.len(), 1, "{c:?}");
    assert!(
        c[0].capable && (c[0].time - masked.time).abs() < 1e-9,
        "{c:?}"
    );
    // Masking helps: the same flight without detection (the loss stays unknown, the observer
    // alone compensates it) errs more after the failure.
    let blind = run_scenario(&uninformed("a6-agent-failure", None), None, None).unwrap();
    assert!(blind.summary.fault.is_none());
    assert!(blind.summary.hover_classifications.is_empty());
    let (with, without) = (peak_after(&r, t_f), peak_after(&blind, t_f));
    assert!(
        with < without,
        "peak error {with} with detection, {without} without"
    );
    assert!(r.summary.verdict.success, "{:?}", r.summary.verdict);
}

#[test]
fn report_only_keeps_the_mask_to_the_caller() {
    let mut s = uninformed("a6-agent-failure", Some(FaultResponseConfig::Report));
    s.duration = 6.5;
    let t_f = s.failures[0].time;
    let r = run_scenario(&s, None, None).unwrap();
    let fault = r.summary.fault.unwrap();
    let confirmed = fault.first_confirmed.expect("confirmed");
    assert_eq!(confirmed.agent, 0);
    assert!(
        confirmed.time > t_f && confirmed.time - t_f <= 0.5,
        "{fault:?}"
    );
    // A loss keeps its residual while the agent stays commanded: confirmed to the end.
    assert!(fault.confirmed_ticks > 50, "{fault:?}");
    assert!(fault.masked.is_none() && r.summary.hover_classifications.is_empty());
}

#[test]
fn an_uninformed_a4_loss_starts_the_landing_on_hover_loss() {
    let mut s = uninformed("agent-failure", Some(FaultResponseConfig::Mask));
    s.failure_response.on_hover_loss = OnHoverLoss::Land;
    let t_f = s.failures[0].time;
    let r = run_scenario(&s, None, None).unwrap();
    let masked = r.summary.fault.and_then(|f| f.masked).expect("masked");
    assert_eq!(masked.agent, 0);
    assert!(masked.time - t_f <= 0.5);
    let c = &r.summary.hover_classifications;
    assert_eq!(c.len(), 1, "{c:?}");
    assert!(!c[0].capable && c[0].landing, "{c:?}");
    // On the ground at the end (the rest height is z = 0).
    assert!(r.summary.final_position[2] < 0.05, "{:?}", r.summary);
}

#[test]
fn the_detector_is_logged_on_the_fault_channel() {
    let mut s = uninformed("a6-agent-failure", Some(FaultResponseConfig::Mask));
    s.duration = 5.6;
    let path = std::env::temp_dir().join(format!("tvmd-fault-{}.mcap", std::process::id()));
    run_scenario(&s, Some(&path), None).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    let _ = std::fs::remove_file(&path);
    let fault: Vec<tvmd_log::proto::Fault> = MessageStream::new(&bytes)
        .unwrap()
        .map(|m| m.unwrap())
        .filter(|m| m.channel.topic == "/fault")
        .map(|m| prost::Message::decode(&*m.data).unwrap())
        .collect();
    // One report per controller period once the team is airborne.
    assert!(fault.len() > 300, "{}", fault.len());
    assert!(fault.iter().all(|f| f.threshold == fault[0].threshold));
    let masked: Vec<_> = fault.iter().filter(|f| f.masked.is_some()).collect();
    assert_eq!(masked.len(), 1, "{masked:?}");
    assert_eq!((masked[0].masked, masked[0].agent), (Some(0), Some(0)));
    assert_eq!(masked[0].verdict, "confirmed");
    assert_eq!(masked[0].kind, "loss");
    assert!(masked[0].statistic > masked[0].threshold);
}

#[test]
fn without_detection_nothing_is_reported_and_detection_needs_the_observer() {
    let r = run_scenario(&Scenario::builtin("a6-agent-failure").unwrap(), None, None).unwrap();
    assert!(r.summary.fault.is_none());
    let mut paper = Scenario::builtin("a6-agent-failure").unwrap();
    paper.fault_detection = Some(FaultDetectionConfig::default());
    assert!(paper.validate().is_err());
}

#[test]
fn the_fault_scenarios_load_and_a_team_override_flies_them() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenarios/faults");
    let mut names: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    names.sort();
    // Three faults, two phases.
    assert_eq!(names.len(), 6, "{names:?}");
    for path in &names {
        let s = Scenario::from_file(path).unwrap();
        let d = s.fault_detection.expect("detection on");
        assert_eq!(d.response, FaultResponseConfig::Mask, "{path:?}");
        assert!(
            s.failures.iter().all(|f| !f.controller_informed),
            "{path:?}"
        );
    }
    let mut s = Scenario::from_file(dir.join("loss-hover.toml")).unwrap();
    s.team.preset = Some("a6-inc".into());
    s.validate().unwrap();
    let r = run_scenario(&s, None, None).unwrap();
    let masked = r.summary.fault.and_then(|f| f.masked).expect("masked");
    assert_eq!(masked.agent, 0);
}
