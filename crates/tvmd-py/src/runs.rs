//! The batch machinery `tvmd.sim`'s functions share: a run's keyword arguments as a checked
//! `RunSpec` ([`RunArgs`]), the items of a `run_many` batch, the runs of a relaxation study, and
//! the batch flown on tvmd-sim's pool with the GIL released ([`run_specs`]). Both `sim` (the
//! threads) and `executor` (one run per task) build on it.

use std::path::{Path, PathBuf};

use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString};

use tvmd_scenario::{FaultDetectionConfig, LawConfig, LimitsConfig, TeamSpec};
use tvmd_sim::runner::{self, sweep_specs, RunOutcome, RunSpec};
use tvmd_sim::sim::SampleRetention;
use tvmd_sim::{RunRequest, ScenarioSource};

use crate::convert::round_cap_arg;
use crate::convert::{fault_detection_arg, law_arg, retention_arg, scalars};
use crate::convert::{scenario_source, shape_error, Int};
use crate::errors::{sim_error, value_error, WRITE};
use crate::interrupt::{interruptible, Ended};
use crate::sim_result::{PySimResult, SimData};
use crate::team::{team_spec, PyTeam};
use tvmd_core::RoundCap;

/// A `tvmd.Team` as a scenario's team and limits.
pub(crate) type TeamConfigArg = (TeamSpec, LimitsConfig);

/// The keys a `run_many` dict may hold (the keyword arguments of `run`).
const RUN_KEYS: &[&str] = &[
    "scenario",
    "team",
    "toml",
    "mcap",
    "relaxation",
    "allocator",
    "precision",
    "pil",
    "null_space",
    "max_samples",
    "law",
];

/// The arguments of one run, as `run` takes them.
#[derive(Default)]
pub(crate) struct RunArgs<'a, 'py> {
    pub(crate) scenario: Option<&'a Bound<'py, PyAny>>,
    pub(crate) toml: Option<String>,
    pub(crate) mcap: Option<PathBuf>,
    pub(crate) relaxation: Option<f64>,
    pub(crate) allocator: Option<String>,
    pub(crate) null_space: Option<String>,
    pub(crate) precision: Option<String>,
    pub(crate) pil: Option<String>,
    /// The converted `max_samples` ([`retention_arg`]).
    pub(crate) samples: SampleRetention,
    pub(crate) team: Option<String>,
    /// A `tvmd.Team` flown instead of the scenario's team ([`team_arg`]).
    pub(crate) team_config: Option<TeamConfigArg>,
    /// The converted `law` ([`law_arg`]), or None for the scenario's.
    pub(crate) law: Option<LawConfig>,
    /// The converted `fault_detection`, or None for the scenario's `[fault_detection]`.
    pub(crate) fault_detection: Option<FaultDetectionConfig>,
    /// `max_rounds`: the scenario's `allocator_max_rounds` replaced, or None for its own.
    pub(crate) max_rounds: Option<RoundCap>,
}

impl RunArgs<'_, '_> {
    /// The one run request of the CLI and Python ([`RunRequest`]): the string options parsed
    /// by its parser (errors name the option).
    pub(crate) fn request(self, scenario_name: &str) -> PyResult<RunRequest> {
        let scenario = match (self.scenario.filter(|s| !s.is_none()), self.toml) {
            (Some(_), Some(_)) => {
                return Err(PyValueError::new_err(
                    "give either `scenario` (a name or a file) or `toml` (TOML text), not both",
                ))
            }
            (Some(s), None) => scenario_source(s, scenario_name)?,
            (None, Some(text)) => ScenarioSource::Toml(text),
            (None, None) => ScenarioSource::Default,
        };
        RunRequest {
            scenario,
            relaxation: self.relaxation,
            allocator: self.allocator,
            team: self.team,
            law: self.law,
            fault_detection: self.fault_detection,
            log: self.mcap,
            samples: self.samples,
            ..RunRequest::default()
        }
        .with_strings(
            self.precision.as_deref(),
            self.pil.as_deref(),
            self.null_space.as_deref(),
        )
        .map_err(value_error)
    }

