//! Every allocator over the set: exactness on the attainable requests, errors on the others,
//! rounds, admissibility; and the closed-loop `s = 1` paper-tilt flight per allocator.

use serde::Serialize;
use tvmd_core::allocation::AllocatorOptions;
use tvmd_core::nalgebra::{Vector3, Vector6};
use tvmd_core::{AdmissibleSet, AllocationRequest, Allocator, AnyAllocator, GimbalCommand};

use super::{failure_mask, team, team_size, AllocationSet, SetRequest, TeamRequests};
use crate::StudyError;
use tvmd_scenario::{Overrides, Scenario};
use tvmd_sim::runner::run_scenario;

/// A request is allocated exactly when `e_f / ||u_fd|| <=` this (issue 16).
pub const EXACT_TOLERANCE: f64 = 1e-9;

/// Admissibility tolerance of the returned forces (the gimbal inverse's round-off; relative to
/// the thrust range for the thrust, as [`AdmissibleSet::contains`]).
const ADMISSIBLE_TOLERANCE: f64 = 1e-9;

/// One allocator on one team's requests.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct EvaluationRow {
    /// The team's label ([`TeamRequests::label`]).
    pub team: String,
    /// The allocator's name.
    pub allocator: String,
    /// Attainable requests evaluated.
    pub attainable: usize,
    /// Attainable requests with relative `e_f <= EXACT_TOLERANCE`.
    pub exact: usize,
    /// Attainable requests with the whole wrench within `EXACT_TOLERANCE` of `||u_d||`.
    pub exact_wrench: usize,
    /// Mean relative `e_f` (`e_f / ||u_fd||`) over the attainable requests not allocated
    /// exactly (`None` when all are).
    pub mean_e_f_non_exact: Option<f64>,
    /// Their largest relative `e_f`.
    pub max_e_f_non_exact: Option<f64>,
    /// Mean solve rounds over every request.
    pub mean_rounds: f64,
    /// Most solve rounds of any request.
    pub max_rounds: u32,
    /// Outside requests evaluated.
    pub outside: usize,
    /// Mean relative `e_f` over the outside requests (`None` without any).
    pub mean_e_f_outside: Option<f64>,
    /// Mean relative whole-wrench error `||u_d - M f|| / ||u_d||` over the outside requests.
    pub mean_wrench_error_outside: Option<f64>,
    /// Requests whose forces are not finite, leave an agent's `E_f`, or load a failed agent
    /// (must be 0: every allocator returns admissible forces).
    pub inadmissible: usize,
    /// Requests the allocator answered with its fallback.
    pub fallbacks: usize,
    /// Per attainable kind, in the set's order: `(kind, exact, requests)`.
    pub exact_by_kind: Vec<(String, usize, usize)>,
}

impl EvaluationRow {
    /// `exact / attainable` (1 without attainable requests).
    pub fn exact_fraction(&self) -> f64 {
        if self.attainable == 0 {
            1.0
        } else {
            self.exact as f64 / self.attainable as f64
        }
    }
}

/// [`evaluate_requests`] for every team of `set` and every allocator of `names`.
pub fn evaluate_set(set: &AllocationSet, names: &[&str]) -> Result<Vec<EvaluationRow>, StudyError> {
    let mut rows = Vec::new();
    for team in &set.teams {
        for name in names {
            rows.push(evaluate_requests(team, &team.requests, name)?);
        }
    }
    Ok(rows)
}

/// The allocator `name` (default options) on `requests` of `team`, each allocated from a reset
/// allocator (no warm start from the previous request: the requests are independent).
pub fn evaluate_requests(
    team: &TeamRequests,
    requests: &[SetRequest],
    name: &str,
) -> Result<EvaluationRow, StudyError> {
    // The capacity is the team's size, as a flight build would choose it.
    match team_size(&team.team)? {
        0..=4 => evaluate_with::<4>(team, requests, name),
        5..=6 => evaluate_with::<6>(team, requests, name),
        7..=8 => evaluate_with::<8>(team, requests, name),
        _ => evaluate_with::<16>(team, requests, name),
    }
}

