//! The agents' own reports in the controller's fault detection (issue 60,
//! `docs/fault-detection.md`, "The agents' reports"): delays per team, fault and flight phase
//! with reports at 100 Hz and 20 ms latency; `a6-agent-failure` not informed against informed; false alarms over nominal
//! flights with 10% of the reports lost and a jittering command link; a report that lies; and
//! the delays from each failure's first effect on a report (`fault_effect`: the first report that
//! differs from the one the agent would have sent had it not failed by more than 3, 1 or 10
//! standard deviations of its noise, or that the failure stopped).
//!
//! ```text
//! cargo run --profile ci -p tvmd-studies --example fault_reports -- [FLIGHTS] [JOBS]
//! ```
//!
//! Every flight has a Monte Carlo draw of the default model-error distributions and the default
//! conditions (servo dynamics, state noise, one period of feedback latency), the offset-free law
//! and the recommended detector with `response = "mask"`, as `examples/fault_detection.rs`; and
//! `[reports]` at their defaults (100 Hz, 20 ms latency, 0.05 N and 5 mrad of noise). `FLIGHTS`
//! nominal flights (default 1000) over A4-, A6-, A8-Inc and hover, wind, tilt. Prints Markdown.
//!
//! `TVMD_STUDY_ANGLE_CHECK=0.025,1.0` flies every flight with the report check's
//! `angle_tolerance` and `angle_forget` set so (how their retuning was measured).
//!
//! `TVMD_STUDY_TRACE=a6-inc,tilt,16,2` prints instead, for nominal flight 16 (A6-Inc, tilt) and
//! agent 2, each tick's command and newest report from 4.9 to 5.8 s (how the report check's
//! allowances were found: the thrust command chatters at the attainable set's boundary).

use tvmd_plant::actuators::FailureKind;
use tvmd_scenario::{
    AgentReports, CommandLinks, DeadEsc, Failure, FaultDetectionConfig, FaultResponseConfig,
    LawConfig, Scenario,
};
use tvmd_sim::diagnostics::FaultSourceName;
use tvmd_sim::{run_scenario, FaultEvent, FaultSummary, RunResult};
use tvmd_studies::montecarlo::Conditions;

mod fault_common;
mod fault_effect;
use fault_common::{delay_after, delay_column, map, quantiles, Phase, TEAMS};
use fault_effect::{EffectWatch, FirstEffect};

const SEED: u64 = 60;

/// A fault of the study: the plant's failure and what the failed agent's reports say.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Fault {
    /// A dead ESC that reports zero speed.
    LossZero,
    /// A dead ESC that falls silent.
    LossSilent,
    /// A damaged propeller (its ESC reports full speed).
    HalfThrust,
    StuckGimbal,
    /// The command link drops (the agent holds 0.1 s, then idles; its reports stop).
    LinkLoss,
    /// A dead rotor whose reports lie (say the command).
    LossLying,
}

impl Fault {
    const ALL: [Fault; 6] = [
        Fault::LossZero,
        Fault::LossSilent,
        Fault::HalfThrust,
        Fault::StuckGimbal,
        Fault::LinkLoss,
        Fault::LossLying,
    ];

    fn name(self) -> &'static str {
        match self {
            Self::LossZero => "loss (ESC reports 0)",
            Self::LossSilent => "loss (ESC silent)",
            Self::HalfThrust => "50% thrust (propeller)",
            Self::StuckGimbal => "stuck gimbal",
            Self::LinkLoss => "link loss",
            Self::LossLying => "loss, lying report",
        }
    }

    fn kind(self) -> FailureKind {
        match self {
            Self::LossZero | Self::LossSilent | Self::LossLying => FailureKind::NoThrust,
            Self::HalfThrust => FailureKind::HalfThrust,
            Self::StuckGimbal => FailureKind::StuckGimbal,
            Self::LinkLoss => FailureKind::LinkLoss,
        }
    }
}

