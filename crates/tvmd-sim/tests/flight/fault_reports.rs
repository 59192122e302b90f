//! The agents' own reports in the controller's fault detection (issue 60, items 3 and 4): with
//! `[reports]` and `[fault_detection]` the simulator passes each agent's newest report to the
//! controller, which names a loss from them faster than the residual can, and the summary and
//! the `/fault` channel say which check named it.

use mcap::MessageStream;
use tvmd_scenario::{
    AgentReports, DeadEsc, FaultDetectionConfig, FaultResponseConfig, LawConfig, Scenario,
};
use tvmd_sim::diagnostics::{FaultKindName, FaultSourceName};
use tvmd_sim::runner::run_scenario;

/// `a6-agent-failure` with the offset-free law, its failure not told to the controller,
/// detection masking, and reports whose dead ESC says `dead_esc`.
fn uninformed_with_reports(dead_esc: Option<DeadEsc>) -> Scenario {
    let mut s = Scenario::builtin("a6-agent-failure").unwrap();
    s.law = LawConfig::default();
    for f in &mut s.failures {
        f.controller_informed = false;
    }
    s.fault_detection = Some(FaultDetectionConfig::with_response(
        FaultResponseConfig::Mask,
    ));
    s.reports = dead_esc.map(|dead_esc| AgentReports {
        dead_esc,
        ..AgentReports::default()
    });
    s
}

#[test]
fn a_dead_esc_reporting_zero_is_masked_from_the_reports_within_50_ms_of_its_first_report() {
    let s = uninformed_with_reports(Some(DeadEsc::Zero));
    let t_f = s.failures[0].time;
    let r = run_scenario(&s, None, None).unwrap();
    let fault = r.summary.fault.expect("the detector reports");
    let masked = fault.masked.expect("masked");
    assert_eq!(masked.agent, 0);
    assert_eq!(masked.source, Some(FaultSourceName::Reports), "{fault:?}");
    assert_eq!(masked.kind, Some(FaultKindName::Loss), "{fault:?}");
    // The first report measured after the failure (100 Hz) arrives 20 ms later; two reports.
    println!("masked {:.3} s after the failure", masked.time - t_f);
    assert!(
        masked.time > t_f && masked.time - t_f <= 0.01 + 0.05,
        "{masked:?}"
    );
    // Without reports the residual names it later.
    let alone = run_scenario(&uninformed_with_reports(None), None, None).unwrap();
    let later = alone.summary.fault.and_then(|f| f.masked).expect("masked");
    assert_eq!(later.source, Some(FaultSourceName::Residual));
    assert!(later.time > masked.time, "{later:?} vs {masked:?}");
}

#[test]
fn a_silent_dead_esc_is_a_link_loss_and_the_fault_channel_names_the_reports() {
    let mut s = uninformed_with_reports(Some(DeadEsc::Silent));
    s.duration = 5.6;
    let t_f = s.failures[0].time;
    let path = std::env::temp_dir().join(format!("tvmd-fault-reports-{}.mcap", std::process::id()));
    let r = run_scenario(&s, Some(&path), None).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    let _ = std::fs::remove_file(&path);
    let masked = r.summary.fault.and_then(|f| f.masked).expect("masked");
    assert_eq!(masked.agent, 0);
    // Whichever check names it first: the link timeout (0.1 s) or the residual.
    println!(
        "masked {:.3} s after the failure by {:?} ({:?})",
        masked.time - t_f,
        masked.source,
        masked.kind
    );
    assert!(masked.time - t_f <= 0.15, "{masked:?}");
    let fault: Vec<tvmd_log::proto::Fault> = MessageStream::new(&bytes)
        .unwrap()
        .map(|m| m.unwrap())
        .filter(|m| m.channel.topic == "/fault")
        .map(|m| prost::Message::decode(&*m.data).unwrap())
        .collect();
    let named: Vec<_> = fault.iter().filter(|f| f.masked.is_some()).collect();
    assert_eq!(named.len(), 1, "{named:?}");
    let expected = match masked.source {
        Some(FaultSourceName::Reports) => ("reports", "link-loss"),
        _ => ("residual", "loss"),
    };
    assert_eq!((named[0].source.as_str(), named[0].kind.as_str()), expected);
    // Periods that name no agent name no source.
    assert!(fault
        .iter()
        .filter(|f| f.agent.is_none())
        .all(|f| f.source.is_empty()));
}
