//! `tvmd-sim montecarlo SCENARIO --runs N --seed S`: the binary parses these arguments and
//! prints what [`run`] returns.

use std::path::PathBuf;
use std::sync::atomic::AtomicBool;

use super::conditions::{Conditions, GustCondition};
use super::{fly_all_until, text_table, with_law, Distributions, ReportFiles, Study, StudyReport};
use crate::StudyError;
use tvmd_plant::turbulence::Turbulence;
use tvmd_scenario::{LawConfig, Scenario};

/// Arguments of `tvmd-sim montecarlo`.
#[derive(Debug, Clone)]
pub struct MonteCarloRequest {
    /// A built-in scenario name (see `tvmd-sim list`) or a TOML file
    /// ([`super::DEFAULT_SCENARIO`] by default).
    pub scenario: String,
    /// The control law every flight flies; `None`: the scenario's own.
    pub law: Option<LawConfig>,
    /// Flights per team, allocator and model-error level.
    pub runs: usize,
    /// Seed of every draw (flight k of a group always draws the same errors).
    pub seed: u64,
    /// Catalogue teams, comma-separated (default: the scenario's).
    pub teams: Vec<String>,
    /// Allocators, comma-separated (default: the scenario's).
    pub allocators: Vec<String>,
    /// Model-error multipliers, comma-separated, one group each (default: 1).
    pub model_error: Vec<f64>,
    /// Mass error half-width (plant mass over the model's in `[1 - e, 1 + e]`).
    pub mass: Option<f64>,
    /// Inertia error half-width.
    pub inertia: Option<f64>,
    /// Centre-of-mass offset half-width per axis (m).
    pub com_offset: Option<f64>,
    /// Thrust efficiency loss half-width per agent (efficiency in `[1 - e, 1]`).
    pub thrust_efficiency: Option<f64>,
    /// Gimbal offset half-width per agent and axis (rad).
    pub gimbal_offset: Option<f64>,
    /// Initial horizontal offset half-width per axis (m).
    pub initial_position: Option<f64>,
    /// Largest initial tilt (rad, at most 2.5; the scenario must start in the air).
    pub initial_tilt: Option<f64>,
    /// Dryden turbulence in every flight: `W20`, the wind speed 20 ft above ground (m/s), at
    /// the scenario's initial height ([`super::conditions::Conditions::turbulence`]).
    pub turbulence: Option<f64>,
    /// A `1 - cos` gust of this peak speed (m/s, 2 s long) in every flight
    /// ([`super::conditions::Conditions::gust`]).
    pub gust: Option<f64>,
    /// Directory for `flights.csv`, `groups.csv` and the PNG figures (default:
    /// `out/montecarlo/<scenario>`).
    pub out: Option<PathBuf>,
    /// Worker threads (default: every core).
    pub jobs: Option<usize>,
}

impl MonteCarloRequest {
    /// The study these arguments describe.
    pub fn study(&self) -> Result<Study, StudyError> {
        let scenario = with_law(Scenario::load(&self.scenario)?, self.law)?;
        let d = Distributions::default();
        let height = scenario.initial_position[2].max(0.0);
        for (name, v) in [("turbulence", self.turbulence), ("gust", self.gust)] {
            if v.is_some_and(|v| !(v.is_finite() && v >= 0.0)) {
                return Err(StudyError::InvalidArgument {
                    name: name.into(),
                    reason: format!("{} m/s: must be finite and at least 0", v.unwrap_or(0.0)),
                });
            }
        }
        let conditions = Conditions {
            turbulence: self.turbulence.map(|w20| Turbulence::standard(w20, height)),
            gust: self.gust.map(|speed| GustCondition {
                speed,
                duration: 2.0,
            }),
            ..d.conditions
        };
        let or = |v: Option<f64>, default: f64| v.unwrap_or(default);
        Ok(Study {
            runs: self.runs,
            seed: self.seed,
            teams: self.teams.clone(),
            allocators: self.allocators.clone(),
            model_errors: self.model_error.clone(),
            distributions: Distributions {
                model_error: d.model_error,
                mass: or(self.mass, d.mass),
                inertia: or(self.inertia, d.inertia),
                com_offset: or(self.com_offset, d.com_offset),
                thrust_efficiency: or(self.thrust_efficiency, d.thrust_efficiency),
                gimbal_offset: or(self.gimbal_offset, d.gimbal_offset),
                initial_position: or(self.initial_position, d.initial_position),
                initial_tilt: or(self.initial_tilt, d.initial_tilt),
                conditions,
            },
            scenario,
        })
    }