/// The flight of `team` in `phase`: offset-free law, detection masking, reports, a Monte Carlo
/// draw `index` and the default conditions (with `links` when given).
fn flight(
    team: &str,
    phase: Phase,
    index: u64,
    reports: AgentReports,
    links: Option<CommandLinks>,
) -> Result<Scenario, Box<dyn std::error::Error>> {
    let mut detection = FaultDetectionConfig::with_response(FaultResponseConfig::Mask);
    if let Some([tolerance, forget]) = angle_check() {
        detection.report_check.angle_tolerance = tolerance;
        detection.report_check.angle_forget = forget;
    }
    let conditions = Conditions {
        links,
        ..Conditions::default()
    };
    fault_common::flight(team, phase, (SEED, index), detection, &conditions, |s| {
        s.reports = Some(AgentReports {
            seed: SEED.wrapping_mul(1_000_003).wrapping_add(index),
            ..reports
        });
    })
}

/// `TVMD_STUDY_ANGLE_CHECK=tolerance,forget`: the report check's `angle_tolerance` (rad) and
/// `angle_forget` (rad/s) for every flight, in place of the recommended ones.
fn angle_check() -> Option<[f64; 2]> {
    let v = std::env::var("TVMD_STUDY_ANGLE_CHECK").ok()?;
    let (a, b) = v.split_once(',')?;
    Some([a.trim().parse().ok()?, b.trim().parse().ok()?])
}

/// Flies `s` with its controller, watching `agent`'s reports from `t_f` on: its fault summary
/// and the failure's first effects on the reports.
fn fly_watching(
    s: &Scenario,
    agent: usize,
    t_f: f64,
) -> Result<(FaultSummary, FirstEffect), Box<dyn std::error::Error>> {
    use tvmd_sim::FlightController;
    let options = tvmd_sim::sim::SimOptions {
        samples: tvmd_sim::sim::SampleRetention::None,
    };
    let mut sim = tvmd_sim::sim::Simulation::with_options(s, options)?;
    let mut c = tvmd_sim::AnyTvmdController::from_scenario(s)?;
    let mut watch = EffectWatch::new(t_f, s.reports.clone().ok_or("no reports")?);
    while !sim.is_finished() {
        let o = sim.observe()?.clone();
        let healthy = sim.healthy_reports();
        watch.see(o.t, o.reports[agent], healthy[agent]);
        let out = c.step(&o.input()).map_err(|e| e.to_string())?;
        let sent = out.commands[agent];
        watch.command(o.t, sent.eta_x, sent.eta_y);
        sim.step_output(out)?;
    }
    Ok((sim.summary().fault.unwrap_or_default(), watch.finish()))
}

struct FaultRun {
    team: &'static str,
    fault: Fault,
    phase: Phase,
    agent: usize,
    summary: FaultSummary,
    t_f: f64,
    effect: FirstEffect,
}

impl FaultRun {
    /// The delay of an event naming the right agent after the fault; `Err` for another agent.
    fn delay(&self, e: Option<FaultEvent>) -> Result<Option<f64>, ()> {
        delay_after(e, self.agent, self.t_f)
    }

    /// The delay of the first confirmation (the right agent) after the failure's first effect
    /// on a report past `fault_effect::EFFECT_SIGMAS[k]`.
    fn since_effect(&self, k: usize) -> Option<f64> {
        let e = self
            .summary
            .first_confirmed
            .filter(|e| e.agent == self.agent)?;
        Some(e.time - self.effect.at[k]?)
    }
}

