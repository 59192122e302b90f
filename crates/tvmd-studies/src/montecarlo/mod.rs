//! Monte Carlo studies (`docs/method.md`, "Monte Carlo"): a scenario flown many times per team,
//! allocator and model-error level, each flight with a model error and initial conditions drawn
//! from stated [`Distributions`]; the results as a table (one [`FlightRow`] per flight, one
//! [`GroupSummary`] per group), CSV files and box plots.
//!
//! A flight is a [`FlightSpec`] (serialisable: a Python executor or a Dask cluster ships it as
//! JSON) flown by [`fly_flight`]; its draw depends only on the study's seed and the flight's
//! index, so the table is the same on one thread, many threads or many machines.

pub mod boxplot;
pub mod catalogue;
pub mod conditions;
pub mod distributions;
pub mod feasibility;
pub mod flight;
pub mod report;
mod study_run;

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

pub use conditions::{Conditions, GustCondition};
pub use distributions::{Distributions, Draw};
pub use flight::{fly_flight, fly_flight_until, FlightRow, FlightSpec};
pub use report::{group_summaries, quantile, text_table, write_csv, GroupSummary};
pub use study_run::{run, run_until, MonteCarloOutput, MonteCarloRequest};

use crate::StudyError;
use tvmd_scenario::{LawConfig, Overrides, Scenario};

/// Largest number of flights of one study.
pub const MAX_FLIGHTS: usize = 10_000_000;

/// The scenario a study flies when none is named (`tvmd-sim montecarlo`, Python's
/// `monte_carlo`): the hover family, which flies the library's default law. (`paper-tilt` names
/// the paper's law, which has no integral action: under any model error it fails every flight.)
pub const DEFAULT_SCENARIO: &str = "hover";

/// `scenario` with its control law replaced by `law` where one is given (`--law`, `law=`),
/// validated.
pub fn with_law(scenario: Scenario, law: Option<LawConfig>) -> Result<Scenario, StudyError> {
    match law {
        None => Ok(scenario),
        Some(law) => Ok(scenario.with_overrides(&Overrides {
            law: Some(law),
            ..Overrides::default()
        })?),
    }
}

/// A study: `runs` flights of `scenario` for every team, allocator and model-error level.
#[derive(Clone, Debug, PartialEq)]
pub struct Study {
    /// The base scenario.
    pub scenario: Scenario,
    /// Flights per group.
    pub runs: usize,
    /// Seed of every draw.
    pub seed: u64,
    /// Catalogue teams; empty: the scenario's own team.
    pub teams: Vec<String>,
    /// Allocators; empty: the scenario's.
    pub allocators: Vec<String>,
    /// Model-error multipliers (each a group of its own); empty: the distributions' own.
    pub model_errors: Vec<f64>,
    /// The distributions.
    pub distributions: Distributions,
}

impl Study {
    /// A study of `runs` flights of `scenario` with the default distributions.
    pub fn new(scenario: Scenario, runs: usize, seed: u64) -> Self {
        Self {
            scenario,
            runs,
            seed,
            teams: Vec::new(),
            allocators: Vec::new(),
            model_errors: Vec::new(),
            distributions: Distributions::default(),
        }
    }

    /// Every flight, group by group (team, then allocator, then level), each checked: an
    /// unknown team or allocator, bad distributions or a draw that makes an invalid scenario
    /// (a tilted start on the ground) fail here, before anything flies.
    pub fn specs(&self) -> Result<Vec<FlightSpec>, StudyError> {
        let bad = |name: &str, reason: String| StudyError::InvalidArgument {
            name: name.into(),
            reason,
        };
        if self.runs == 0 {
            return Err(bad("runs", "must be at least 1".into()));
        }
        let teams: Vec<Option<String>> = if self.teams.is_empty() {
            vec![None]
        } else {
            self.teams.iter().cloned().map(Some).collect()
        };
        let allocators = if self.allocators.is_empty() {
            vec![self.scenario.allocator.clone()]
        } else {
            self.allocators.clone()
        };
        let levels = if self.model_errors.is_empty() {
            vec![self.distributions.model_error]
        } else {
            self.model_errors.clone()
        };
        let total = teams.len() * allocators.len() * levels.len() * self.runs;
        if total > MAX_FLIGHTS {
            return Err(bad(
                "runs",
                format!("{total} flights in all, above {MAX_FLIGHTS}"),
            ));
        }
        let scenario_toml = self.scenario.to_toml_string()?;
        let mut specs = Vec::with_capacity(total);
        for team in &teams {
            for allocator in &allocators {
                for &model_error in &levels {
                    let distributions = Distributions {
                        model_error,
                        ..self.distributions
                    };
                    distributions.validate()?;
                    for index in 0..self.runs as u64 {
                        specs.push(FlightSpec {
                            scenario_toml: scenario_toml.clone(),
                            team: team.clone(),
                            allocator: allocator.clone(),
                            seed: self.seed,
                            index,
                            distributions,
                        });
                    }
                    // The first flight of each group stands for its team and allocator.
                    if let Some(last) = specs.last() {
                        let first = FlightSpec {
                            index: 0,
                            ..last.clone()
                        };
                        first.scenario()?;
                    }
                }
            }
        }
        Ok(specs)
    }
}

