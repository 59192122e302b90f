//! The results of a study: one summary per group (team, allocator, model-error level) and the
//! tables as CSV.

use std::path::Path;

use serde::Serialize;

use super::flight::FlightRow;
use crate::StudyError;

/// The flights of one team, allocator and model-error level.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct GroupSummary {
    /// Team.
    pub team: String,
    /// Allocator.
    pub allocator: String,
    /// Model-error multiplier.
    pub model_error: f64,
    /// Flights.
    pub runs: usize,
    /// Flights whose verdict is a success.
    pub successes: usize,
    /// `successes / runs`.
    pub success_rate: f64,
    /// Flights no admissible command could hold ([`super::feasibility`]).
    pub infeasible: usize,
    /// Flights neither judged feasible nor infeasible.
    pub undecided: usize,
    /// Flights judged feasible.
    pub feasible: usize,
    /// Feasible flights whose verdict is a success.
    pub feasible_successes: usize,
    /// `feasible_successes / feasible` (`None` without a feasible flight).
    pub feasible_success_rate: Option<f64>,
    /// Flights that ended early (a flight error).
    pub errors: usize,
    /// Median steady-state position error (m).
    pub median_position_steady_state: Option<f64>,
    /// 90th percentile of the steady-state position error (m).
    pub p90_position_steady_state: Option<f64>,
    /// Median peak position error (m).
    pub median_position_peak: Option<f64>,
    /// Median 2% settling time of the position error, over the flights that settled (s).
    pub median_position_settling_time: Option<f64>,
    /// Flights whose position error settled.
    pub settled: usize,
    /// Median settling time of the attitude error to `R_d` (s).
    pub median_planned_attitude_settling_time: Option<f64>,
    /// Median of the mean thrust efficiency.
    pub median_thrust_efficiency: Option<f64>,
    /// Median time saturated (s).
    pub median_time_saturated: Option<f64>,
}

/// The `q`-quantile (linear between order statistics) of the finite values; `None` if none.
pub fn quantile(values: impl IntoIterator<Item = f64>, q: f64) -> Option<f64> {
    let mut v: Vec<f64> = values.into_iter().filter(|x| x.is_finite()).collect();
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    let at = q.clamp(0.0, 1.0) * (v.len() - 1) as f64;
    let (lo, hi) = (at.floor() as usize, at.ceil() as usize);
    Some(v[lo] + (v[hi] - v[lo]) * (at - lo as f64))
}

/// The group key of a row.
pub fn group_key(r: &FlightRow) -> (String, String, f64) {
    (r.team.clone(), r.allocator.clone(), r.model_error)
}

/// One summary per group, in the order the groups first appear.
pub fn group_summaries(rows: &[FlightRow]) -> Vec<GroupSummary> {
    let mut keys: Vec<(String, String, f64)> = Vec::new();
    for r in rows {
        let k = group_key(r);
        if !keys.contains(&k) {
            keys.push(k);
        }
    }
    keys.into_iter()
        .map(|k| {
            let g: Vec<&FlightRow> = rows.iter().filter(|r| group_key(r) == k).collect();
            let successes = g.iter().filter(|r| r.success).count();
            let judged = |name: &str| g.iter().filter(|r| r.feasibility == name).count();
            let feasible = judged("feasible");
            let feasible_successes = g
                .iter()
                .filter(|r| r.success && r.feasibility == "feasible")
                .count();
            let median = |f: &dyn Fn(&FlightRow) -> Option<f64>| {
                quantile(g.iter().filter_map(|r| f(r)), 0.5)
            };
            GroupSummary {
                runs: g.len(),
                successes,
                success_rate: successes as f64 / g.len().max(1) as f64,
                infeasible: judged("infeasible"),
                undecided: judged("undecided"),
                feasible,
                feasible_successes,
                feasible_success_rate: (feasible > 0)
                    .then(|| feasible_successes as f64 / feasible as f64),
                errors: g.iter().filter(|r| r.error.is_some()).count(),
                median_position_steady_state: median(&|r| r.position_steady_state),
                p90_position_steady_state: quantile(
                    g.iter().filter_map(|r| r.position_steady_state),
                    0.9,
                ),
                median_position_peak: median(&|r| r.position_peak),
                median_position_settling_time: median(&|r| r.position_settling_time),
                settled: g
                    .iter()
                    .filter(|r| r.position_settling_time.is_some())
                    .count(),
                median_planned_attitude_settling_time: median(&|r| {
                    r.planned_attitude_settling_time
                }),
                median_thrust_efficiency: median(&|r| r.mean_thrust_efficiency),
                median_time_saturated: median(&|r| Some(r.time_saturated)),
                team: k.0,
                allocator: k.1,
                model_error: k.2,
            }
        })
        .collect()
}

/// Writes `rows` as CSV with a header (empty cells for `None`).
pub fn write_csv<T: Serialize>(rows: &[T], path: &Path) -> Result<(), StudyError> {
    crate::plot::ensure_parent(path)?;
    const ACTION: &str = "write the table";
    let csv_err = |e: csv::Error| {
        let source = match e.into_kind() {
            csv::ErrorKind::Io(e) => e,
            other => std::io::Error::other(format!("{other:?}")),
        };
        StudyError::file(ACTION, path)(source)
    };
    tvmd_log::paths::write_via_temporary(path, ACTION, |temporary| {
        let mut w = csv::Writer::from_path(temporary).map_err(csv_err)?;
        for r in rows {
            w.serialize(r).map_err(csv_err)?;
        }
        w.flush().map_err(StudyError::file(ACTION, path))
    })
}

/// The group summaries as a fixed-width text table.
pub fn text_table(groups: &[GroupSummary]) -> String {
    let opt = |v: Option<f64>, p: usize| v.map_or_else(|| "-".into(), |x| format!("{x:.p$}"));
    let mut out = format!(
        "{:<16} {:<30} {:>6} {:>6} {:>8} {:>10} {:>10} {:>10} {:>10} {:>10} {:>9}\n",
        "team",
        "allocator",
        "error",
        "runs",
        "success",
        "infeasible",
        "feas. ok",
        "steady (m)",
        "peak (m)",
        "settle (s)",
        "thrust eff",
    );
    for g in groups {
        out.push_str(&format!(
            "{:<16} {:<30} {:>6} {:>6} {:>7.1}% {:>10} {:>10} {:>10} {:>10} {:>10} {:>9}\n",
            g.team,
            g.allocator,
            g.model_error,
            g.runs,
            100.0 * g.success_rate,
            if g.undecided > 0 {
                format!("{} (+{}?)", g.infeasible, g.undecided)
            } else {
                g.infeasible.to_string()
            },
            g.feasible_success_rate
                .map_or_else(|| "-".into(), |r| format!("{:.1}%", 100.0 * r)),
            opt(g.median_position_steady_state, 4),
            opt(g.median_position_peak, 3),
            opt(g.median_position_settling_time, 2),
            opt(g.median_thrust_efficiency, 4),
        ));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantiles_interpolate_and_skip_non_finite_values() {
        assert_eq!(quantile([3.0, 1.0, 2.0], 0.5), Some(2.0));
        assert_eq!(quantile([1.0, 2.0, 3.0, 4.0], 0.5), Some(2.5));
        assert_eq!(quantile([1.0, f64::NAN, 5.0], 1.0), Some(5.0));
        assert!((quantile((0..=10).map(f64::from), 0.9).unwrap() - 9.0).abs() < 1e-12);
        assert_eq!(quantile(Vec::<f64>::new(), 0.5), None);
    }
}