fn fault_runs(jobs: usize) -> Vec<FaultRun> {
    let mut specs = Vec::new();
    for (k, team) in TEAMS.iter().enumerate() {
        for fault in Fault::ALL {
            for phase in [Phase::Hover, Phase::Tilt] {
                for agent in 0..4 + 2 * k {
                    specs.push((*team, fault, phase, agent));
                }
            }
        }
    }
    map(&specs, jobs, |k, &(team, fault, phase, agent)| {
        let reports = AgentReports {
            dead_esc: match fault {
                Fault::LossSilent => DeadEsc::Silent,
                _ => DeadEsc::Zero,
            },
            lying: if fault == Fault::LossLying {
                vec![agent]
            } else {
                vec![]
            },
            ..AgentReports::default()
        };
        let mut s = flight(team, phase, 20_000 + k as u64, reports, None).ok()?;
        let t_f = phase.fault_time();
        s.duration = t_f + 3.0;
        s.failures = vec![Failure {
            agent,
            time: t_f,
            kind: fault.kind(),
            controller_informed: false,
            informed_after: 0.0,
        }];
        let (summary, effect) = fly_watching(&s, agent, t_f).ok()?;
        Some(FaultRun {
            team,
            fault,
            phase,
            agent,
            summary,
            t_f,
            effect,
        })
    })
}

fn source(e: &Option<FaultEvent>) -> &'static str {
    match e.and_then(|e| e.source) {
        Some(FaultSourceName::Reports) => "reports",
        Some(FaultSourceName::Residual) => "residual",
        None => "-",
    }
}

/// The runs of each team, fault and phase, in the tables' order.
fn groups(runs: &[FaultRun]) -> Vec<(&'static str, Fault, Phase, Vec<&FaultRun>)> {
    let mut out = Vec::new();
    for team in TEAMS {
        for fault in Fault::ALL {
            for phase in [Phase::Hover, Phase::Tilt] {
                let group = runs
                    .iter()
                    .filter(|r| r.team == team && r.fault == fault && r.phase == phase)
                    .collect();
                out.push((team, fault, phase, group));
            }
        }
    }
    out
}

fn fault_table(runs: &[FaultRun]) {
    println!("| team | fault | phase | flights | named (right agent) | delay median / worst (s) | isolated: confirmed (right agent) | delay median / worst (s) | by reports / residual | masked | delay median / worst (s) | wrong agent first |");
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|");
    for (team, fault, phase, group) in groups(runs) {
        let mut wrong = 0;
        let mut column = |pick: &dyn Fn(&FaultRun) -> Option<FaultEvent>| {
            let (n, q, w) = delay_column(&group, |r| r.delay(pick(r)), 3);
            wrong += w;
            (n, q)
        };
        let (ns, ds) = column(&|r| r.summary.first_suspected);
        let (nc, dc) = column(&|r| r.summary.first_confirmed);
        let (nm, dm) = column(&|r| r.summary.masked);
        let by = |name: &str| {
            group
                .iter()
                .filter(|r| source(&r.summary.first_confirmed) == name)
                .count()
        };
        println!(
            "| {team} | {} | {} | {} | {ns} | {ds} | {nc} | {dc} | {} / {} | {nm} | {dm} | {wrong} |",
            fault.name(),
            phase.name(),
            group.len(),
            by("reports"),
            by("residual"),
        );
    }
}

