//! The agents' own reports in the controller's fault detection, closed loop on the RK4 plant
//! (`flight/mod.rs`): A4-Inc hovers under model error and a constant disturbance, agent 2 fails
//! at 2 s, and each agent reports every period (100 Hz) what it did two periods earlier (20 ms
//! latency). `cargo test -p tvmd-core --test fault_reports -- --nocapture` prints the delays.

mod flight;

use flight::{Body, Truth};
use tvmd_core::nalgebra::Vector3;
use tvmd_core::team::presets;
use tvmd_core::{
    AgentCommand, AgentReading, Controller, ControllerSettings, FailureMask, FaultDetection,
    FaultKind, FaultResponse, FaultSource, FaultVerdict, RedistributedPseudoInverse, Reference,
    ReportError, TeamConfig,
};

type C = Controller<f64, 4, RedistributedPseudoInverse>;

const CUT: f64 = 2.0;
const LOST: usize = 2;

fn hover() -> Vector3<f64> {
    Vector3::new(0.0, 0.0, 1.5)
}

fn truth(team: &TeamConfig<f64, 4>) -> Truth {
    Truth {
        mass: team.mass() * 1.03,
        inertia: team.inertia() * 1.04,
        gravity: 9.81,
        force: Vector3::new(0.25, -0.15, -0.3),
        torque: Vector3::new(0.04, -0.03, 0.02),
    }
}

fn detecting(response: FaultResponse) -> C {
    let team = presets::a4_inc::<f64, 4>().unwrap();
    let settings = ControllerSettings {
        fault_detection: Some(FaultDetection::recommended(response)),
        ..ControllerSettings::offset_free_law()
    };
    Controller::new(team, settings, RedistributedPseudoInverse).unwrap()
}

/// How the failed agent reports after the cut.
#[derive(Clone, Copy, PartialEq)]
enum After {
    /// Zero rotor speed (a dead ESC that still talks).
    Zero,
    /// Nothing (its link is gone; its rotor keeps the last command).
    Silent,
    /// The command it received (a lying sensor), its rotor dead.
    Lying,
    /// No reports at all, from anyone (the residual only).
    NoReports,
}

/// What one flight showed: when the controller first masked an agent, which, the verdict
/// then, and the outputs (for comparisons).
struct Flown {
    masked: Option<(f64, usize)>,
    verdict: Option<(FaultVerdict<f64>, FaultSource)>,
    commands: Vec<[AgentCommand<f64>; 4]>,
}

fn fly(c: &mut C, after: After, seconds: f64) -> Flown {
    let team = *c.team();
    let truth = truth(&team);
    let blocks = *team.effectiveness(&FailureMask::none()).blocks();
    let dt = c.settings().period;
    let mut body = Body::at(hover());
    let mut sent: Vec<[AgentCommand<f64>; 4]> = vec![];
    let mut flown = Flown {
        masked: None,
        verdict: None,
        commands: vec![],
    };
    for k in 0..(seconds / dt).round() as usize {
        let t = k as f64 * dt;
        let failed = t >= CUT;
        // The report measured two periods ago of the commands then in force.
        if after != After::NoReports && sent.len() >= 2 {
            let held = sent[sent.len() - 2];
            let measured_failed = t - 2.0 * dt >= CUT;
            for (i, cmd) in held.iter().enumerate() {
                let thrust = match (i == LOST && measured_failed, after) {
                    (true, After::Zero) => 0.0,
                    (true, After::Silent) => continue,
                    _ => cmd.thrust,
                };
                let r = AgentReading::new(thrust, cmd.eta_x, cmd.eta_y, 2.0 * dt).unwrap();
                c.set_report(i, r).unwrap();
            }
        }
        let out = c.step(&body.state(), &Reference::hover(hover())).unwrap();
        sent.push(out.commands);
        flown.commands.push(out.commands);
        if let (None, Some(m)) = (flown.masked, c.fault_masking()) {
            flown.masked = Some((t, m.agent));
            flown.verdict = c.fault_report().map(|r| (r.verdict, r.source));
        }
        let mut u = out.allocation.wrench;
        // A dead rotor delivers nothing; a silent agent keeps flying its command.
        if failed && after != After::Silent {
            u -= blocks[LOST].get().unwrap() * out.allocation.forces[LOST];
        }
        for _ in 0..10 {
            body = flight::rk4(&body, &truth, &u, dt / 10.0);
        }
    }
    flown
}