/// Flies every spec on `jobs` threads (default: every core), rows in input order;
/// `progress(done)` after each flight. `Err` if a flight could not start (its index named).
pub fn fly_all(
    specs: &[FlightSpec],
    jobs: Option<usize>,
    progress: Option<&(dyn Fn(usize) + Sync)>,
) -> Result<Vec<FlightRow>, StudyError> {
    Ok(fly_all_until(specs, jobs, progress, None)?.rows)
}

/// The flights [`fly_all_until`] finished.
#[derive(Clone, Debug, PartialEq)]
pub struct Flown {
    /// The finished flights' rows, in input order.
    pub rows: Vec<FlightRow>,
    /// The flights asked for.
    pub total: usize,
    /// Whether `cancel` stopped the study (then `rows` holds fewer than `total`).
    pub interrupted: bool,
}

/// [`fly_all`], stopping once `cancel` is set: the flights in the air stop at their next
/// controller tick and are dropped, the others do not start; the finished rows are kept.
pub fn fly_all_until(
    specs: &[FlightSpec],
    jobs: Option<usize>,
    progress: Option<&(dyn Fn(usize) + Sync)>,
    cancel: Option<&AtomicBool>,
) -> Result<Flown, StudyError> {
    let stopped = || cancel.is_some_and(|c| c.load(Ordering::Relaxed));
    let done = std::sync::atomic::AtomicUsize::new(0);
    let workers = tvmd_sim::pool::worker_count(jobs, specs.len());
    let rows = tvmd_sim::pool::map_in_order(specs, workers, |_, spec| {
        if stopped() {
            return Ok(None);
        }
        let row = fly_flight_until(spec, cancel);
        let n = done.fetch_add(1, Ordering::Relaxed) + 1;
        if let Some(p) = progress {
            p(n);
        }
        row
    });
    let mut finished = Vec::with_capacity(specs.len());
    for (k, r) in rows.into_iter().enumerate() {
        match r {
            Some(Ok(Some(row))) => finished.push(row),
            Some(Ok(None)) => {}
            Some(Err(e)) => {
                return Err(StudyError::InvalidArgument {
                    name: format!("flight {k}"),
                    reason: e.to_string(),
                })
            }
            None => return Err(StudyError::Internal(format!("flight {k} did not finish"))),
        }
    }
    Ok(Flown {
        interrupted: finished.len() < specs.len() && stopped(),
        total: specs.len(),
        rows: finished,
    })
}

/// What [`write_report`] wrote.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct ReportFiles {
    /// One row per flight.
    pub flights: PathBuf,
    /// One row per group.
    pub groups: PathBuf,
    /// The figures.
    pub plots: Vec<PathBuf>,
}

/// Writes `flights.csv`, `groups.csv` and the figures into `dir`.
pub fn write_report(rows: &[FlightRow], dir: &Path) -> Result<ReportFiles, StudyError> {
    let groups = group_summaries(rows);
    let files = ReportFiles {
        flights: dir.join("flights.csv"),
        groups: dir.join("groups.csv"),
        plots: Vec::new(),
    };
    write_csv(rows, &files.flights)?;
    write_csv(&groups, &files.groups)?;
    let plots = boxplot::write_plots(rows, &groups, dir)?;
    Ok(ReportFiles { plots, ..files })
}

/// A study's results: every flight, the group summaries, the overall success rate and the
/// files written (with an output directory).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct StudyReport {
    /// One row per flight.
    pub flights: Vec<FlightRow>,
    /// One summary per group.
    pub groups: Vec<GroupSummary>,
    /// Successful flights over all flights.
    pub success_rate: f64,
    /// The CSV tables and figures, when written.
    pub files: Option<ReportFiles>,
}

