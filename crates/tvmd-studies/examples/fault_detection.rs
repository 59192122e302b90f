//! The agent fault detector in flight (`docs/fault-detection.md`): detection and isolation
//! delays per team, fault kind and flight phase; false alarms over nominal Monte Carlo flights;
//! and the flight outcome with the controller not informed against the informed baseline.
//!
//! ```text
//! cargo run --profile ci -p tvmd-studies --example fault_detection -- [FLIGHTS] [JOBS] [EPSILON]
//! ```
//!
//! `FLIGHTS` nominal flights (default 1000) spread over A4-Inc, A6-Inc, A8-Inc and the hover,
//! wind and tilt flights, each with a Monte Carlo draw of the default model-error distributions
//! and the default conditions (servo dynamics, state noise, one period of feedback latency).
//! The fault flights use the same draws and conditions: every agent of each team loses its
//! thrust, half its thrust, or sticks its gimbal, at hover (t = 4 s) and in the tilt (t = 7 s),
//! the controller not informed, detection on with the recommended settings and `response =
//! "mask"`. Prints Markdown tables.

use std::sync::atomic::{AtomicUsize, Ordering};

use tvmd_plant::actuators::FailureKind;
use tvmd_scenario::{
    Failure, FaultDetectionConfig, FaultResponseConfig, LawConfig, OnHoverLoss, Scenario,
};
use tvmd_sim::{run_scenario, FaultSummary, RunResult};
use tvmd_studies::montecarlo::Conditions;

mod fault_common;
use fault_common::{delay_after, delay_column, map, Phase, TEAMS};

const SEED: u64 = 47;

/// The detector of every flight: the recommended one with `"mask"`, or another stated model
/// error (the third argument).
fn detection() -> FaultDetectionConfig {
    let mut d = FaultDetectionConfig::with_response(FaultResponseConfig::Mask);
    if let Some(e) = std::env::args().nth(3).and_then(|a| a.parse().ok()) {
        d.model_error = e;
    }
    d
}

/// The flight of `team` in `phase` with the offset-free law and detection (`"mask"`), a Monte
/// Carlo draw `index` and the default conditions.
fn flight(team: &str, phase: Phase, index: u64) -> Result<Scenario, Box<dyn std::error::Error>> {
    let conditions = Conditions::default();
    fault_common::flight(team, phase, (SEED, index), detection(), &conditions, |_| {})
}

fn kind_name(k: FailureKind) -> &'static str {
    match k {
        FailureKind::NoThrust => "loss",
        FailureKind::HalfThrust => "50% thrust",
        FailureKind::StuckGimbal => "stuck gimbal",
        FailureKind::NoThrustStuckGimbal => "loss + stuck",
        FailureKind::LinkLoss => "link loss",
    }
}

/// One fault flight's result.
struct FaultRun {
    team: &'static str,
    kind: FailureKind,
    phase: Phase,
    agent: usize,
    fault: FaultSummary,
    t_f: f64,
    /// The largest statistic over the first second after the fault, in units of `k`: what
    /// the fault put in the residual within the issue's second (below 1, no detector at this
    /// threshold could see it).
    first_second: f64,
}

impl FaultRun {
    /// The delay of an event naming the right agent after the fault; `Err` for another agent.
    fn delay(&self, e: Option<tvmd_sim::FaultEvent>) -> Result<Option<f64>, ()> {
        delay_after(e, self.agent, self.t_f)
    }
}

fn fault_runs(jobs: usize) -> Vec<FaultRun> {
    let mut specs = Vec::new();
    for (k, team) in TEAMS.iter().enumerate() {
        let n = 4 + 2 * k;
        for kind in [
            FailureKind::NoThrust,
            FailureKind::HalfThrust,
            FailureKind::StuckGimbal,
        ] {
            for phase in [Phase::Hover, Phase::Tilt] {
                for agent in 0..n {
                    specs.push((*team, kind, phase, agent));
                }
            }
        }
    }
    map(&specs, jobs, |k, &(team, kind, phase, agent)| {
        let mut s = flight(team, phase, 10_000 + k as u64).ok()?;
        let t_f = phase.fault_time();
        s.duration = t_f + 3.0;
        s.failures = vec![Failure {
            agent,
            time: t_f,
            kind,
            controller_informed: false,
            informed_after: 0.0,
        }];
        let r = run_scenario(&s, None, None).ok()?;
        let first_second = r
            .samples
            .iter()
            .filter(|x| x.t >= t_f && x.t <= t_f + 1.0)
            .filter_map(|x| x.fault.as_ref())
            .map(|f| f.statistic / f.threshold.max(1e-9))
            .filter(|x| x.is_finite())
            .fold(0.0, f64::max);
        Some(FaultRun {
            team,
            kind,
            phase,
            agent,
            fault: r.summary.fault.unwrap_or_default(),
            t_f,
            first_second,
        })
    })
}

