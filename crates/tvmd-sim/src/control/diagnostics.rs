//! The [`Diagnostics`] of one core cycle, converted to f64 (planner, control law, allocation,
//! Lyapunov values).

use std::collections::BTreeMap;

use super::convert::{array_to_sim, matrix_to_sim, to_sim, vector_to_sim, CoreFloat};
use super::CoreOutput;
use crate::diagnostics::{
    AllocationDiagnostics, ControlDiagnostics, Diagnostics, FaultDiagnostics, FaultKindName,
    FaultSourceName, FaultVerdictName, LyapunovDiagnostics, NullSpaceDiagnostics,
    PlannerDiagnostics,
};
use tvmd_core::{FaultKind, FaultReport, FaultSource, FaultVerdict, PlannerStatus};
use tvmd_plant::math::{planned_roll, to_rows};

/// The diagnostics of `out` for a team of `n` agents, with the controller's failure note.
pub(super) fn cycle_diagnostics<T: CoreFloat>(
    out: &CoreOutput<T>,
    n: usize,
    failure_note: Option<String>,
) -> Diagnostics {
    let r_d = matrix_to_sim(&out.planner.r_d);
    let law = &out.law;
    let e = array_to_sim::<T, 6>(law.e_xi.into());
    let alloc = &out.allocation;
    let mut extra = BTreeMap::new();
    extra.insert("f_r", serde_json::json!(vector_to_sim(&out.f_r)));
    extra.insert(
        "command_clamp",
        serde_json::json!(to_sim(out.command_clamp)),
    );
    Diagnostics {
        planner: Some(PlannerDiagnostics {
            r_d: to_rows(&r_d),
            theta: to_sim(out.planner.theta),
            t_tf: to_sim(out.projection.t_tf),
            t_eta: to_sim(out.projection.t_eta),
            reference_feasible: out.planner.status == PlannerStatus::AlreadyFeasible,
            planned_roll: planned_roll(&r_d),
            status: out.planner.status.as_str().to_string(),
            iterations: out.planner.iterations,
        }),
        control: Some(ControlDiagnostics {
            u_r: array_to_sim(law.u_r.into()),
            u_d: array_to_sim(law.u_d.into()),
            e_x: vector_to_sim(&law.e_x),
            e_v: [e[3], e[4], e[5]],
            e_r: vector_to_sim(&law.e_r),
            e_omega: [e[0], e[1], e[2]],
            t_tf: to_sim(out.projection.t_tf),
            t_eta: to_sim(out.projection.t_eta),
            extra: serde_json::json!(extra),
        }),
        allocation: Some(AllocationDiagnostics {
            wrench: array_to_sim(alloc.wrench.into()),
            e_f: to_sim(alloc.e_f),
            saturated: alloc.saturated[..n].to_vec(),
            wrench_error: to_sim(alloc.wrench_error),
            rounds: alloc.rounds,
            fallback: alloc.fallback,
            forces: alloc.forces[..n].iter().map(vector_to_sim).collect(),
            rotor_speeds: out.commands[..n].iter().map(|c| to_sim(c.omega)).collect(),
            null_space: out.null_space.ran.then(|| {
                let r = &out.null_space;
                NullSpaceDiagnostics {
                    iterations: r.iterations,
                    objective: [to_sim(r.objective_before), to_sim(r.objective_after)],
                    margin: [to_sim(r.margin_before), to_sim(r.margin_after)],
                    largest_force_change: to_sim(r.largest_force_change),
                    wrench_drift: to_sim(r.wrench_drift),
                }
            }),
        }),
        lyapunov: Some(LyapunovDiagnostics {
            v_x: to_sim(law.v_x),
            v_r: to_sim(law.v_r),
        }),
        cycle_error: None,
        failure_note,
        hover: None,
        fault: None,
    }
}

/// The detector's report in f64 (no agent masked: the caller fills `masked`).
pub fn fault_diagnostics<T: CoreFloat>(report: &FaultReport<T>) -> FaultDiagnostics {
    let (verdict, agent, kind, periods) = match report.verdict {
        FaultVerdict::Nominal => (FaultVerdictName::Nominal, None, None, 0),
        FaultVerdict::Unexplained => (FaultVerdictName::Unexplained, None, None, 0),
        FaultVerdict::Suspected {
            agent,
            kind,
            periods,
        } => (
            FaultVerdictName::Suspected,
            Some(agent),
            Some(kind),
            periods,
        ),
        FaultVerdict::Confirmed { agent, kind } => {
            (FaultVerdictName::Confirmed, Some(agent), Some(kind), 0)
        }
    };
    let (kind, efficiency) = match kind {
        None => (None, None),
        Some(FaultKind::Loss) => (Some(FaultKindName::Loss), None),
        Some(FaultKind::PartialLoss { efficiency }) => {
            (Some(FaultKindName::PartialLoss), Some(to_sim(efficiency)))
        }
        Some(FaultKind::StuckGimbal) => (Some(FaultKindName::StuckGimbal), None),
        Some(FaultKind::LinkLoss) => (Some(FaultKindName::LinkLoss), None),
    };
    let source = agent.map(|_| match report.source {
        FaultSource::Residual => FaultSourceName::Residual,
        FaultSource::Reports => FaultSourceName::Reports,
    });
    FaultDiagnostics {
        statistic: to_sim(report.statistic),
        threshold: to_sim(report.threshold),
        verdict,
        agent,
        kind,
        efficiency,
        periods,
        masked: None,
        source,
    }
}
