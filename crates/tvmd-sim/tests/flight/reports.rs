//! The agents' own reports in flight (issue 60, item 2): their age and noise as stated, and what
//! a faulty agent reports: a dead ESC nothing (or zero), a damaged propeller its full speed, a
//! stuck servo its stuck angle, a silent link nothing, a lying agent its command.

use tvmd_plant::actuators::FailureKind;
use tvmd_scenario::{AgentReports, DeadEsc, Failure, Scenario};
use tvmd_sim::control::AnyTvmdController;
use tvmd_sim::sim::reports::AgentReport;
use tvmd_sim::sim::Simulation;
use tvmd_sim::FlightController;

/// `(t, reports, actual outputs)` of every tick of `s` flown by its controller.
type Tick = (
    f64,
    Vec<Option<AgentReport>>,
    Vec<tvmd_plant::actuators::ActuatorCommand>,
);

fn fly(s: &Scenario) -> Vec<Tick> {
    let mut sim = Simulation::new(s).unwrap();
    let mut controller = AnyTvmdController::from_scenario(s).unwrap();
    let mut ticks = Vec::new();
    while !sim.is_finished() {
        let o = sim.observe().unwrap().clone();
        let out = controller.step(&o.input()).unwrap();
        sim.step_output(out).unwrap();
        ticks.push((o.t, o.reports, sim.samples().last().unwrap().actual.clone()));
    }
    ticks
}

fn hover(failure: Option<(usize, FailureKind)>, reports: AgentReports) -> Scenario {
    let mut s = Scenario::builtin("hover").unwrap();
    s.team.preset = Some("a6-inc".into());
    s.duration = 3.0;
    s.reports = Some(reports);
    s.failures = failure
        .map(|(agent, kind)| Failure {
            agent,
            time: 1.0,
            kind,
            controller_informed: false,
            informed_after: 0.0,
        })
        .into_iter()
        .collect();
    s
}

/// The tick at `t` or just after.
fn at(ticks: &[Tick], t: f64) -> &Tick {
    ticks.iter().find(|k| k.0 >= t - 1e-9).unwrap()
}

#[test]
fn reports_arrive_late_by_the_latency_with_the_stated_noise() {
    let ticks = fly(&hover(None, AgentReports::default()));
    assert!(
        ticks[0].1.iter().all(Option::is_none),
        "nothing arrived at t = 0"
    );
    for (t, reports, _) in ticks.iter().filter(|k| k.0 > 0.5) {
        assert_eq!(reports.len(), 6);
        for r in reports {
            let r = r.unwrap();
            // 20 ms late, sampled at 100 Hz: measured between 20 and 30 ms ago.
            assert!(
                r.age >= 0.02 - 1e-9 && r.age <= 0.03 + 1e-9,
                "t = {t}: {r:?}"
            );
        }
    }
    // Against the hover's steady thrusts (the team barely moves): noise of the stated size.
    let late = at(&ticks, 2.0);
    for (r, a) in late.1.iter().zip(&late.2) {
        let r = r.unwrap();
        assert!(
            (r.thrust - a.thrust).abs() < 5.0 * 0.05 + 0.05,
            "{r:?} vs {a:?}"
        );
        assert!(
            (r.eta_x - a.eta_x).abs() < 5.0 * 0.005 + 0.01,
            "{r:?} vs {a:?}"
        );
    }
    let spread = {
        let x: Vec<f64> = ticks
            .iter()
            .filter(|k| k.0 > 1.0)
            .map(|k| k.1[0].unwrap().thrust - k.2[0].thrust)
            .collect();
        let mean = x.iter().sum::<f64>() / x.len() as f64;
        (x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / x.len() as f64).sqrt()
    };
    assert!(spread > 0.03 && spread < 0.08, "thrust noise {spread}");
}

