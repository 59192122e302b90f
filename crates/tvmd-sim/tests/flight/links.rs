//! Per-agent command links in flight (issue 60, item 1): an ideal link changes nothing, a lossy
//! and late link is flown through, and a silent link holds the agent's last command, then idles
//! it.

use tvmd_plant::actuators::FailureKind;
use tvmd_scenario::{CommandLinks, Failure, LinkFailsafe, Scenario};
use tvmd_sim::runner::run_scenario;
use tvmd_sim::sim::{RunResult, Simulation};

fn hover(preset: &str, links: Option<CommandLinks>) -> Scenario {
    let mut s = Scenario::builtin("hover").unwrap();
    s.team.preset = Some(preset.into());
    s.links = links;
    s
}

fn flown(s: &Scenario) -> RunResult {
    run_scenario(s, None, None).unwrap()
}

#[test]
fn an_ideal_link_flies_bit_for_bit_as_no_link() {
    let none = flown(&hover("a4-inc", None));
    let ideal = flown(&hover("a4-inc", Some(CommandLinks::default())));
    assert_eq!(none.samples.len(), ideal.samples.len());
    for (a, b) in none.samples.iter().zip(&ideal.samples) {
        assert_eq!(a.position, b.position, "t = {}", a.t);
        assert_eq!(a.actual, b.actual, "t = {}", a.t);
    }
}

#[test]
fn a_late_lossy_link_is_flown_through() {
    let links = CommandLinks {
        latency: 0.02,
        jitter: 0.005,
        loss: 0.1,
        ..CommandLinks::default()
    };
    let s = hover("a4-inc", Some(links));
    let r = flown(&s);
    assert!(r.summary.verdict.success, "{:?}", r.summary.verdict);
    let rms = r.summary.metrics.position.as_ref().unwrap().rms;
    let ideal = flown(&hover("a4-inc", None));
    let ideal_rms = ideal.summary.metrics.position.as_ref().unwrap().rms;
    // The link costs tracking (the agents idle until the first command arrives, 20 ms, and
    // hold through losses), but not much.
    let largest_late = r
        .samples
        .iter()
        .filter(|x| x.t > 2.0)
        .map(|x| {
            (0..3)
                .map(|k| (x.position[k] - x.reference_position[k]).powi(2))
                .sum::<f64>()
                .sqrt()
        })
        .fold(0.0, f64::max);
    assert!(rms > ideal_rms && rms < 0.01, "{rms} vs {ideal_rms}");
    assert!(largest_late < 0.01, "{largest_late}");
    let mut sim = Simulation::new(&s).unwrap();
    while !sim.is_finished() {
        let commands = vec![Default::default(); sim.agents()];
        sim.observe().unwrap();
        sim.step(&commands).unwrap();
    }
    let stats = sim.link_stats().unwrap();
    assert_eq!(stats.len(), 4);
    for st in &stats {
        let rate = st.lost as f64 / st.sent as f64;
        assert!(rate > 0.08 && rate < 0.12, "{st:?}");
        assert_eq!(st.failsafes, 0, "no 0.1 s silence at 10% independent loss");
    }
    assert!(Simulation::new(&hover("a4-inc", None))
        .unwrap()
        .link_stats()
        .is_none());
}

#[test]
fn a_silent_link_holds_the_last_command_then_idles_the_agent() {
    for failsafe in [LinkFailsafe::Idle, LinkFailsafe::Hold] {
        let mut s = hover("a6-inc", None);
        if failsafe == LinkFailsafe::Hold {
            s.links = Some(CommandLinks {
                failsafe,
                ..CommandLinks::default()
            });
        }
        s.failures = vec![Failure {
            agent: 2,
            time: 2.0,
            kind: FailureKind::LinkLoss,
            controller_informed: false,
            informed_after: 0.0,
        }];
        let r = flown(&s);
        let at = |t: f64| r.samples.iter().find(|x| x.t >= t - 1e-9).unwrap();
        let last = at(1.99).commands[2];
        // Held: the agent applies the last command it received while the others follow theirs.
        assert_eq!(at(2.05).actual[2].thrust, last.thrust);
        assert_eq!(at(2.05).actual[2].eta_x, last.eta_x);
        match failsafe {
            LinkFailsafe::Idle => {
                assert_eq!(at(2.15).actual[2].thrust, 0.0);
                assert_eq!(at(2.15).actual[2].eta_x, 0.0);
            }
            LinkFailsafe::Hold => assert_eq!(at(3.0).actual[2].thrust, last.thrust),
        }
        assert!(
            at(2.15).commands[2].thrust > 0.0,
            "the controller is not told"
        );
    }
}

#[test]
fn a_reset_seed_draws_the_links_anew_and_repeats_itself() {
    let lossy = CommandLinks {
        loss: 0.3,
        ..CommandLinks::default()
    };
    let mut s = hover("a4-inc", Some(lossy));
    s.duration = 0.5;
    let lost = |seed: Option<u64>| {
        let mut sim = Simulation::new(&s).unwrap();
        sim.reset(seed).unwrap();
        while !sim.is_finished() {
            let n = sim.agents();
            sim.observe().unwrap();
            sim.step(&vec![Default::default(); n]).unwrap();
        }
        sim.link_stats().unwrap()
    };
    assert_eq!(lost(None), lost(None));
    assert_eq!(lost(Some(7)), lost(Some(7)));
    assert_ne!(lost(Some(7)), lost(Some(8)));
}
