//! A run read back from its MCAP log ([`load_run`]): the scenario of [`METADATA_SCENARIO`], one
//! [`Sample`] per logged tick, and the summary of [`METADATA_RESULT`].
//!
//! Each tick's state, reference and controller output are rebuilt from its messages (every
//! numeric field a protobuf `double`, so the loop's values exactly, except that a `-0.0` in a
//! non-repeated field reads back as `0.0`: protobuf omits a field equal to zero) and recorded with
//! [`Sample::record`], the function the loop records with: the samples equal the in-memory
//! ones of a run that kept every tick. On the ticks a `[log] decimation > 1` thinned, the
//! heavy topics are absent: those samples have no commands, actual outputs, planner or
//! allocation values (NaN in Python). The summary and the paper's metrics are the ones the run
//! computed (written when it ended, [`write_result_metadata`]); a log without them (a run that
//! did not finish writing) gets them folded over the samples read, with the last tick as the
//! final state and no wall time. A file damaged after its first tick (truncated) loads the ticks
//! before the damage and says so ([`LoadedRun::damage`]).

use std::collections::BTreeMap;
use std::path::Path;

use nalgebra::{Matrix3, Vector3};

use crate::diagnostics::{
    AllocationDiagnostics, ControlDiagnostics, Diagnostics, FaultDiagnostics, HoverDiagnostics,
    LyapunovDiagnostics, NullSpaceDiagnostics, PlannerDiagnostics,
};
use crate::flight::FlightOutput;
use crate::sim::{PaperMetrics, RunResult, RunSummary, RunTotals, Sample, SummaryFold};
use crate::SimError;
use tvmd_log::{proto, read_run, LogError, TickMessages, METADATA_RESULT, METADATA_SCENARIO};
use tvmd_plant::actuators::ActuatorCommand;
use tvmd_plant::math::from_rows;
use tvmd_plant::physics::PlantState;
use tvmd_plant::reference::ReferenceSample;
use tvmd_scenario::Scenario;

/// A run read back from its log.
#[derive(Clone, Debug)]
pub struct LoadedRun {
    /// The scenario that ran (overrides applied).
    pub scenario: Scenario,
    /// Its samples (one per logged tick, stride 1), summary and paper metrics.
    pub result: RunResult,
    /// The file is damaged (e.g. truncated): what stopped the reading. The samples are the
    /// ticks before it, the summary folded over them.
    pub damage: Option<String>,
}

fn bad(what: impl std::fmt::Display) -> SimError {
    SimError::Log(LogError::LogRead(what.to_string()))
}

/// `N` entries of a repeated field (`field` names it in the error).
fn fixed<const N: usize>(v: &[f64], field: &str) -> Result<[f64; N], SimError> {
    v.try_into()
        .map_err(|_| bad(format!("`{field}` has {} entries, expected {N}", v.len())))
}

fn vec3(v: &[f64], field: &str) -> Result<Vector3<f64>, SimError> {
    Ok(Vector3::from(fixed::<3>(v, field)?))
}

fn rows3(v: &[f64], field: &str) -> Result<[[f64; 3]; 3], SimError> {
    let a = fixed::<9>(v, field)?;
    Ok([[a[0], a[1], a[2]], [a[3], a[4], a[5]], [a[6], a[7], a[8]]])
}

fn matrix(v: &[f64], field: &str) -> Result<Matrix3<f64>, SimError> {
    Ok(from_rows(&rows3(v, field)?))
}

fn state(s: &proto::State) -> Result<PlantState, SimError> {
    Ok(PlantState {
        position: vec3(&s.position, "/state.position")?,
        rotation: matrix(&s.rotation, "/state.rotation")?,
        velocity: vec3(&s.velocity, "/state.velocity")?,
        omega: vec3(&s.omega, "/state.omega")?,
    })
}

fn reference(r: &proto::Reference) -> Result<ReferenceSample, SimError> {
    Ok(ReferenceSample {
        t: r.t,
        position: vec3(&r.position, "/reference.position")?,
        velocity: vec3(&r.velocity, "/reference.velocity")?,
        acceleration: vec3(&r.acceleration, "/reference.acceleration")?,
        rotation: matrix(&r.rotation, "/reference.rotation")?,
        omega: vec3(&r.omega, "/reference.omega")?,
        // Not logged (the controller's input only).
        omega_dot: Vector3::zeros(),
        roll: r.roll,
        roll_rate: r.roll_rate,
    })
}

