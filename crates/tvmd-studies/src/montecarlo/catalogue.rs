//! `tvmd-sim catalogue`: every catalogue team with every allocator through four tasks, as one
//! results table (README, "Results across the catalogue"): the nominal step response
//! (`reference-jump`), wind (`wind`), a one-agent failure (`agent-failure`) and model error
//! (`hover` with the default distributions, `--runs` flights).

use std::path::PathBuf;
use std::sync::atomic::AtomicBool;

use serde::Serialize;
use tvmd_core::presets::Preset;

use super::{fly_all_until, with_law, Distributions, FlightRow, Study};
use crate::StudyError;
use tvmd_scenario::{LawConfig, Scenario};

/// The allocators of the table by default (the Clarabel ones need the `clarabel` feature).
pub const ALLOCATORS: [&str; 4] = [
    "pseudo-inverse",
    "weighted-pseudo-inverse",
    "redistributed-pseudo-inverse",
    "exact-boundary-redistribution",
];

/// The tasks: column name and built-in scenario.
pub const TASKS: [(&str, &str); 4] = [
    ("nominal", "reference-jump"),
    ("wind", "wind"),
    ("failure", "agent-failure"),
    ("model error", "hover"),
];

/// What the catalogue flies and where it writes (`tvmd-sim catalogue`'s options).
#[derive(Debug, Clone)]
pub struct CatalogueSettings {
    /// Model-error flights per team and allocator.
    pub runs: usize,
    /// Seed of the model-error draws.
    pub seed: u64,
    /// Catalogue teams, comma-separated (default: all 20).
    pub teams: Vec<String>,
    /// Allocators, comma-separated (default: the four without the `clarabel` feature).
    pub allocators: Vec<String>,
    /// The control law of every task; `None`: the tasks' own (the families' default law).
    pub law: Option<LawConfig>,
    /// Write `catalogue.csv` (one row per team and allocator) and `catalogue.md` here.
    pub out: Option<PathBuf>,
    /// Worker threads (default: every core).
    pub jobs: Option<usize>,
}

/// One row of the table: a team and an allocator through the four tasks.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CatalogueRow {
    /// Team.
    pub team: String,
    /// Allocator.
    pub allocator: String,
    /// The step response met its bounds.
    pub nominal: bool,
    /// 2% settling time of the step (s).
    pub nominal_settling_time: Option<f64>,
    /// The wind hover met its bounds.
    pub wind: bool,
    /// Steady-state position error in the wind (m).
    pub wind_steady_state: Option<f64>,
    /// The one-agent failure met its bounds.
    pub failure: bool,
    /// Peak position error over the failure flight (m).
    pub failure_peak: Option<f64>,
    /// Share of the model-error flights that met their bounds.
    pub model_error_success_rate: f64,
    /// Median steady-state position error of the model-error flights (m).
    pub model_error_median_steady_state: Option<f64>,
}

/// The study of one task: deterministic tasks fly once with no draw, the model-error task
/// `runs` times with the default distributions.
fn task_study(
    scenario: &str,
    teams: &[String],
    allocators: &[String],
    args: &CatalogueSettings,
) -> Result<Study, StudyError> {
    let base = with_law(Scenario::builtin(scenario)?, args.law)?;
    let model_error = scenario == "hover";
    let none = Distributions {
        model_error: 0.0,
        initial_position: 0.0,
        initial_tilt: 0.0,
        conditions: super::Conditions::none(),
        ..Distributions::default()
    };
    Ok(Study {
        scenario: base,
        runs: if model_error { args.runs } else { 1 },
        seed: args.seed,
        teams: teams.to_vec(),
        allocators: allocators.to_vec(),
        model_errors: Vec::new(),
        distributions: if model_error {
            Distributions::default()
        } else {
            none
        },
    })
}

/// Flies the table; returns its rows and every flight.
pub fn run(args: &CatalogueSettings) -> Result<(Vec<CatalogueRow>, Vec<FlightRow>), StudyError> {
    run_until(args, None)
}