#[test]
fn a_faulty_agent_reports_what_a_real_one_would() {
    let quiet = AgentReports {
        thrust_noise: 0.0,
        angle_noise: 0.0,
        ..AgentReports::default()
    };
    // A dead ESC: silent (the newest report ages), or zero speed.
    let ticks = fly(&hover(Some((1, FailureKind::NoThrust)), quiet.clone()));
    let r = at(&ticks, 2.0).1[1].unwrap();
    assert!(r.age > 0.9, "{r:?}");
    let zero = AgentReports {
        dead_esc: DeadEsc::Zero,
        ..quiet.clone()
    };
    let ticks = fly(&hover(Some((1, FailureKind::NoThrust)), zero));
    let r = at(&ticks, 2.0).1[1].unwrap();
    assert!(r.thrust == 0.0 && r.age < 0.031, "{r:?}");
    // A damaged propeller: the rotor spins as commanded, so the report shows twice the thrust.
    let ticks = fly(&hover(Some((2, FailureKind::HalfThrust)), quiet.clone()));
    let before = at(&ticks, 2.0);
    let r = before.1[2].unwrap();
    let actual = at(&ticks, 2.0 - r.age).2[2].thrust;
    assert!(
        (r.thrust - 2.0 * actual).abs() < 0.05 * actual,
        "{r:?}, actual {actual}"
    );
    // A stuck servo reports its stuck angle; a silent link, nothing.
    let ticks = fly(&hover(Some((3, FailureKind::StuckGimbal)), quiet.clone()));
    let stuck = at(&ticks, 1.0).2[3].eta_x;
    assert_eq!(at(&ticks, 2.5).2[3].eta_x, stuck);
    assert!((at(&ticks, 2.5).1[3].unwrap().eta_x - stuck).abs() < 1e-12);
    let ticks = fly(&hover(Some((4, FailureKind::LinkLoss)), quiet.clone()));
    assert!(at(&ticks, 2.5).1[4].unwrap().age > 1.4);
    assert!(at(&ticks, 2.5).1[0].unwrap().age < 0.031);
    // A lying agent says it does its command while its rotor is dead.
    let lying = AgentReports {
        lying: vec![1],
        ..quiet
    };
    let ticks = fly(&hover(Some((1, FailureKind::NoThrust)), lying));
    let k = at(&ticks, 2.0);
    let r = k.1[1].unwrap();
    assert_eq!(k.2[1].thrust, 0.0);
    assert!(r.thrust > 1.0 && r.age < 0.031, "{r:?}");
}

#[test]
fn no_reports_section_means_no_reports() {
    let mut s = Scenario::builtin("hover").unwrap();
    s.duration = 0.05;
    let mut sim = Simulation::new(&s).unwrap();
    assert!(sim.observe().unwrap().reports.is_empty());
}

/// The reports a healthy agent would have sent (`Simulation::healthy_reports`): the same as
/// the reports for an agent that has not failed, bit for bit (the same actuators, commands and
/// noise); for a failed one they differ by the failure's effect alone.
#[test]
fn healthy_reports_differ_by_the_failure_alone() {
    let zero = AgentReports {
        dead_esc: DeadEsc::Zero,
        ..AgentReports::default()
    };
    let s = hover(Some((1, FailureKind::NoThrust)), zero);
    let mut sim = Simulation::new(&s).unwrap();
    let mut controller = AnyTvmdController::from_scenario(&s).unwrap();
    let mut effects = 0;
    while !sim.is_finished() {
        let o = sim.observe().unwrap().clone();
        let healthy = sim.healthy_reports();
        assert_eq!(healthy.len(), 6);
        for (i, (r, h)) in o.reports.iter().zip(&healthy).enumerate() {
            let (Some(r), Some(h)) = (r, h) else {
                assert_eq!(r, h);
                continue;
            };
            // Measured before the failure at 1.0 s, or another agent: the same report.
            if i != 1 || o.t - r.age < 1.0 - 1e-9 {
                assert_eq!(r, h, "t = {}, agent {i}", o.t);
            } else {
                assert!(r.thrust.abs() < 0.3 && h.thrust > 1.0, "{r:?} {h:?}");
                assert_eq!((r.eta_x, r.eta_y, r.age), (h.eta_x, h.eta_y, h.age));
                effects += 1;
            }
        }
        let out = controller.step(&o.input()).unwrap();
        sim.step_output(out).unwrap();
    }
    assert!(effects > 150, "{effects} reports after the failure");
    let mut s = Scenario::builtin("hover").unwrap();
    s.duration = 0.05;
    assert!(Simulation::new(&s).unwrap().healthy_reports().is_empty());
}