fn command(c: &proto::AgentCommand) -> ActuatorCommand {
    ActuatorCommand {
        eta_x: c.eta_x,
        eta_y: c.eta_y,
        thrust: c.thrust,
    }
}

fn planner(p: &proto::Planner) -> Result<PlannerDiagnostics, SimError> {
    Ok(PlannerDiagnostics {
        r_d: rows3(&p.r_d, "/planner.r_d")?,
        theta: p.theta,
        t_tf: p.t_tf,
        t_eta: p.t_eta,
        reference_feasible: p.reference_feasible,
        planned_roll: p.planned_roll,
        status: p.status.clone(),
        iterations: p.iterations,
    })
}

fn control(c: &proto::Control) -> Result<ControlDiagnostics, SimError> {
    Ok(ControlDiagnostics {
        u_r: fixed(&c.u_r, "/control.u_r")?,
        u_d: fixed(&c.u_d, "/control.u_d")?,
        e_x: fixed(&c.e_x, "/control.e_x")?,
        e_v: fixed(&c.e_v, "/control.e_v")?,
        e_r: fixed(&c.e_r, "/control.e_r")?,
        e_omega: fixed(&c.e_omega, "/control.e_omega")?,
        t_tf: c.t_tf,
        t_eta: c.t_eta,
        extra: if c.extra_json.is_empty() {
            serde_json::Value::Null
        } else {
            serde_json::from_str(&c.extra_json)
                .map_err(|e| bad(format!("/control.extra_json: {e}")))?
        },
    })
}

fn allocation(a: &proto::Allocation) -> Result<AllocationDiagnostics, SimError> {
    let null_space = match &a.null_space {
        Some(n) => Some(NullSpaceDiagnostics {
            iterations: n.iterations,
            objective: fixed(&n.objective, "/allocation.null_space.objective")?,
            margin: fixed(&n.margin, "/allocation.null_space.margin")?,
            largest_force_change: n.largest_force_change,
            wrench_drift: n.wrench_drift,
        }),
        None => None,
    };
    Ok(AllocationDiagnostics {
        wrench: fixed(&a.wrench, "/allocation.wrench")?,
        e_f: a.e_f,
        saturated: a.saturated.clone(),
        wrench_error: a.wrench_error,
        rounds: a.rounds,
        fallback: a.fallback,
        forces: a.forces.iter().map(|f| [f.x, f.y, f.z]).collect(),
        rotor_speeds: a.rotor_speeds.clone(),
        null_space,
    })
}

fn hover(h: &proto::Hover) -> HoverDiagnostics {
    HoverDiagnostics {
        capable: h.capable,
        margin: h.margin,
        limiting_agent: h.limiting_agent.map(|i| i as usize),
        limit: h.limit.clone(),
        landing: h.landing,
        // Not logged.
        refused: None,
    }
}

/// A name the log wrote with serde's kebab-case, back as its enum.
fn named<V: serde::de::DeserializeOwned>(t: f64, what: &str, s: &str) -> Result<V, SimError> {
    serde_json::from_value(serde_json::Value::String(s.to_string())).map_err(|_| {
        bad(format!(
            "the `/fault` message at t = {t} s has an unknown {what} `{s}`"
        ))
    })
}

/// A `/fault` message back as the report it logged.
fn fault(f: &proto::Fault) -> Result<FaultDiagnostics, SimError> {
    Ok(FaultDiagnostics {
        statistic: f.statistic,
        threshold: f.threshold,
        verdict: named(f.t, "verdict", &f.verdict)?,
        agent: f.agent.map(|i| i as usize),
        kind: if f.kind.is_empty() {
            None
        } else {
            Some(named(f.t, "kind", &f.kind)?)
        },
        efficiency: f.efficiency,
        periods: f.periods,
        masked: f.masked.map(|i| i as usize),
        source: if f.source.is_empty() {
            None
        } else {
            Some(named(f.t, "source", &f.source)?)
        },
    })
}

fn non_empty(s: &str) -> Option<String> {
    (!s.is_empty()).then(|| s.to_string())
}