#[test]
fn a_dead_rotor_reported_at_zero_speed_is_masked_from_the_reports_within_50_ms() {
    let mut c = detecting(FaultResponse::Mask);
    let flown = fly(&mut c, After::Zero, 3.0);
    let (t, agent) = flown.masked.unwrap();
    println!(
        "zero-speed report: masked agent {agent} {:.3} s after the cut",
        t - CUT
    );
    assert_eq!(agent, LOST);
    // Latency 20 ms, then two reports: the third period after the cut's first report.
    assert!(t >= CUT && t - CUT <= 0.05, "masked at {t}");
    assert_eq!(
        flown.verdict,
        Some((
            FaultVerdict::Confirmed {
                agent: LOST,
                kind: FaultKind::Loss
            },
            FaultSource::Reports
        ))
    );
}

#[test]
fn a_silent_agent_is_a_link_loss_after_the_timeout_and_is_masked() {
    let mut c = detecting(FaultResponse::Mask);
    let flown = fly(&mut c, After::Silent, 3.0);
    let (t, agent) = flown.masked.unwrap();
    println!(
        "silent agent: masked {agent} {:.3} s after the cut",
        t - CUT
    );
    assert_eq!(agent, LOST);
    let timeout = FaultDetection::<f64>::recommended(FaultResponse::Mask)
        .report_check()
        .link_timeout();
    // Its last report was measured 10 ms before the cut (20 ms old then).
    assert!(
        t - CUT >= timeout - 0.03 && t - CUT <= timeout + 0.01,
        "{t}"
    );
    assert!(matches!(
        flown.verdict,
        Some((
            FaultVerdict::Confirmed {
                kind: FaultKind::LinkLoss,
                ..
            },
            FaultSource::Reports
        ))
    ));
}

#[test]
fn a_lying_report_is_caught_by_the_residual() {
    let mut c = detecting(FaultResponse::Mask);
    let flown = fly(&mut c, After::Lying, 3.0);
    let (t, agent) = flown.masked.unwrap();
    println!(
        "lying report: masked {agent} {:.3} s after the cut",
        t - CUT
    );
    assert_eq!(agent, LOST);
    assert!(t - CUT <= 0.5, "{t}");
    assert!(matches!(
        flown.verdict,
        Some((FaultVerdict::Confirmed { .. }, FaultSource::Residual))
    ));
    // Without reports the residual names it alike (the reports that agree change nothing).
    let mut alone = detecting(FaultResponse::Mask);
    let without = fly(&mut alone, After::NoReports, 3.0);
    assert_eq!(without.masked, flown.masked);
    assert_eq!(without.commands, flown.commands);
}

#[test]
fn bad_reports_are_typed_errors_and_detection_off_refuses_them() {
    let mut c = detecting(FaultResponse::Report);
    let r = AgentReading::new(5.0, 0.0, 0.0, 0.02).unwrap();
    assert_eq!(
        c.set_report(4, r),
        Err(ReportError::Agent { agent: 4, len: 4 })
    );
    assert!(matches!(
        c.set_report_speed(0, f64::NAN, 0.0, 0.0, 0.0),
        Err(ReportError::NonFinite { quantity: "speed" })
    ));
    assert!(matches!(
        c.set_report_speed(0, 0.5, 0.0, 0.0, -1.0),
        Err(ReportError::Negative {
            quantity: "age",
            ..
        })
    ));
    assert!(c.report(0).is_none());
    c.set_report(0, r).unwrap();
    assert_eq!(c.report(0), Some(r));
    // A step ages it; a reset forgets it.
    c.step(
        &tvmd_core::RigidState::at_rest(hover()),
        &Reference::hover(hover()),
    )
    .unwrap();
    let aged = c.report(0).unwrap().age();
    assert!((aged - 0.03).abs() < 1e-12, "{aged}");
    c.reset();
    assert!(c.report(0).is_none());
    let team = presets::a4_inc::<f64, 4>().unwrap();
    let mut off = C::new(
        team,
        ControllerSettings::offset_free_law(),
        RedistributedPseudoInverse,
    )
    .unwrap();
    assert_eq!(off.set_report(0, r), Err(ReportError::DetectionOff));
}