fn fault_table(runs: &[FaultRun]) {
    println!("| team | fault | phase | flights | suspected (right agent) | delay median / worst (s) | confirmed (right agent) | delay median / worst (s) | loss confirmed, masked | delay median / worst (s) | wrong agent | largest statistic / k in the first second: smallest / median / largest |");
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|");
    for team in TEAMS {
        for kind in [
            FailureKind::NoThrust,
            FailureKind::HalfThrust,
            FailureKind::StuckGimbal,
        ] {
            for phase in [Phase::Hover, Phase::Tilt] {
                let group: Vec<&FaultRun> = runs
                    .iter()
                    .filter(|r| r.team == team && r.kind == kind && r.phase == phase)
                    .collect();
                let mut wrong = 0;
                let mut column = |pick: &dyn Fn(&FaultRun) -> Option<tvmd_sim::FaultEvent>| {
                    let (n, q, w) = delay_column(&group, |r| r.delay(pick(r)), 2);
                    wrong += w;
                    (n, q)
                };
                let (ns, ds) = column(&|r| r.fault.first_suspected);
                let (nc, dc) = column(&|r| r.fault.first_confirmed);
                let (nm, dm) = column(&|r| r.fault.masked);
                let mut peaks: Vec<f64> = group.iter().map(|r| r.first_second).collect();
                peaks.sort_by(f64::total_cmp);
                let peak = match (peaks.first(), peaks.get(peaks.len() / 2), peaks.last()) {
                    (Some(s), Some(m), Some(l)) => format!("{s:.2} / {m:.2} / {l:.2}"),
                    _ => "-".into(),
                };
                println!(
                    "| {team} | {} | {} | {} | {ns} | {ds} | {nc} | {dc} | {nm} | {dm} | {wrong} | {peak} |",
                    kind_name(kind),
                    phase.name(),
                    group.len()
                );
            }
        }
    }
}

fn false_alarms(flights: usize, jobs: usize) {
    let phases = [Phase::Hover, Phase::Wind, Phase::Tilt];
    let specs: Vec<(usize, &str, Phase)> = (0..flights)
        .map(|k| (k, TEAMS[k % 3], phases[(k / 3) % 3]))
        .collect();
    let done = AtomicUsize::new(0);
    let rows = map(&specs, jobs, |_, &(k, team, phase)| {
        let s = flight(team, phase, k as u64).ok()?;
        let r = run_scenario(&s, None, None).ok()?;
        let f = r.summary.fault.unwrap_or_default();
        let d = done.fetch_add(1, Ordering::Relaxed) + 1;
        if d % 100 == 0 {
            eprintln!("{d} nominal flights");
        }
        Some((team, phase, f, r.summary.verdict.success))
    });
    println!("| team | flight | flights | over threshold | suspected | confirmed (false alarm) | masked | largest statistic / k | verdict ok |");
    println!("|---|---|---|---|---|---|---|---|---|");
    for team in TEAMS {
        for phase in phases {
            let g: Vec<_> = rows
                .iter()
                .filter(|r| r.0 == team && r.1 == phase)
                .collect();
            let count = |p: &dyn Fn(&FaultSummary) -> bool| g.iter().filter(|r| p(&r.2)).count();
            let worst = g
                .iter()
                .map(|r| r.2.max_statistic / r.2.threshold.max(1e-9))
                .fold(0.0, f64::max);
            println!(
                "| {team} | {} | {} | {} | {} | {} | {} | {worst:.2} | {} |",
                phase.name(),
                g.len(),
                count(&|f| f.first_alarm.is_some()),
                count(&|f| f.first_suspected.is_some()),
                count(&|f| f.first_confirmed.is_some()),
                count(&|f| f.masked.is_some()),
                g.iter().filter(|r| r.3).count(),
            );
        }
    }
}