    /// Loads the scenario, applies the overrides and validates the result
    /// ([`RunRequest::spec`]: the log is checked too, and never the scenario file).
    pub(crate) fn spec(mut self, scenario_name: &str) -> PyResult<RunSpec> {
        let team = self.team_config.take();
        let max_rounds = self.max_rounds;
        let mut spec = self.request(scenario_name)?.spec().map_err(value_error)?;
        fly_team(&mut spec, team)?;
        if max_rounds.is_some() {
            spec.scenario.allocator_max_rounds = max_rounds;
            spec.scenario.validate().map_err(value_error)?;
        }
        Ok(spec)
    }
}

/// The scenario of a `Simulation`, `ScenarioController` or `SimulationBatch`: `run`'s
/// arguments, the built-in `"hover"` when neither `scenario` nor `toml` is given; `control`
/// the converted `fault_detection` and `max_rounds` ([`control_args`]).
#[allow(clippy::too_many_arguments)]
pub(crate) fn spec(
    py: Python<'_>,
    scenario: Option<&Bound<'_, PyAny>>,
    toml: Option<String>,
    team: Option<&Bound<'_, PyAny>>,
    relaxation: Option<f64>,
    allocator: Option<String>,
    precision: Option<String>,
    null_space: Option<String>,
    law: Option<&Bound<'_, PyAny>>,
    max_samples: Option<&Int>,
    control: (Option<FaultDetectionConfig>, Option<RoundCap>),
) -> PyResult<RunSpec> {
    let (team, team_config) = team_arg(team)?;
    let hover = PyString::new(py, "hover").into_any();
    let scenario = scenario
        .filter(|s| !s.is_none())
        .or(toml.is_none().then_some(&hover));
    RunArgs {
        scenario,
        toml,
        team,
        team_config,
        relaxation,
        allocator,
        precision,
        null_space,
        law: law.map(|l| law_arg(l, "law")).transpose()?,
        samples: retention_arg(max_samples, "max_samples")?,
        fault_detection: control.0,
        max_rounds: control.1,
        ..RunArgs::default()
    }
    .spec("scenario")
}

/// The `fault_detection` (as `tvmd.Controller`'s) and `max_rounds` (the scenario's
/// `allocator_max_rounds`) arguments of `run` and `Simulation`.
pub(crate) fn control_args(
    fault_detection: Option<&Bound<'_, PyAny>>,
    max_rounds: Option<&Bound<'_, PyAny>>,
) -> PyResult<(Option<FaultDetectionConfig>, Option<RoundCap>)> {
    let detection = fault_detection
        .filter(|f| !f.is_none())
        .map(|f| fault_detection_arg(f, "fault_detection"))
        .transpose()?;
    Ok((detection, round_cap_arg(max_rounds)?))
}

/// Flies `team` (a `tvmd.Team`'s team and limits, [`team_arg`]) in `spec` instead of its
/// scenario's, validated again; nothing to do without one.
fn fly_team(spec: &mut RunSpec, team: Option<TeamConfigArg>) -> PyResult<()> {
    if let Some((team, limits)) = team {
        spec.scenario.team = team;
        spec.scenario.limits = limits;
        spec.scenario.validate().map_err(value_error)?;
    }
    Ok(())
}

/// A `team` argument: a catalogue name (a `str`) or a `tvmd.Team` ([`team_spec`]), as the
/// `team` and `team_config` of [`RunArgs`].
pub(crate) fn team_arg(
    team: Option<&Bound<'_, PyAny>>,
) -> PyResult<(Option<String>, Option<TeamConfigArg>)> {
    let Some(team) = team.filter(|t| !t.is_none()) else {
        return Ok((None, None));
    };
    if let Ok(name) = team.cast::<PyString>() {
        return Ok((Some(name.to_cow()?.into_owned()), None));
    }
    if let Ok(t) = team.cast::<PyTeam>() {
        return Ok((None, Some(team_spec(&t.get().inner)?)));
    }
    let got = team.get_type().name()?;
    Err(PyTypeError::new_err(format!(
        "`team` must be a catalogue team name (str) or a tvmd.Team, got {got}"
    )))
}