fn evaluate_with<const N: usize>(
    team_requests: &TeamRequests,
    requests: &[SetRequest],
    name: &str,
) -> Result<EvaluationRow, StudyError> {
    let t = team::<N>(&team_requests.team)?;
    let mask = failure_mask(&t, &team_requests.failed)?;
    let effectiveness = t.effectiveness(&mask);
    let sets = [AdmissibleSet::from_limits(t.limits()); N];
    let mut allocator = AnyAllocator::<f64, N>::from_name(name, &AllocatorOptions::default())
        .map_err(|e| StudyError::invalid_team(format!("allocator `{name}`: {e}")))?;
    allocator.configure(&effectiveness);
    let mut row = EvaluationRow {
        team: team_requests.label(),
        allocator: name.to_string(),
        attainable: 0,
        exact: 0,
        exact_wrench: 0,
        mean_e_f_non_exact: None,
        max_e_f_non_exact: None,
        mean_rounds: 0.0,
        max_rounds: 0,
        outside: 0,
        mean_e_f_outside: None,
        mean_wrench_error_outside: None,
        inadmissible: 0,
        fallbacks: 0,
        exact_by_kind: Vec::new(),
    };
    let (mut non_exact, mut outside_e_f, mut outside_wrench) = (Vec::new(), Vec::new(), Vec::new());
    let mut rounds = 0u64;
    for r in requests {
        let wrench = Vector6::from_column_slice(&r.wrench);
        allocator.reset();
        let a = allocator.allocate(&AllocationRequest {
            effectiveness: &effectiveness,
            sets: &sets,
            wrench,
        });
        rounds += u64::from(a.rounds);
        row.max_rounds = row.max_rounds.max(a.rounds);
        row.fallbacks += usize::from(a.fallback);
        let admissible = a.forces.iter().enumerate().all(|(i, f)| {
            f.iter().all(|x| x.is_finite())
                && if i < t.len() && !mask.is_failed(i) {
                    sets[i].contains(&GimbalCommand::from_force(f), ADMISSIBLE_TOLERANCE)
                } else {
                    *f == Vector3::zeros()
                }
        });
        row.inadmissible += usize::from(!admissible);
        let u_f = wrench.fixed_rows::<3>(3).norm();
        let e_f = a.e_f / u_f;
        let wrench_error = a.wrench_error / wrench.norm();
        if r.attainable() {
            row.attainable += 1;
            let exact = e_f <= EXACT_TOLERANCE;
            match row.exact_by_kind.iter_mut().find(|(k, _, _)| *k == r.kind) {
                Some(entry) => {
                    entry.1 += usize::from(exact);
                    entry.2 += 1;
                }
                None => row
                    .exact_by_kind
                    .push((r.kind.clone(), usize::from(exact), 1)),
            }
            if exact {
                row.exact += 1;
            } else {
                non_exact.push(e_f);
            }
            row.exact_wrench += usize::from(wrench_error <= EXACT_TOLERANCE);
        } else {
            row.outside += 1;
            outside_e_f.push(e_f);
            outside_wrench.push(wrench_error);
        }
    }
    row.mean_rounds = rounds as f64 / requests.len().max(1) as f64;
    row.mean_e_f_non_exact = mean(&non_exact);
    row.max_e_f_non_exact = non_exact.iter().copied().reduce(f64::max);
    row.mean_e_f_outside = mean(&outside_e_f);
    row.mean_wrench_error_outside = mean(&outside_wrench);
    Ok(row)
}

fn mean(values: &[f64]) -> Option<f64> {
    (!values.is_empty()).then(|| values.iter().sum::<f64>() / values.len() as f64)
}

fn sci(v: Option<f64>) -> String {
    v.map_or_else(|| "-".into(), |x| format!("{x:.2e}"))
}

fn fixed(v: Option<f64>) -> String {
    v.map_or_else(|| "-".into(), |x| format!("{x:.4}"))
}

/// The evaluation as a markdown table.
pub fn markdown_table(rows: &[EvaluationRow]) -> String {
    let mut out = String::from(
        "| team | allocator | exact (e_f) | exact (wrench) | mean / max rel. e_f, not exact | \
         mean / max rounds | outside: mean rel. e_f / wrench error | inadmissible | fallbacks |\n\
         |---|---|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        out += &format!(
            "| {} | {} | {}/{} ({:.1}%) | {}/{} | {} / {} | {:.2} / {} | {} / {} | {} | {} |\n",
            r.team,
            r.allocator,
            r.exact,
            r.attainable,
            100.0 * r.exact_fraction(),
            r.exact_wrench,
            r.attainable,
            sci(r.mean_e_f_non_exact),
            sci(r.max_e_f_non_exact),
            r.mean_rounds,
            r.max_rounds,
            sci(r.mean_e_f_outside),
            sci(r.mean_wrench_error_outside),
            r.inadmissible,
            r.fallbacks,
        );
    }
    out
}