/// The failure's first effect on the failed agent's reports (past 3, 1 and 10 standard
/// deviations of the report's noise, or a report missing) and the first confirmation after it.
fn effect_table(runs: &[FaultRun]) {
    println!("| team | fault | phase | flights | an effect (3 sigma) | first effect, s after t_f: median / worst | isolated, s after the first effect (3 sigma): median / worst | (1 sigma): median / worst | (10 sigma): median / worst | largest angle effect within 50 ms (rad), median | reports within the commands' range, median share | the check's servo model's largest error (rad), median: healthy / stuck reports | named by a check against that model (0.1 rad, 2 reports), s after the first effect: median / worst |");
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    for (team, fault, phase, group) in groups(runs) {
        let first: Vec<f64> = group
            .iter()
            .filter_map(|r| Some(r.effect.at[0]? - r.t_f))
            .collect();
        let after =
            |k: usize| quantiles(group.iter().filter_map(|r| r.since_effect(k)).collect(), 3);
        let median = |pick: fn(&FirstEffect) -> Option<f64>, digits: usize| {
            let v: Vec<f64> = group.iter().filter_map(|r| pick(&r.effect)).collect();
            quantiles(v, digits)
                .split(" / ")
                .next()
                .unwrap_or("-")
                .to_string()
        };
        let (largest, inside, model) = if fault == Fault::StuckGimbal {
            (
                median(|e| e.largest, 3),
                median(|e| e.inside, 2),
                format!(
                    "{} (worst {:.3}) / {} | {}",
                    median(|e| e.model.map(|m| m[0]), 3),
                    group
                        .iter()
                        .filter_map(|r| Some(r.effect.model?[0]))
                        .fold(0.0, f64::max),
                    median(|e| e.model.map(|m| m[1]), 3),
                    quantiles(
                        group.iter().filter_map(|r| r.effect.model_named).collect(),
                        3
                    ),
                ),
            )
        } else {
            ("-".into(), "-".into(), "- | -".into())
        };
        println!(
            "| {team} | {} | {} | {} | {} | {} | {} | {} | {} | {largest} | {inside} | {model} |",
            fault.name(),
            phase.name(),
            group.len(),
            first.len(),
            quantiles(first, 3),
            after(0),
            after(1),
            after(2),
        );
    }
}