/// A `run_many` entry: a scenario (name or path) or a dict of `run` keyword arguments; `k` its
/// index, which errors name.
pub(crate) fn run_item(item: &Bound<'_, PyAny>, k: usize) -> PyResult<RunSpec> {
    Ok(run_request(item, k)?.0)
}

/// A `run_many` entry as its checked spec and the scenario file it reads, if any.
pub(crate) fn run_request(
    item: &Bound<'_, PyAny>,
    k: usize,
) -> PyResult<(RunSpec, Option<PathBuf>)> {
    // The log is checked before any run flies, its errors named as the threads name a run's.
    let checked = |r: RunRequest| -> PyResult<(RunSpec, Option<PathBuf>)> {
        let spec = r.flight().map_err(value_error)?;
        let log = spec.log.as_deref().map(|l| (WRITE, l));
        r.check_log()
            .map_err(|e| sim_error(e, &batch_label(k, &spec), log))?;
        Ok((spec, r.input().map(Path::to_path_buf)))
    };
    let name = format!("runs[{k}]");
    let Ok(dict) = item.cast::<PyDict>() else {
        if item.is_instance_of::<PyString>() || item.hasattr("__fspath__")? {
            let scenario = Some(item);
            return checked(
                RunArgs {
                    scenario,
                    ..RunArgs::default()
                }
                .request(&name)?,
            );
        }
        let got = item.get_type().name()?;
        return Err(PyTypeError::new_err(format!(
            "`{name}` must be a scenario name, a path to a TOML file or a dict of `run` keyword \
             arguments ({}), got {got}",
            RUN_KEYS.join(", ")
        )));
    };
    for key in dict.keys() {
        let key_str: String = key.extract().map_err(|_| {
            PyTypeError::new_err(format!("`{name}` keys must be strings, got {key}"))
        })?;
        if !RUN_KEYS.contains(&key_str.as_str()) {
            return Err(PyValueError::new_err(format!(
                "`{name}` has the unknown key '{key_str}' (known: {})",
                RUN_KEYS.join(", ")
            )));
        }
    }
    fn opt<'py, T: pyo3::conversion::FromPyObjectOwned<'py>>(
        dict: &Bound<'py, PyDict>,
        name: &str,
        key: &str,
    ) -> PyResult<Option<T>> {
        match dict.get_item(key)? {
            Some(v) if !v.is_none() => v.extract::<T>().map(Some).map_err(|e| {
                let e: PyErr = e.into();
                PyTypeError::new_err(format!("`{name}['{key}']`: {}", e.value(dict.py())))
            }),
            _ => Ok(None),
        }
    }
    let scenario = dict.get_item("scenario")?;
    let max_samples = opt::<Int>(dict, &name, "max_samples")?;
    let samples = retention_arg(max_samples.as_ref(), &format!("{name}['max_samples']"))?;
    let law = match dict.get_item("law")? {
        Some(l) if !l.is_none() => Some(law_arg(&l, &format!("{name}['law']"))?),
        _ => None,
    };
    let (team, team_config) = match dict.get_item("team")? {
        Some(t) => team_arg(Some(&t)).map_err(|e| {
            let why = e.value(dict.py()).to_string();
            let why = why.strip_prefix("`team` ").unwrap_or(&why);
            PyErr::from_type(e.get_type(dict.py()), format!("`{name}['team']` {why}"))
        })?,
        None => (None, None),
    };
    let request = RunArgs {
        scenario: scenario.as_ref(),
        toml: opt(dict, &name, "toml")?,
        mcap: opt(dict, &name, "mcap")?,
        relaxation: opt(dict, &name, "relaxation")?,
        allocator: opt(dict, &name, "allocator")?,
        null_space: opt(dict, &name, "null_space")?,
        precision: opt(dict, &name, "precision")?,
        pil: opt(dict, &name, "pil")?,
        samples,
        team,
        team_config: None,
        law,
        ..RunArgs::default()
    }
    .request(&format!("{name}['scenario']"))?;
    let (mut spec, input) = checked(request)?;
    fly_team(&mut spec, team_config)?;
    Ok((spec, input))
}