impl StudyReport {
    /// The report of `rows`, writing the tables and figures into `out` if given.
    pub fn new(rows: Vec<FlightRow>, out: Option<&Path>) -> Result<Self, StudyError> {
        if let Some(dir) = out {
            tvmd_log::paths::check_output_dir(dir, "the report directory (`out`)")?;
        }
        let files = out.map(|dir| write_report(&rows, dir)).transpose()?;
        let successes = rows.iter().filter(|r| r.success).count();
        Ok(Self {
            groups: group_summaries(&rows),
            success_rate: successes as f64 / rows.len().max(1) as f64,
            flights: rows,
            files,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn short_hover() -> Scenario {
        let mut s = Scenario::builtin("hover").unwrap();
        s.duration = 2.0;
        s.success.steady_state_window = 0.5;
        s
    }

    #[test]
    fn specs_cover_every_group_and_rows_do_not_depend_on_threads() {
        let mut study = Study::new(short_hover(), 3, 11);
        study.teams = vec!["a4-inc".into(), "a6-inc".into()];
        study.model_errors = vec![0.0, 1.0];
        study.distributions.initial_position = 0.0;
        let specs = study.specs().unwrap();
        assert_eq!(specs.len(), 2 * 2 * 3);
        let one = fly_all(&specs, Some(1), None).unwrap();
        let two = fly_all(&specs, Some(2), None).unwrap();
        assert_eq!(one, two);
        // Through JSON, as an executor ships it: the same row.
        let back = FlightSpec::from_json(&specs[4].to_json().unwrap()).unwrap();
        assert_eq!(fly_flight(&back).unwrap(), one[4]);
        let groups = group_summaries(&one);
        assert_eq!(groups.len(), 4);
        assert!(groups.iter().all(|g| g.runs == 3));
        // Small errors: every plant can hold the hover, and the groups count it so.
        assert!(one
            .iter()
            .all(|r| r.feasibility == "feasible" && r.infeasible_at.is_none()));
        assert!(groups
            .iter()
            .all(|g| g.feasible == 3 && g.infeasible == 0 && g.undecided == 0));
        assert!(groups
            .iter()
            .all(|g| g.feasible_success_rate == Some(g.success_rate)));
        // The nominal plant hovers: every flight of model error 0 succeeds.
        let nominal: Vec<_> = groups.iter().filter(|g| g.model_error == 0.0).collect();
        assert!(nominal.iter().all(|g| g.success_rate == 1.0), "{nominal:?}");
        assert!(one
            .iter()
            .filter(|r| r.model_error == 0.0)
            .all(|r| r.mass_scale == 1.0));
    }

    #[test]
    fn bad_studies_fail_before_flying() {
        let mut s = Study::new(short_hover(), 0, 1);
        assert!(s.specs().unwrap_err().to_string().contains("runs"));
        s.runs = 2;
        s.teams = vec!["a99".into()];
        assert!(s.specs().unwrap_err().to_string().contains("team"));
        s.teams.clear();
        s.allocators = vec!["nope".into()];
        assert!(s.specs().unwrap_err().to_string().contains("allocator"));
        s.allocators.clear();
        let mut tilted = Study::new(Scenario::builtin("paper-tilt").unwrap(), 2, 1);
        tilted.distributions.initial_tilt = 0.5;
        let e = tilted.specs().unwrap_err().to_string();
        assert!(e.contains("initial_attitude"), "{e}");
    }

    #[test]
    fn the_report_writes_tables_and_figures() {
        let mut study = Study::new(short_hover(), 4, 3);
        study.model_errors = vec![0.5, 2.0];
        let rows = fly_all(&study.specs().unwrap(), None, None).unwrap();
        let dir = std::env::temp_dir().join(format!("tvmd-mc-{}", std::process::id()));
        let files = write_report(&rows, &dir).unwrap();
        let text = std::fs::read_to_string(&files.flights).unwrap();
        let header = text.lines().next().unwrap();
        assert!(
            header.starts_with("scenario,team,allocator,law,seed,index,model_error,"),
            "{header}"
        );
        assert_eq!(text.lines().count(), 1 + rows.len());
        let groups = std::fs::read_to_string(&files.groups).unwrap();
        assert_eq!(groups.lines().count(), 1 + 2);
        for p in &files.plots {
            let bytes = std::fs::read(p).unwrap();
            assert!(bytes.starts_with(b"\x89PNG"), "{}", p.display());
        }
        assert_eq!(files.plots.len(), boxplot::METRICS.len() + 1);
        let _ = std::fs::remove_dir_all(&dir);
    }
}