    /// The output directory.
    pub fn out_dir(&self, study: &Study) -> PathBuf {
        self.out.clone().unwrap_or_else(|| {
            PathBuf::from("out")
                .join("montecarlo")
                .join(tvmd_log::paths::file_stem(&study.scenario.name))
        })
    }
}

/// What a study printed and wrote.
#[derive(Debug)]
pub struct MonteCarloOutput {
    /// The group table as text.
    pub table: String,
    /// Overall success rate.
    pub success_rate: f64,
    /// Flights flown (and reported).
    pub flights: usize,
    /// Flights asked for.
    pub total: usize,
    /// Whether the study was stopped: the report then holds the `flights` finished of `total`.
    pub interrupted: bool,
    /// The files written.
    pub files: ReportFiles,
}

/// Runs the study of `args`; `progress(done, total)` after each flight.
pub fn run(
    args: &MonteCarloRequest,
    progress: Option<&(dyn Fn(usize, usize) + Sync)>,
) -> Result<MonteCarloOutput, StudyError> {
    run_until(args, progress, None)
}

/// [`run`], stopping once `cancel` is set: the report (tables and figures) then holds the
/// flights that finished and says so (`interrupted`). The output directory is checked before
/// the first flight.
pub fn run_until(
    args: &MonteCarloRequest,
    progress: Option<&(dyn Fn(usize, usize) + Sync)>,
    cancel: Option<&AtomicBool>,
) -> Result<MonteCarloOutput, StudyError> {
    let study = args.study()?;
    let specs = study.specs()?;
    let out = args.out_dir(&study);
    tvmd_log::paths::check_output_dir(&out, "the report directory (--out)")?;
    let total = specs.len();
    let each = progress.map(|p| move |done: usize| p(done, total));
    let flown = fly_all_until(
        &specs,
        args.jobs,
        each.as_ref().map(|f| f as &(dyn Fn(usize) + Sync)),
        cancel,
    )?;
    if flown.interrupted && flown.rows.is_empty() {
        return Err(StudyError::Interrupted(format!(
            "stopped before any of the {total} flights finished; nothing written"
        )));
    }
    let report = StudyReport::new(flown.rows, Some(&out))?;
    Ok(MonteCarloOutput {
        table: text_table(&report.groups),
        success_rate: report.success_rate,
        flights: report.flights.len(),
        total,
        interrupted: flown.interrupted,
        files: report
            .files
            .ok_or_else(|| StudyError::Internal("the report wrote no files".into()))?,
    })
}

#[cfg(test)]
mod tests {
    use super::super::DEFAULT_SCENARIO;
    use super::*;

    fn request(scenario: &str, law: Option<LawConfig>) -> MonteCarloRequest {
        MonteCarloRequest {
            scenario: scenario.into(),
            law,
            runs: 1,
            seed: 0,
            teams: Vec::new(),
            allocators: Vec::new(),
            model_error: Vec::new(),
            mass: None,
            inertia: None,
            com_offset: None,
            thrust_efficiency: None,
            gimbal_offset: None,
            initial_position: None,
            initial_tilt: None,
            turbulence: None,
            gust: None,
            out: None,
            jobs: None,
        }
    }

    /// Issue 61: a study that names no scenario flies the library's default law, and `law`
    /// replaces any scenario's own.
    #[test]
    fn the_default_study_flies_the_default_law_and_law_replaces_the_scenarios() {
        let default = request(DEFAULT_SCENARIO, None).study().unwrap();
        assert_eq!(default.scenario.law, LawConfig::default());
        let paper = request("paper-tilt", None).study().unwrap();
        assert!(paper.scenario.law.is_paper());
        let overridden = request("paper-tilt", Some(LawConfig::default()))
            .study()
            .unwrap();
        assert_eq!(overridden.scenario.law, LawConfig::default());
        let hover_paper = request(DEFAULT_SCENARIO, Some(LawConfig::paper()))
            .study()
            .unwrap();
        assert!(hover_paper.scenario.law.is_paper());
    }
}