/// The exact counts by attainable kind as a markdown table (`exact/requests` per kind).
pub fn markdown_by_kind(rows: &[EvaluationRow]) -> String {
    let kinds: Vec<&str> = rows
        .first()
        .map(|r| r.exact_by_kind.iter().map(|(k, _, _)| k.as_str()).collect())
        .unwrap_or_default();
    let mut out = format!("| team | allocator | {} |\n|---|---|", kinds.join(" | "));
    out += &"---|".repeat(kinds.len());
    out += "\n";
    for r in rows {
        out += &format!("| {} | {} |", r.team, r.allocator);
        for kind in &kinds {
            let cell = r
                .exact_by_kind
                .iter()
                .find(|(k, _, _)| k == kind)
                .map_or_else(|| "-".to_string(), |(_, e, n)| format!("{e}/{n}"));
            out += &format!(" {cell} |");
        }
        out += "\n";
    }
    out
}

/// The `s = 1` paper-tilt flight with one allocator (f64 controller).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ClosedLoopRow {
    /// The allocator's name.
    pub allocator: String,
    /// Largest `e_f` of the flight (N).
    pub max_e_f: Option<f64>,
    /// `max e_f / (m_C g)`.
    pub max_e_f_over_weight: Option<f64>,
    /// Largest position error (m) (the initial offset of paper-tilt, 0.707 m, for a flight that
    /// does not stray further).
    pub max_position_error: f64,
    /// Largest position error from `t = 4 s` (m).
    pub max_position_error_after_4s: f64,
    /// Largest position error over `6 s <= t <= 12 s`, the tilt (m).
    pub max_position_error_6_to_12s: Option<f64>,
    /// Horizontal error at `t = 12 s` (m).
    pub horizontal_error_at_12s: Option<f64>,
    /// Final position error (m).
    pub final_position_error: f64,
    /// Control periods with a saturated agent.
    pub saturated_periods: usize,
    /// Cycles the controller refused.
    pub cycle_errors: usize,
}

/// The built-in `paper-tilt` flown with relaxation `s = 1` once per allocator of `names` (the
/// summary of `tvmd-sim run paper-tilt --relaxation 1 --allocator NAME`).
pub fn closed_loop_rows(names: &[&str]) -> Result<Vec<ClosedLoopRow>, StudyError> {
    names
        .iter()
        .map(|name| {
            let scenario = Scenario::builtin("paper-tilt")?.with_overrides(&Overrides {
                relaxation: Some(1.0),
                allocator: Some((*name).to_string()),
                ..Overrides::default()
            })?;
            let result = run_scenario(&scenario, None, None)?;
            let s = result.summary;
            Ok(ClosedLoopRow {
                allocator: (*name).to_string(),
                max_e_f: s.max_e_f,
                max_e_f_over_weight: s.max_e_f_over_weight,
                max_position_error: s.max_position_error,
                max_position_error_after_4s: s.max_position_error_after_4s,
                max_position_error_6_to_12s: result.paper.max_position_error_6_to_12s,
                horizontal_error_at_12s: s.horizontal_error_at_12s,
                final_position_error: s.final_position_error,
                saturated_periods: s.saturated_periods,
                cycle_errors: s.cycle_errors,
            })
        })
        .collect()
}

/// The closed-loop rows as a markdown table.
pub fn markdown_closed_loop(rows: &[ClosedLoopRow]) -> String {
    let mut out = String::from(
        "| allocator | max e_f (N) | max e_f / (m_C g) | max position error (m): all / t >= 4 s \
         / 6-12 s | horizontal error at 12 s (m) | final position error (m) | saturated periods \
         | skipped cycles |\n|---|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        out += &format!(
            "| {} | {} | {} | {:.4} / {:.4} / {} | {} | {:.4} | {} | {} |\n",
            r.allocator,
            sci(r.max_e_f),
            sci(r.max_e_f_over_weight),
            r.max_position_error,
            r.max_position_error_after_4s,
            fixed(r.max_position_error_6_to_12s),
            fixed(r.horizontal_error_at_12s),
            r.final_position_error,
            r.saturated_periods,
            r.cycle_errors,
        );
    }
    out
}