/// The runs of a `run_many` batch, each loaded and validated ([`run_item`]), and the batch's
/// paths checked: no log given twice, none a scenario file of the batch.
pub(crate) fn run_items(runs: &Bound<'_, PyAny>) -> PyResult<Vec<RunSpec>> {
    if runs.is_instance_of::<PyString>() || runs.is_instance_of::<PyDict>() {
        return Err(PyTypeError::new_err(
            "`runs` must be a sequence of runs (names, paths or dicts), not a single str or dict",
        ));
    }
    let items = runs
        .try_iter()
        .map_err(|_| PyTypeError::new_err("`runs` must be an iterable of runs"))?
        .enumerate()
        .map(|(k, item)| run_request(&item?, k))
        .collect::<PyResult<Vec<_>>>()?;
    let inputs: Vec<(String, &Path)> = items
        .iter()
        .enumerate()
        .filter_map(|(k, (_, input))| {
            Some((format!("scenario file of runs[{k}]"), input.as_deref()?))
        })
        .collect();
    let specs: Vec<RunSpec> = items.iter().map(|(spec, _)| spec.clone()).collect();
    runner::check_batch_paths(&specs, &[], &inputs).map_err(value_error)?;
    Ok(specs)
}

/// A `run_many(..., errors="keep")` batch: each run's `SimResult`, or the exception it would
/// have raised (a bad entry or log, a failure while flying), by index. Only what concerns the
/// batch as a whole raises: `runs` not a sequence, two runs on one log, an interrupt.
pub(crate) fn run_items_keeping(
    py: Python<'_>,
    runs: &Bound<'_, PyAny>,
    jobs: Option<usize>,
) -> PyResult<Vec<Py<PyAny>>> {
    if runs.is_instance_of::<PyString>() || runs.is_instance_of::<PyDict>() {
        return Err(PyTypeError::new_err(
            "`runs` must be a sequence of runs (names, paths or dicts), not a single str or dict",
        ));
    }
    let mut slots: Vec<Option<Py<PyAny>>> = Vec::new();
    let mut flown: Vec<(usize, RunSpec, Option<PathBuf>)> = Vec::new();
    let items = runs
        .try_iter()
        .map_err(|_| PyTypeError::new_err("`runs` must be an iterable of runs"))?;
    for (k, item) in items.enumerate() {
        let checked = run_request(&item?, k).and_then(|(spec, input)| {
            check_logs(std::slice::from_ref(&spec), &|_, s| batch_label(k, s))?;
            Ok((spec, input))
        });
        match checked {
            Ok((spec, input)) => {
                flown.push((k, spec, input));
                slots.push(None);
            }
            Err(e) => slots.push(Some(e.into_value(py).into_any())),
        }
    }
    let inputs: Vec<(String, &Path)> = flown
        .iter()
        .filter_map(|(k, _, input)| {
            Some((format!("scenario file of runs[{k}]"), input.as_deref()?))
        })
        .collect();
    let specs: Vec<RunSpec> = flown.iter().map(|(_, spec, _)| spec.clone()).collect();
    runner::check_batch_paths(&specs, &[], &inputs).map_err(value_error)?;
    let outcomes = run_interruptibly(py, specs, jobs)?;
    for ((k, _, _), RunOutcome { spec, result }) in flown.into_iter().zip(outcomes) {
        let value = match result {
            Ok(result) => Py::new(
                py,
                PySimResult {
                    inner: SimData::new(spec, result),
                },
            )?
            .into_any(),
            Err(e) => {
                let log = spec.log.as_deref().map(|l| (WRITE, l));
                sim_error(e, &batch_label(k, &spec), log)
                    .into_value(py)
                    .into_any()
            }
        };
        if let Some(slot) = slots.get_mut(k) {
            *slot = Some(value);
        }
    }
    slots
        .into_iter()
        .map(|s| {
            s.ok_or_else(|| {
                pyo3::exceptions::PyRuntimeError::new_err("a run of the batch returned nothing")
            })
        })
        .collect()
}