/// The sample of one logged tick, recorded as the loop records it.
fn sample(m: &TickMessages) -> Result<Sample, SimError> {
    let t = m.state.t;
    let r = m
        .reference
        .as_ref()
        .ok_or_else(|| bad(format!("the tick at t = {t} s has no `/reference` message")))?;
    let diagnostics = Diagnostics {
        planner: m.planner.as_ref().map(planner).transpose()?,
        control: m.control.as_ref().map(control).transpose()?,
        allocation: m.allocation.as_ref().map(allocation).transpose()?,
        lyapunov: m.lyapunov.as_ref().map(|l| LyapunovDiagnostics {
            v_x: l.v_x,
            v_r: l.v_r,
        }),
        cycle_error: m.note.as_ref().and_then(|n| non_empty(&n.cycle_error)),
        failure_note: m.note.as_ref().and_then(|n| non_empty(&n.failure_note)),
        hover: m.hover.as_ref().map(hover),
        fault: m.fault.as_ref().map(fault).transpose()?,
    };
    let actuators = m.actuators.as_ref();
    let output = FlightOutput {
        commands: actuators.map_or_else(Vec::new, |a| a.commanded.iter().map(command).collect()),
        diagnostics,
    };
    let actual = actuators.map_or_else(Vec::new, |a| a.actual.iter().map(command).collect());
    let failed = actuators.map_or_else(Vec::new, |a| a.failed.clone());
    Ok(Sample::record(
        t,
        &state(&m.state)?,
        &reference(r)?,
        &output,
        actual,
        failed,
    ))
}

/// Writes the run's summary and paper metrics into the log's metadata record
/// [`METADATA_RESULT`] (JSON), for [`load_run`].
pub fn write_result_metadata(
    log: &mut tvmd_log::RunLog,
    result: &RunResult,
) -> Result<(), SimError> {
    let encode = |e: serde_json::Error| bad(format!("cannot encode the result: {e}"));
    let mut meta = BTreeMap::new();
    let summary = serde_json::to_string(&result.summary).map_err(encode)?;
    meta.insert("summary".to_string(), summary);
    let paper = serde_json::to_string(&result.paper).map_err(encode)?;
    meta.insert("paper_metrics".to_string(), paper);
    Ok(log.write_metadata(METADATA_RESULT, meta)?)
}

/// The summary and metrics stored in the log, if it has them and they decode.
fn stored(meta: Option<&BTreeMap<String, String>>) -> Option<(RunSummary, PaperMetrics)> {
    let meta = meta?;
    let summary = serde_json::from_str(meta.get("summary")?).ok()?;
    let paper = serde_json::from_str(meta.get("paper_metrics")?).ok()?;
    Some((summary, paper))
}

/// Reads the run logged at `path`: its scenario, samples, summary and metrics (module docs).
/// Errors ([`LogError::File`], [`LogError::LogRead`]) name the path.
pub fn load_run(path: impl AsRef<Path>) -> Result<LoadedRun, SimError> {
    let path = path.as_ref();
    let run = read_run(path)?;
    let in_path = |e: SimError| match e {
        SimError::Log(LogError::LogRead(m)) => bad(format!("{}: {m}", path.display())),
        other => bad(format!("{}: {other}", path.display())),
    };
    let toml = run
        .metadata
        .get(METADATA_SCENARIO)
        .and_then(|m| m.get("toml"))
        .ok_or_else(|| {
            bad(format!(
                "{}: no `{METADATA_SCENARIO}` metadata record with the scenario",
                path.display()
            ))
        })?;
    let scenario = Scenario::from_toml_str(toml).map_err(|e| in_path(e.into()))?;
    let samples = run
        .ticks
        .iter()
        .map(sample)
        .collect::<Result<Vec<_>, _>>()
        .map_err(in_path)?;
    let (summary, paper) = match stored(run.metadata.get(METADATA_RESULT)) {
        Some(stored) => stored,
        None => {
            let fold = SummaryFold::over(&scenario, &samples);
            let last = &run.ticks[run.ticks.len() - 1].state;
            let totals = RunTotals {
                time: last.t,
                final_state: state(last).map_err(in_path)?,
                mass: scenario.team_body().map_or(f64::NAN, |t| t.mass()),
                controller_calls: samples.len(),
                physics_steps: 0,
                wall_time: 0.0,
                interrupted: false,
            };
            (fold.summary(&scenario, &totals), fold.paper())
        }
    };
    Ok(LoadedRun {
        damage: run.damage,
        scenario,
        result: RunResult {
            samples,
            sample_stride: 1,
            summary,
            paper,
        },
    })
}