/// [`run`], stopping once `cancel` is set: [`StudyError::Interrupted`], after writing the
/// finished flights to `catalogue-flights.csv` when `out` is given (the table needs them all).
/// The output directory is checked before the first flight.
pub fn run_until(
    args: &CatalogueSettings,
    cancel: Option<&AtomicBool>,
) -> Result<(Vec<CatalogueRow>, Vec<FlightRow>), StudyError> {
    if let Some(dir) = &args.out {
        tvmd_log::paths::check_output_dir(dir, "the catalogue directory (--out)")?;
    }
    let teams: Vec<String> = if args.teams.is_empty() {
        Preset::ALL.iter().map(|p| p.name().to_string()).collect()
    } else {
        args.teams.clone()
    };
    let allocators: Vec<String> = if args.allocators.is_empty() {
        ALLOCATORS.iter().map(|a| a.to_string()).collect()
    } else {
        args.allocators.clone()
    };
    let mut specs = Vec::new();
    for (_, scenario) in TASKS {
        specs.extend(task_study(scenario, &teams, &allocators, args)?.specs()?);
    }
    let flown = fly_all_until(&specs, args.jobs, None, cancel)?;
    if flown.interrupted {
        let kept = match &args.out {
            Some(dir) => {
                let path = dir.join("catalogue-flights.csv");
                super::write_csv(&flown.rows, &path)?;
                format!("written to {}", path.display())
            }
            None => "not written (no output directory)".into(),
        };
        return Err(StudyError::Interrupted(format!(
            "the catalogue was stopped: {} of {} flights finished, {kept}; no table",
            flown.rows.len(),
            flown.total
        )));
    }
    let flights = flown.rows;
    let mut rows = Vec::new();
    for team in &teams {
        for allocator in &allocators {
            let of = |scenario: &str| -> Vec<&FlightRow> {
                let name = Scenario::builtin(scenario)
                    .map(|s| s.name)
                    .unwrap_or_default();
                flights
                    .iter()
                    .filter(|f| &f.team == team && &f.allocator == allocator && f.scenario == name)
                    .collect()
            };
            let one = |scenario: &str| of(scenario).first().map(|f| (*f).clone());
            let nominal = one("reference-jump");
            let wind = one("wind");
            let failure = one("agent-failure");
            let mc = of("hover");
            let successes = mc.iter().filter(|f| f.success).count();
            rows.push(CatalogueRow {
                team: team.clone(),
                allocator: allocator.clone(),
                nominal: nominal.as_ref().is_some_and(|f| f.success),
                nominal_settling_time: nominal.as_ref().and_then(|f| f.position_settling_time),
                wind: wind.as_ref().is_some_and(|f| f.success),
                wind_steady_state: wind.as_ref().and_then(|f| f.position_steady_state),
                failure: failure.as_ref().is_some_and(|f| f.success),
                failure_peak: failure.as_ref().and_then(|f| f.position_peak),
                model_error_success_rate: successes as f64 / mc.len().max(1) as f64,
                model_error_median_steady_state: super::quantile(
                    mc.iter().filter_map(|f| f.position_steady_state),
                    0.5,
                ),
            });
        }
    }
    Ok((rows, flights))
}

/// The rows as a Markdown table.
pub fn markdown(rows: &[CatalogueRow], runs: usize) -> String {
    let ok = |b: bool| if b { "pass" } else { "fail" };
    let opt = |v: Option<f64>, p: usize| v.map_or_else(|| "-".into(), |x| format!("{x:.p$}"));
    let mut out = format!(
        "| team | allocator | nominal step | settling (s) | wind | steady (m) | one-agent failure | peak (m) | model error ({runs} flights) | median steady (m) |\n|---|---|---|---|---|---|---|---|---|---|\n"
    );
    for r in rows {
        out.push_str(&format!(
            "| {} | {} | {} | {} | {} | {} | {} | {} | {:.0}% | {} |\n",
            r.team,
            r.allocator,
            ok(r.nominal),
            opt(r.nominal_settling_time, 2),
            ok(r.wind),
            opt(r.wind_steady_state, 3),
            ok(r.failure),
            opt(r.failure_peak, 3),
            100.0 * r.model_error_success_rate,
            opt(r.model_error_median_steady_state, 3),
        ));
    }
    out
}

/// Runs the table and writes its files if `out` is given; returns the Markdown.
pub fn run_and_write(args: &CatalogueSettings) -> Result<String, StudyError> {
    run_and_write_until(args, None)
}

/// [`run_and_write`], stopping once `cancel` is set ([`run_until`]).
pub fn run_and_write_until(
    args: &CatalogueSettings,
    cancel: Option<&AtomicBool>,
) -> Result<String, StudyError> {
    let (rows, flights) = run_until(args, cancel)?;
    let md = markdown(&rows, args.runs);
    if let Some(dir) = &args.out {
        super::write_csv(&flights, &dir.join("catalogue-flights.csv"))?;
        super::write_csv(&rows, &dir.join("catalogue.csv"))?;
        let path = dir.join("catalogue.md");
        tvmd_log::paths::write_file(&path, "write the table", md.as_bytes())?;
    }
    Ok(md)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_team_and_allocator_through_the_four_tasks() {
        let args = CatalogueSettings {
            runs: 2,
            seed: 0,
            teams: vec!["a6-inc".into()],
            allocators: vec!["exact-boundary-redistribution".into()],
            law: None,
            out: None,
            jobs: None,
        };
        let (rows, flights) = run(&args).unwrap();
        assert_eq!(flights.len(), 3 + 2);
        assert_eq!(rows.len(), 1);
        let r = &rows[0];
        // The step settles; the families' default law (offset-free) holds the wind's set-point
        // (the paper's law left it 0.3 m downwind: no integral action).
        assert!(r.nominal && r.nominal_settling_time.is_some(), "{r:?}");
        assert!(r.wind && r.wind_steady_state.unwrap() < 0.01, "{r:?}");
        let md = markdown(&rows, 2);
        assert!(
            md.lines().count() == 3
                && md.contains("| a6-inc | exact-boundary-redistribution | pass |"),
            "{md}"
        );
    }
}