/// The runs of a relaxation study as `relaxation_sweep` takes them: `args`' scenario once per
/// relaxation (default 0.25, 0.5, 0.75, 1), each with `args`' target and sample retention.
pub(crate) fn sweep_run_specs(
    relaxations: Option<&Bound<'_, PyAny>>,
    args: RunArgs<'_, '_>,
    mcap_dir: Option<PathBuf>,
) -> PyResult<Vec<RunSpec>> {
    let values = match relaxations.filter(|r| !r.is_none()) {
        Some(r) => match scalars(r, "relaxations")? {
            (values, shape) if shape.len() == 1 => values,
            (_, shape) => return Err(shape_error("relaxations", "(k,)", &shape)),
        },
        None => vec![0.25, 0.5, 0.75, 1.0],
    };
    let base = args.spec("scenario")?;
    let mut specs =
        sweep_specs(&base.scenario, &values, mcap_dir.as_deref()).map_err(value_error)?;
    for spec in &mut specs {
        spec.pil = base.pil;
        spec.samples = base.samples;
    }
    Ok(specs)
}

/// The error prefix of run `k` of a `run_many` batch.
pub(crate) fn batch_label(k: usize, spec: &RunSpec) -> String {
    format!("runs[{k}] ({}): ", spec.scenario.name)
}

/// The error prefix of a run of a relaxation study.
pub(crate) fn sweep_label(spec: &RunSpec) -> String {
    format!(
        "s = {} ({}): ",
        spec.scenario.relaxation, spec.scenario.name
    )
}

/// Runs the specs on tvmd-sim's worker pool with the GIL released; the first failure in input
/// order is raised, its message prefixed with `label(k)`.
pub(crate) fn run_specs(
    py: Python<'_>,
    specs: Vec<RunSpec>,
    jobs: Option<usize>,
    label: impl Fn(usize, &RunSpec) -> String,
) -> PyResult<Vec<PySimResult>> {
    check_logs(&specs, &label)?;
    let outcomes = run_interruptibly(py, specs, jobs)?;
    let results = outcomes.into_iter().enumerate();
    results
        .map(|(k, RunOutcome { spec, result })| match result {
            Ok(result) => Ok(PySimResult {
                inner: SimData::new(spec, result),
            }),
            Err(e) => {
                let log = spec.log.as_deref().map(|l| (WRITE, l));
                Err(sim_error(e, &label(k, &spec), log))
            }
        })
        .collect()
}

/// Checks a batch's logs before any run flies ([`tvmd_log::paths`]): each one (the error
/// prefixed with `label(k)`, as a failure of run `k` is), then no two the same.
pub(crate) fn check_logs(
    specs: &[RunSpec],
    label: &impl Fn(usize, &RunSpec) -> String,
) -> PyResult<()> {
    for (k, spec) in specs.iter().enumerate() {
        if let Some(log) = spec.log.as_deref() {
            tvmd_log::paths::check_output(log, "the log", "write the MCAP log")
                .map_err(|e| sim_error(e, &label(k, spec), Some((WRITE, log))))?;
        }
    }
    runner::check_batch_outputs(specs, &[]).map_err(value_error)
}

/// Runs the batch on tvmd-sim's pool ([`interruptible`]): on `KeyboardInterrupt` (or any
/// signal handler's exception) the flights stop at their next controller tick (logs
/// finalised), and the exception is raised.
fn run_interruptibly(
    py: Python<'_>,
    specs: Vec<RunSpec>,
    jobs: Option<usize>,
) -> PyResult<Vec<RunOutcome>> {
    match interruptible(py, |cancel| {
        runner::run_many_until(specs, jobs, None, Some(cancel))
    })? {
        Ended::Finished(outcomes) => Ok(outcomes),
        Ended::Interrupted { signal, .. } => Err(signal),
    }
}