/// The largest position error and tilt (rad) from `from` on.
fn after(r: &RunResult, from: f64) -> (f64, f64) {
    r.samples
        .iter()
        .filter(|s| s.t >= from)
        .fold((0.0f64, 0.0f64), |(e, tilt), s| {
            let d = [0, 1, 2].map(|i| s.position[i] - s.reference_position[i]);
            let err = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            let [roll, pitch, _] = s.roll_pitch_yaw;
            let c = roll.cos() * pitch.cos();
            (e.max(err), tilt.max(c.clamp(-1.0, 1.0).acos()))
        })
}

fn outcomes() -> Result<(), Box<dyn std::error::Error>> {
    println!("| flight | controller | masked at (s) | peak position error after the fault (m) | max tilt after the fault (rad) | landed |");
    println!("|---|---|---|---|---|---|");
    for (name, land) in [("a6-agent-failure", false), ("agent-failure", true)] {
        for (label, law, informed, detect) in [
            ("paper law, informed", LawConfig::paper(), true, false),
            ("offset-free, informed", LawConfig::default(), true, false),
            (
                "offset-free, not informed, detection",
                LawConfig::default(),
                false,
                true,
            ),
            (
                "offset-free, not informed, no detection",
                LawConfig::default(),
                false,
                false,
            ),
        ] {
            let mut s = Scenario::builtin(name)?;
            s.law = law;
            for f in &mut s.failures {
                f.controller_informed = informed;
            }
            if land {
                s.failure_response.on_hover_loss = OnHoverLoss::Land;
            }
            if detect {
                s.fault_detection = Some(detection());
            }
            let t_f = s.failures[0].time;
            let r = run_scenario(&s, None, None)?;
            let (peak, tilt) = after(&r, t_f);
            let masked = r
                .summary
                .fault
                .and_then(|f| f.masked)
                .map_or("-".into(), |m| format!("{:.2} (agent {})", m.time, m.agent));
            let landed = r.summary.final_position[2] < 0.05;
            println!(
                "| {name}{} | {label} | {masked} | {peak:.3} | {tilt:.3} | {landed} |",
                if land { " (land)" } else { "" }
            );
        }
    }
    Ok(())
}

/// The peak position error (m) and the max tilt (rad) after a failure.
type PeakAndTilt = (f64, f64);

/// The flight targets against the delay of an informed controller: the offset-free law told
/// `informed_after` seconds after the failure (no detection), as if a detector or the agent's
/// telemetry named it that late.
fn informed_late() -> Result<(), Box<dyn std::error::Error>> {
    const DELAYS: [f64; 10] = [0.0, 0.01, 0.02, 0.03, 0.04, 0.05, 0.07, 0.1, 0.15, 0.2];
    print!("| flight |");
    for d in DELAYS {
        print!(" {d:.2} s |");
    }
    println!();
    println!("|---|{}", "---|".repeat(DELAYS.len()));
    for (name, land) in [("a6-agent-failure", false), ("agent-failure", true)] {
        let runs = DELAYS.map(|d| -> Result<PeakAndTilt, Box<dyn std::error::Error>> {
            let mut s = Scenario::builtin(name)?;
            s.law = LawConfig::default();
            for f in &mut s.failures {
                f.informed_after = d;
            }
            if land {
                s.failure_response.on_hover_loss = OnHoverLoss::Land;
            }
            let t_f = s.failures[0].time;
            Ok(after(&run_scenario(&s, None, None)?, t_f))
        });
        let (quantity, pick): (&str, fn(&PeakAndTilt) -> f64) = if land {
            ("max tilt (rad)", |r| r.1)
        } else {
            ("peak position error (m)", |r| r.0)
        };
        print!(
            "| {name}{}: {quantity} |",
            if land { " (land)" } else { "" }
        );
        for r in runs {
            print!(" {:.3} |", pick(&r?));
        }
        println!();
    }
    Ok(())
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let flights: usize = args.next().map_or(Ok(1000), |a| a.parse())?;
    let jobs: usize = args.next().map_or(Ok(2), |a| a.parse())?;
    println!("## Flight outcome, controller informed or not\n");
    outcomes()?;
    println!(
        "\n## The same flights, the controller informed late (offset-free law, no detection)\n"
    );
    informed_late()?;
    println!("\n## Detection and isolation delays (fault at t_f, not informed)\n");
    fault_table(&fault_runs(jobs));
    println!("\n## False alarms over {flights} nominal flights\n");
    false_alarms(flights, jobs);
    Ok(())
}