/// The largest position error from `from` on.
fn peak_after(r: &RunResult, from: f64) -> f64 {
    r.samples
        .iter()
        .filter(|s| s.t >= from)
        .map(|s| {
            let d = [0, 1, 2].map(|i| s.position[i] - s.reference_position[i]);
            (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt()
        })
        .fold(0.0, f64::max)
}

/// `a6-agent-failure` (the builtin flight: no draws, no noise) informed, and not informed with
/// detection and reports.
fn outcome() -> Result<(), Box<dyn std::error::Error>> {
    println!("| controller | masked at (s after the loss), by | peak position error after the loss (m) | / informed |");
    println!("|---|---|---|---|");
    let informed = {
        let mut s = Scenario::builtin("a6-agent-failure")?;
        s.law = LawConfig::default();
        let t_f = s.failures[0].time;
        peak_after(&run_scenario(&s, None, None)?, t_f)
    };
    println!("| offset-free, informed | - | {informed:.4} | 1.00 |");
    for (label, reports) in [
        ("not informed, detection, no reports", None),
        (
            "not informed, detection, reports (ESC reports 0)",
            Some(DeadEsc::Zero),
        ),
        (
            "not informed, detection, reports (ESC silent)",
            Some(DeadEsc::Silent),
        ),
    ] {
        let mut s = Scenario::builtin("a6-agent-failure")?;
        s.law = LawConfig::default();
        for f in &mut s.failures {
            f.controller_informed = false;
        }
        s.fault_detection = Some(FaultDetectionConfig::with_response(
            FaultResponseConfig::Mask,
        ));
        s.reports = reports.map(|dead_esc| AgentReports {
            dead_esc,
            ..AgentReports::default()
        });
        let t_f = s.failures[0].time;
        let r = run_scenario(&s, None, None)?;
        let masked = r.summary.fault.and_then(|f| f.masked);
        let at = masked.map_or("-".into(), |m| {
            format!("{:.2}, {}", m.time - t_f, source(&Some(m)))
        });
        let peak = peak_after(&r, t_f);
        println!(
            "| {label} | {at} | {peak:.4} | {:.2} |",
            peak / informed.max(1e-12)
        );
    }
    Ok(())
}

/// Nominal flights with 10% of the reports lost and a jittering command link (0-10 ms).
fn false_alarms(flights: usize, jobs: usize) {
    let phases = [Phase::Hover, Phase::Wind, Phase::Tilt];
    let specs: Vec<(usize, &str, Phase)> = (0..flights)
        .map(|k| (k, TEAMS[k % 3], phases[(k / 3) % 3]))
        .collect();
    let links = CommandLinks {
        jitter: 0.01,
        ..CommandLinks::default()
    };
    let rows = map(&specs, jobs, |_, &(k, team, phase)| {
        let reports = AgentReports {
            loss: 0.1,
            ..AgentReports::default()
        };
        let s = flight(team, phase, k as u64, reports, Some(links)).ok()?;
        let r = run_scenario(&s, None, None).ok()?;
        Some((team, phase, r.summary.fault.unwrap_or_default()))
    });
    println!("| team | flight | flights | suspected | confirmed (false alarm): by reports / residual | masked |");
    println!("|---|---|---|---|---|---|");
    for team in TEAMS {
        for phase in phases {
            let g: Vec<_> = rows
                .iter()
                .filter(|r| r.0 == team && r.1 == phase)
                .collect();
            let count = |p: &dyn Fn(&FaultSummary) -> bool| g.iter().filter(|r| p(&r.2)).count();
            println!(
                "| {team} | {} | {} | {} | {} / {} | {} |",
                phase.name(),
                g.len(),
                count(&|f| f.first_suspected.is_some()),
                count(&|f| source(&f.first_confirmed) == "reports"),
                count(&|f| source(&f.first_confirmed) == "residual"),
                count(&|f| f.masked.is_some()),
            );
        }
    }
}

/// A trace of one nominal flight (`TVMD_STUDY_TRACE=team,phase,index,agent`): per tick the
/// command sent and the agent's newest report.
fn trace(spec: &str) -> Result<(), Box<dyn std::error::Error>> {
    use tvmd_sim::FlightController;
    let parts: Vec<&str> = spec.split(',').collect();
    let team = TEAMS.iter().find(|t| **t == parts[0]).ok_or("team")?;
    let phase = [Phase::Hover, Phase::Wind, Phase::Tilt]
        .into_iter()
        .find(|p| p.name() == parts[1])
        .ok_or("phase")?;
    let (index, agent): (u64, usize) = (parts[2].parse()?, parts[3].parse()?);
    let s = flight(team, phase, index, AgentReports::default(), None)?;
    let mut sim = tvmd_sim::sim::Simulation::new(&s)?;
    let mut c = tvmd_sim::AnyTvmdController::from_scenario(&s)?;
    while !sim.is_finished() {
        let o = sim.observe()?.clone();
        let out = c.step(&o.input()).map_err(|e| e.to_string())?;
        let cmd = out.commands[agent];
        let f = out.diagnostics.fault;
        if o.t > 4.9 && o.t < 5.8 {
            println!(
                "{:.2} cmd {:.3} {:.3} {:.3} report {:?} fault {:?}",
                o.t,
                cmd.thrust,
                cmd.eta_x,
                cmd.eta_y,
                o.reports.get(agent),
                f.map(|f| (f.verdict, f.agent, f.kind))
            );
        }
        sim.step_output(out)?;
    }
    Ok(())
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    if let Some(spec) = std::env::var_os("TVMD_STUDY_TRACE") {
        return trace(&spec.to_string_lossy());
    }
    let mut args = std::env::args().skip(1);
    let flights: usize = args.next().map_or(Ok(1000), |a| a.parse())?;
    let jobs: usize = args.next().map_or(Ok(2), |a| a.parse())?;
    println!("## a6-agent-failure, not informed, with reports\n");
    outcome()?;
    println!("\n## Delays with reports (100 Hz, 20 ms), fault at t_f, not informed\n");
    let runs = fault_runs(jobs);
    fault_table(&runs);
    println!("\n## The failure's first effect on a report (the failed agent's report against the one it would have sent had it not failed, the same noise), not informed\n");
    effect_table(&runs);
    println!("\n## False alarms over {flights} nominal flights, 10% of the reports lost, link jitter 0-10 ms\n");
    false_alarms(flights, jobs);
    Ok(())
}
