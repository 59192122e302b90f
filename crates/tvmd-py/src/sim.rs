//! The simulator `tvmd-sim` as the submodule `tvmd._tvmd.sim` (re-exported by
//! `python/tvmd/sim.py` as `tvmd.sim`): built-in scenarios, one run ([`run`]), a batch of runs
//! in parallel threads ([`run_many`], [`relaxation_sweep`]) and the result record
//! [`PySimResult`] (`tvmd.sim.SimResult`).
//!
//! Thin like the rest of the bindings: scenarios are loaded, validated and run by `tvmd-sim`
//! (`Scenario::builtin` / `from_file` / `from_toml_str`, `runner::run_scenario`), the metrics
//! come from `RunSummary` and `metrics::PaperMetrics`; this module converts arguments and
//! results. Runs release the GIL (`Python::detach`); a batch runs on `jobs` threads (the
//! calling thread is one of them) and returns the results in input order.
//!
//! Errors: a scenario, TOML text or override that cannot be used raises `ValueError` (the
//! message is tvmd-sim's, naming the field), wrong argument types `TypeError`, I/O errors
//! `OSError` (its errno subclass, e.g. `FileNotFoundError`, with the file name), a run that
//! fails while flying (divergence, controller error) `RuntimeError`. A panic inside tvmd-sim is
//! caught and raised as `RuntimeError` too, never as `PanicException`.

use std::path::{Path, PathBuf};

use numpy::ndarray::{Array1, Array2, Array3};
use numpy::{PyArray1, PyArray2, PyArray3};
use pyo3::exceptions::{PyAttributeError, PyOSError, PyRuntimeError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyString, PyTuple};

use tvmd_sim::actuators::ActuatorCommand;
use tvmd_sim::control::hover_roll_limit;
use tvmd_sim::runner::{self, sweep_specs, RunOutcome, RunSpec};
use tvmd_sim::scenario::{Overrides, Scenario, BUILTIN_NAMES};
use tvmd_sim::sim::{PaperMetrics, RunResult, RunSummary, Sample};
use tvmd_sim::SimError;

use crate::convert::{any, array1, bool_array, scalars};

/// The default scenario of [`run`] and [`relaxation_sweep`].
const DEFAULT_SCENARIO: &str = "paper-tilt";

/// The keys a `run_many` dict may hold (the keyword arguments of `run`).
const RUN_KEYS: &[&str] = &["scenario", "toml", "mcap", "relaxation", "allocator"];

// ---------------------------------------------------------------------------------------------
// Errors
// ---------------------------------------------------------------------------------------------

/// An `OSError` for `error` (its errno subclass when the OS gave an errno), naming `file`.
fn os_error(what: &str, error: &std::io::Error, file: Option<&Path>) -> PyErr {
    let message = format!("{what}: {error}");
    match (error.raw_os_error(), file) {
        (Some(errno), Some(file)) => {
            PyOSError::new_err((errno, message, file.display().to_string()))
        }
        (Some(errno), None) => PyOSError::new_err((errno, message)),
        (None, Some(file)) => PyOSError::new_err(format!("{message}: '{}'", file.display())),
        (None, None) => PyOSError::new_err(message),
    }
}

/// A file an I/O error refers to, and what was done with it.
type IoFile<'a> = Option<(&'a str, &'a Path)>;

/// The Python exception of a tvmd-sim error; `context` prefixes the message. An I/O error
/// refers to `file`: `("cannot read the scenario file", path)` when loading, `("cannot write the
/// MCAP log", path)` when running.
fn sim_error(error: SimError, context: &str, file: IoFile<'_>) -> PyErr {
    let (what, file) = match file {
        Some((what, path)) => (what, Some(path)),
        None => ("I/O error", None),
    };
    match error {
        SimError::Io(io) => os_error(&format!("{context}{what}"), &io, file),
        SimError::InvalidTeam(_)
        | SimError::InvalidScenario { .. }
        | SimError::ScenarioParse { .. }
        | SimError::UnknownScenario { .. } => PyValueError::new_err(format!("{context}{error}")),
        SimError::Mcap(_) | SimError::LogRead(_) | SimError::LogFinished => {
            let message = format!("{context}{error}");
            match file {
                Some(f) => PyOSError::new_err(format!("{message}: '{}'", f.display())),
                None => PyOSError::new_err(message),
            }
        }
        other => PyRuntimeError::new_err(format!("{context}{other}")),
    }
}

/// The Python exception of a failed run (a panic is `SimError::Internal`, a `RuntimeError`).
fn run_error(error: SimError, context: &str, log: Option<&Path>) -> PyErr {
    sim_error(
        error,
        context,
        log.map(|l| ("cannot write the MCAP log", l)),
    )
}

// ---------------------------------------------------------------------------------------------
// Arguments
// ---------------------------------------------------------------------------------------------

/// Reads a scenario file; I/O errors name the file.
fn scenario_file(path: &Path) -> PyResult<Scenario> {
    Scenario::from_file(path)
        .map_err(|e| sim_error(e, "", Some(("cannot read the scenario file", path))))
}

/// The scenario of a `scenario` argument: a `str` is a built-in name, or a TOML file if it ends
/// in `.toml` or names an existing file (the rule of the `tvmd-sim` command line); an
/// `os.PathLike` is a file.
fn scenario_arg(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<Scenario> {
    if let Ok(s) = obj.cast::<PyString>() {
        let s = s.to_cow()?;
        // Only a file can fail with an I/O error.
        return Scenario::load(&s).map_err(|e| {
            sim_error(
                e,
                "",
                Some(("cannot read the scenario file", Path::new(s.as_ref()))),
            )
        });
    }
    if obj.hasattr("__fspath__")? {
        let path: PathBuf = obj.extract().map_err(|e| {
            PyTypeError::new_err(format!("`{name}` is not a usable file path: {e}"))
        })?;
        return scenario_file(&path);
    }
    let got = obj.get_type().name()?;
    Err(PyTypeError::new_err(format!(
        "`{name}` must be a built-in scenario name or a path to a TOML file (str or \
         os.PathLike), got {got}"
    )))
}

/// The arguments of one run, as `run` takes them.
#[derive(Default)]
struct RunArgs<'a, 'py> {
    scenario: Option<&'a Bound<'py, PyAny>>,
    toml: Option<String>,
    mcap: Option<PathBuf>,
    relaxation: Option<f64>,
    allocator: Option<String>,
}

impl RunArgs<'_, '_> {
    /// Loads the scenario, applies the overrides and validates the result.
    fn spec(self, scenario_name: &str) -> PyResult<RunSpec> {
        let mut scenario = match (self.scenario.filter(|s| !s.is_none()), self.toml) {
            (Some(_), Some(_)) => {
                return Err(PyValueError::new_err(
                    "give either `scenario` (a name or a file) or `toml` (TOML text), not both",
                ))
            }
            (Some(s), None) => scenario_arg(s, scenario_name)?,
            (None, Some(text)) => {
                Scenario::from_toml_str(&text).map_err(|e| sim_error(e, "", None))?
            }
            (None, None) => {
                Scenario::builtin(DEFAULT_SCENARIO).map_err(|e| sim_error(e, "", None))?
            }
        };
        let overrides = Overrides {
            relaxation: self.relaxation,
            allocator: self.allocator,
        };
        overrides
            .apply(&mut scenario)
            .map_err(|e| sim_error(e, "", None))?;
        Ok(RunSpec {
            scenario,
            log: self.mcap,
        })
    }
}

/// A `run_many` entry: a scenario (name or path) or a dict of `run` keyword arguments.
fn run_item(item: &Bound<'_, PyAny>, k: usize) -> PyResult<RunSpec> {
    let name = format!("runs[{k}]");
    let Ok(dict) = item.cast::<PyDict>() else {
        if item.is_instance_of::<PyString>() || item.hasattr("__fspath__")? {
            return RunArgs {
                scenario: Some(item),
                ..RunArgs::default()
            }
            .spec(&name);
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
    RunArgs {
        scenario: scenario.as_ref(),
        toml: opt(dict, &name, "toml")?,
        mcap: opt(dict, &name, "mcap")?,
        relaxation: opt(dict, &name, "relaxation")?,
        allocator: opt(dict, &name, "allocator")?,
    }
    .spec(&format!("{name}['scenario']"))
}

/// Worker threads for `count` runs: `jobs` (>= 1) or the available cores, at most `count`.
fn job_count(jobs: Option<i64>, count: usize) -> PyResult<usize> {
    let jobs = match jobs {
        None => std::thread::available_parallelism().map_or(1, |n| n.get()),
        Some(j) => usize::try_from(j)
            .ok()
            .filter(|j| *j >= 1)
            .ok_or_else(|| PyValueError::new_err(format!("`jobs` must be >= 1, got {j}")))?,
    };
    Ok(jobs.clamp(1, count.max(1)))
}

// ---------------------------------------------------------------------------------------------
// Running (without the GIL)
// ---------------------------------------------------------------------------------------------

/// Runs the specs with the GIL released and converts the results (the first failure in input
/// order is raised, its message prefixed with `label(k)`).
fn run_specs(
    py: Python<'_>,
    specs: Vec<RunSpec>,
    jobs: Option<i64>,
    label: impl Fn(usize, &RunSpec) -> String,
) -> PyResult<Vec<PySimResult>> {
    let jobs = job_count(jobs, specs.len())?;
    let outcomes = py.detach(|| runner::run_many(specs, Some(jobs), None));
    outcomes
        .into_iter()
        .enumerate()
        .map(|(k, RunOutcome { spec, result })| match result {
            Ok(result) => Ok(PySimResult::new(spec, result)),
            Err(e) => Err(run_error(e, &label(k, &spec), spec.log.as_deref())),
        })
        .collect()
}

// ---------------------------------------------------------------------------------------------
// Functions
// ---------------------------------------------------------------------------------------------

/// The names of the built-in scenarios (`"paper-tilt"` is the paper's simulation, SPEC "The
/// paper's simulation"; `"relaxation-<s>"` the relaxation study; failures, A4-Con, ...).
#[pyfunction]
fn builtin_scenarios() -> Vec<&'static str> {
    BUILTIN_NAMES.to_vec()
}

/// A built-in scenario as TOML text: every field, a starting point for a scenario file (or for
/// `run(toml=...)`).
///
/// Raises:
///     ValueError: unknown name.
#[pyfunction]
fn scenario_toml(name: &str) -> PyResult<String> {
    Scenario::builtin(name)
        .and_then(|s| s.to_toml_string())
        .map_err(|e| sim_error(e, "", None))
}

/// Runs one scenario with the tvmd controller in the loop (tvmd-sim: rapier3d rigid body at
/// `physics.dt`, controller every `controller_period` with zero-order hold) and returns its
/// time series. The GIL is released during the run.
///
/// Args:
///     scenario: a built-in name (see `builtin_scenarios()`), or a TOML scenario file (a path
///         ending in `.toml` or naming an existing file, or any `os.PathLike`). Default
///         `"paper-tilt"`: the paper's simulation (A4-Inc, ascent, roll tilt towards the
///         infeasible `pi/3`, descent; `s = 0.5`).
///     toml: inline TOML scenario text instead of `scenario` (fields left out take the
///         paper-tilt defaults; see `scenario_toml("paper-tilt")`).
///     mcap: write an MCAP log there (parent directories are created; open it in Foxglove).
///     relaxation: override the planner's AFS relaxation `s`, in (0, 1].
///     allocator: override the allocator ("redistributed-pseudo-inverse", "pseudo-inverse",
///         "weighted-pseudo-inverse", "clarabel" with the cargo feature).
///
/// Raises:
///     ValueError: unknown scenario, TOML that does not parse or a field that is not valid (the
///         message names the field, e.g. `physics.dt`), a bad override, both `scenario` and
///         `toml`.
///     TypeError: an argument of the wrong type.
///     OSError: the scenario file cannot be read or the log cannot be written.
///     RuntimeError: the run failed while flying (the state diverged, the controller failed).
#[pyfunction]
#[pyo3(signature = (scenario = None, *, toml = None, mcap = None, relaxation = None, allocator = None))]
fn run(
    py: Python<'_>,
    scenario: Option<&Bound<'_, PyAny>>,
    toml: Option<String>,
    mcap: Option<PathBuf>,
    relaxation: Option<f64>,
    allocator: Option<String>,
) -> PyResult<PySimResult> {
    let spec = RunArgs {
        scenario,
        toml,
        mcap,
        relaxation,
        allocator,
    }
    .spec("scenario")?;
    let mut outcomes = py.detach(|| runner::run_many(vec![spec], Some(1), None));
    let RunOutcome { spec, result } = outcomes
        .pop()
        .ok_or_else(|| PyRuntimeError::new_err("tvmd-sim returned no result"))?;
    match result {
        Ok(result) => Ok(PySimResult::new(spec, result)),
        Err(e) => Err(run_error(e, "", spec.log.as_deref())),
    }
}

/// Runs many scenarios in parallel threads (GIL released) and returns their results in input
/// order.
///
/// Args:
///     runs: a sequence whose items are each a scenario (a built-in name or a TOML file, as
///         `run`'s `scenario`) or a dict of `run`'s keyword arguments, e.g.
///         `{"scenario": "a4-con", "relaxation": 1.0}` or `{"toml": text, "mcap": "x.mcap"}`.
///     jobs: worker threads (default: the available cores), at most `len(runs)`.
///
/// Every item is loaded and validated before any run starts. If runs fail, the first failure
/// in input order is raised, its message prefixed with `runs[k]`.
///
/// Raises:
///     ValueError, TypeError, OSError, RuntimeError: as `run`; `ValueError` also for an
///         unknown dict key or `jobs < 1`.
#[pyfunction]
#[pyo3(signature = (runs, *, jobs = None))]
fn run_many(
    py: Python<'_>,
    runs: &Bound<'_, PyAny>,
    jobs: Option<i64>,
) -> PyResult<Vec<PySimResult>> {
    if runs.is_instance_of::<PyString>() || runs.is_instance_of::<PyDict>() {
        return Err(PyTypeError::new_err(
            "`runs` must be a sequence of runs (names, paths or dicts), not a single str or dict",
        ));
    }
    let specs = runs
        .try_iter()
        .map_err(|_| PyTypeError::new_err("`runs` must be an iterable of runs"))?
        .enumerate()
        .map(|(k, item)| run_item(&item?, k))
        .collect::<PyResult<Vec<_>>>()?;
    run_specs(py, specs, jobs, |k, s| {
        format!("runs[{k}] ({}): ", s.scenario.name)
    })
}

/// The paper's relaxation study: one scenario flown once per relaxation `s` (in parallel
/// threads, GIL released), results in the order of `relaxations`. The planner's roll limit in
/// hover is `atan(c_y(1, s))`, so the largest planned roll grows with `s`.
///
/// Each run's `scenario_name` is `"<name>-s<s>"` (as `tvmd-sim sweep`).
///
/// Args:
///     relaxations: the values of `s`, each in (0, 1].
///     scenario: as `run` (default `"paper-tilt"`).
///     toml: inline TOML text instead of `scenario`.
///     allocator: override the scenario's allocator.
///     mcap_dir: write one MCAP log per run there, `<name>-s<s>.mcap`.
///     jobs: worker threads (default: the available cores).
///
/// Raises:
///     ValueError: as `run`; an `s` outside (0, 1] or not finite, `relaxations` not 1-D.
///     TypeError, OSError, RuntimeError: as `run`.
#[pyfunction]
#[pyo3(signature = (relaxations = None, scenario = None, *, toml = None, allocator = None, mcap_dir = None, jobs = None))]
#[allow(clippy::too_many_arguments)]
fn relaxation_sweep(
    py: Python<'_>,
    relaxations: Option<&Bound<'_, PyAny>>,
    scenario: Option<&Bound<'_, PyAny>>,
    toml: Option<String>,
    allocator: Option<String>,
    mcap_dir: Option<PathBuf>,
    jobs: Option<i64>,
) -> PyResult<Vec<PySimResult>> {
    let values = match relaxations.filter(|r| !r.is_none()) {
        Some(r) => {
            let (values, shape) = scalars(r, "relaxations")?;
            if shape.len() != 1 {
                return Err(crate::convert::shape_error("relaxations", "(k,)", &shape));
            }
            values
        }
        None => vec![0.25, 0.5, 0.75, 1.0],
    };
    let base = RunArgs {
        scenario,
        toml,
        allocator,
        ..RunArgs::default()
    }
    .spec("scenario")?
    .scenario;
    let specs =
        sweep_specs(&base, &values, mcap_dir.as_deref()).map_err(|e| sim_error(e, "", None))?;
    run_specs(py, specs, jobs, |_, s| {
        format!("s = {} ({}): ", s.scenario.relaxation, s.scenario.name)
    })
}

// ---------------------------------------------------------------------------------------------
// Result
// ---------------------------------------------------------------------------------------------

/// The result of one simulated run (read-only; every array access returns a fresh float64
/// copy, so bind it to a name before indexing in a loop).
///
/// `K` samples, one per controller tick (`t_k = k controller_period`, true state before the
/// tick's commands act); `n` agents. SI units, z up, angles in rad. Values a controller did not
/// report at a tick (a skipped cycle) are NaN.
///
/// Attributes:
///     scenario_name, relaxation (`s`), allocator, mcap_path (str or None), n_agents,
///     mass (`m_C`, kg), gravity (`g`, m/s^2), hover_roll_limit (`atan(c_y(1, s))`, rad: the
///     planned roll at which the planner saturates in hover).
///     t: (K,) time (s).
///     position, velocity, reference_position: (K, 3) `x` (m), `x_dot` (m/s), `x_r` (m).
///     attitude_rpy, reference_rpy, planned_rpy: (K, 3) roll, pitch, yaw (ZYX) of `R`, `R_r`
///         and the planned `R_d`.
///     reference_roll: (K,) `phi_r`. planned_roll: (K,) `phi_d = atan2(R_d[2,1], R_d[2,2])`.
///     attitude_error: (K,) angle between `R` and `R_d`. theta: (K,) planner angle `theta*`.
///     e_f: (K,) allocation error `||u_fd - u_f||` (N). saturated_agents: (K,) int64, agents
///         the allocator saturated (-1 if not reported).
///     V_x, V_R: (K,) the Lyapunov candidates. cycle_error: (K,) bool, cycle skipped.
///     commands, actual: (K, n, 3) commanded and actual actuator values, columns
///         `eta_x, eta_y` (rad), `thrust` (N). failed: (K, n) bool, true failure flags.
///     summary: dict, every field of tvmd-sim's `RunSummary` (`max_planned_roll`, `max_e_f`,
///         `max_e_f_over_weight` = `max e_f / (m_C g)`, `max_position_error_after_4s`, ...).
///     paper_metrics: dict, tvmd-sim's `PaperMetrics` (horizontal errors at 4 and 12 s,
///         stage-B attitude settling, `e_f` onset, `V_x` rise, ...).
///     scenario_toml: the scenario that ran, as TOML.
#[pyclass(module = "tvmd.sim", name = "SimResult", frozen)]
pub struct PySimResult {
    scenario: Scenario,
    mcap: Option<PathBuf>,
    samples: Vec<Sample>,
    summary: RunSummary,
    paper: PaperMetrics,
    hover_roll_limit: Option<f64>,
    mass: Option<f64>,
    n: usize,
}

/// The field names of `SimResult`, in `to_dict` order.
const RESULT_FIELDS: &[&str] = &[
    "scenario_name",
    "relaxation",
    "allocator",
    "mcap_path",
    "n_agents",
    "mass",
    "gravity",
    "hover_roll_limit",
    "t",
    "position",
    "velocity",
    "reference_position",
    "attitude_rpy",
    "reference_rpy",
    "reference_roll",
    "planned_roll",
    "planned_rpy",
    "attitude_error",
    "theta",
    "e_f",
    "saturated_agents",
    "V_x",
    "V_R",
    "cycle_error",
    "commands",
    "actual",
    "failed",
    "summary",
    "paper_metrics",
    "scenario_toml",
];

fn column<'py>(
    py: Python<'py>,
    samples: &[Sample],
    f: impl Fn(&Sample) -> Option<f64>,
) -> Bound<'py, PyArray1<f64>> {
    let values: Vec<f64> = samples.iter().map(|s| f(s).unwrap_or(f64::NAN)).collect();
    array1(py, &values)
}

fn column3<'py>(
    py: Python<'py>,
    samples: &[Sample],
    f: impl Fn(&Sample) -> Option<[f64; 3]>,
) -> Bound<'py, PyArray2<f64>> {
    let rows: Vec<[f64; 3]> = samples
        .iter()
        .map(|s| f(s).unwrap_or([f64::NAN; 3]))
        .collect();
    crate::convert::rows_array(py, &rows)
}

fn agent_columns<'py>(
    py: Python<'py>,
    samples: &[Sample],
    n: usize,
    f: impl Fn(&Sample) -> &[ActuatorCommand],
) -> Bound<'py, PyArray3<f64>> {
    let a = Array3::from_shape_fn((samples.len(), n, 3), |(k, i, j)| {
        samples
            .get(k)
            .and_then(|s| f(s).get(i))
            .and_then(|c| [c.eta_x, c.eta_y, c.thrust].get(j).copied())
            .unwrap_or(f64::NAN)
    });
    PyArray3::from_owned_array(py, a)
}

/// A JSON value (of a tvmd-sim record) as Python objects: objects become dicts, arrays lists.
fn json_to_py<'py>(py: Python<'py>, value: &serde_json::Value) -> PyResult<Bound<'py, PyAny>> {
    use serde_json::Value;
    Ok(match value {
        Value::Null => py.None().into_bound(py),
        Value::Bool(b) => any(py, *b)?,
        Value::Number(x) => match (x.as_i64(), x.as_u64(), x.as_f64()) {
            (Some(i), _, _) => any(py, i)?,
            (None, Some(u), _) => any(py, u)?,
            (None, None, f) => any(py, f.unwrap_or(f64::NAN))?,
        },
        Value::String(s) => any(py, s.as_str())?,
        Value::Array(items) => {
            let list = PyList::empty(py);
            for item in items {
                list.append(json_to_py(py, item)?)?;
            }
            list.into_any()
        }
        Value::Object(map) => {
            let dict = PyDict::new(py);
            for (k, v) in map {
                dict.set_item(k, json_to_py(py, v)?)?;
            }
            dict.into_any()
        }
    })
}

fn record_to_py<'py, T: serde::Serialize>(
    py: Python<'py>,
    record: &T,
) -> PyResult<Bound<'py, PyAny>> {
    let value = serde_json::to_value(record)
        .map_err(|e| PyRuntimeError::new_err(format!("cannot convert a tvmd-sim record: {e}")))?;
    json_to_py(py, &value)
}

impl PySimResult {
    fn new(spec: RunSpec, result: RunResult) -> Self {
        let scenario = spec.scenario;
        let paper = PaperMetrics::new(&scenario, &result.samples);
        let hover_roll_limit = hover_roll_limit(&scenario, scenario.relaxation).ok();
        let team = scenario.team_body().ok();
        let n = result
            .samples
            .first()
            .map(|s| s.commands.len())
            .or_else(|| team.as_ref().map(|t| t.len()))
            .unwrap_or(0);
        Self {
            mass: team.as_ref().map(|t| t.mass()),
            paper,
            hover_roll_limit,
            n,
            mcap: spec.log,
            samples: result.samples,
            summary: result.summary,
            scenario,
        }
    }

    fn field<'py>(&self, py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyAny>> {
        let s = &self.samples;
        Ok(match name {
            "scenario_name" => any(py, self.scenario.name.as_str())?,
            "relaxation" => any(py, self.scenario.relaxation)?,
            "allocator" => any(py, self.scenario.allocator.as_str())?,
            "mcap_path" => any(py, self.mcap_string())?,
            "n_agents" => any(py, self.n)?,
            "mass" => any(py, self.mass)?,
            "gravity" => any(py, self.scenario.physics.gravity)?,
            "hover_roll_limit" => any(py, self.hover_roll_limit)?,
            "t" => column(py, s, |x| Some(x.t)).into_any(),
            "position" => column3(py, s, |x| Some(x.position)).into_any(),
            "velocity" => column3(py, s, |x| Some(x.velocity)).into_any(),
            "reference_position" => column3(py, s, |x| Some(x.reference_position)).into_any(),
            "attitude_rpy" => column3(py, s, |x| Some(x.roll_pitch_yaw)).into_any(),
            "reference_rpy" => column3(py, s, |x| Some(x.reference_roll_pitch_yaw)).into_any(),
            "reference_roll" => column(py, s, |x| Some(x.reference_roll)).into_any(),
            "planned_roll" => column(py, s, |x| x.planned_roll).into_any(),
            "planned_rpy" => column3(py, s, |x| x.planned_roll_pitch_yaw).into_any(),
            "attitude_error" => column(py, s, |x| x.attitude_error).into_any(),
            "theta" => column(py, s, |x| x.theta).into_any(),
            "e_f" => column(py, s, |x| x.e_f).into_any(),
            "saturated_agents" => {
                let v: Vec<i64> = s
                    .iter()
                    .map(|x| {
                        x.saturated_agents
                            .map_or(-1, |c| i64::try_from(c).unwrap_or(i64::MAX))
                    })
                    .collect();
                PyArray1::from_owned_array(py, Array1::from(v)).into_any()
            }
            "V_x" => column(py, s, |x| x.v_x).into_any(),
            "V_R" => column(py, s, |x| x.v_r).into_any(),
            "cycle_error" => {
                let v: Vec<bool> = s.iter().map(|x| x.cycle_error).collect();
                bool_array(py, &v).into_any()
            }
            "commands" => agent_columns(py, s, self.n, |x| &x.commands).into_any(),
            "actual" => agent_columns(py, s, self.n, |x| &x.actual).into_any(),
            "failed" => {
                let a = Array2::from_shape_fn((s.len(), self.n), |(k, i)| {
                    s.get(k)
                        .and_then(|x| x.failed.get(i))
                        .copied()
                        .unwrap_or(false)
                });
                PyArray2::from_owned_array(py, a).into_any()
            }
            "summary" => record_to_py(py, &self.summary)?,
            "paper_metrics" => record_to_py(py, &self.paper)?,
            "scenario_toml" => any(py, self.scenario_toml()?)?,
            other => {
                return Err(PyAttributeError::new_err(format!(
                    "SimResult has no field '{other}'"
                )))
            }
        })
    }

    fn mcap_string(&self) -> Option<String> {
        self.mcap.as_ref().map(|p| p.display().to_string())
    }
}

#[pymethods]
impl PySimResult {
    /// (K,) time `t` (s).
    #[getter]
    fn t<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.field(py, "t")
    }

    /// (K, 3) position `x` of the centre of mass (m).
    #[getter]
    fn position<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.field(py, "position")
    }

    /// (K, 3) world velocity `x_dot` (m/s).
    #[getter]
    fn velocity<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.field(py, "velocity")
    }

    /// (K, 3) reference position `x_r` (m).
    #[getter]
    fn reference_position<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.field(py, "reference_position")
    }

    /// (K, 3) roll, pitch, yaw of `R` (rad, ZYX: `R = R_z(yaw) R_y(pitch) R_x(roll)`).
    #[getter]
    fn attitude_rpy<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.field(py, "attitude_rpy")
    }

    /// (K, 3) roll, pitch, yaw of the reference `R_r` (rad).
    #[getter]
    fn reference_rpy<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.field(py, "reference_rpy")
    }

    /// (K,) reference roll `phi_r` (rad).
    #[getter]
    fn reference_roll<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.field(py, "reference_roll")
    }

    /// (K,) planned roll `phi_d = atan2(R_d[2,1], R_d[2,2])` (rad); NaN if not reported.
    #[getter]
    fn planned_roll<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.field(py, "planned_roll")
    }

    /// (K, 3) roll, pitch, yaw of the planned `R_d` (rad); NaN if not reported.
    #[getter]
    fn planned_rpy<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.field(py, "planned_rpy")
    }

    /// (K,) angle between `R` and the planned `R_d` (rad); NaN if not reported.
    #[getter]
    fn attitude_error<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.field(py, "attitude_error")
    }

    /// (K,) planner bisection angle `theta*` (rad); NaN if not reported.
    #[getter]
    fn theta<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.field(py, "theta")
    }

    /// (K,) allocation error `e_f = ||u_fd - u_f||` (N); NaN if not reported.
    #[getter]
    fn e_f<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.field(py, "e_f")
    }

    /// (K,) int64: agents the allocator saturated (-1 if not reported).
    #[getter]
    fn saturated_agents<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.field(py, "saturated_agents")
    }

    /// (K,) Lyapunov candidate `V_x = ||e_x||_{K_x} + ||e_v||_{K_v}`; NaN if not reported.
    #[getter(V_x)]
    fn v_x<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.field(py, "V_x")
    }

    /// (K,) Lyapunov candidate `V_R = Psi(R, R_d) + ||e_Omega||_{K_Omega}`; NaN if not reported.
    #[getter(V_R)]
    fn v_r<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.field(py, "V_R")
    }

    /// (K,) bool: the controller skipped the cycle (held its previous commands).
    #[getter]
    fn cycle_error<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.field(py, "cycle_error")
    }

    /// (K, n, 3) commands per agent: `eta_x`, `eta_y` (rad), `thrust` (N).
    #[getter]
    fn commands<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.field(py, "commands")
    }

    /// (K, n, 3) actual actuator outputs at each tick (before the new commands act).
    #[getter]
    fn actual<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.field(py, "actual")
    }

    /// (K, n) bool: true failure flags of the agents.
    #[getter]
    fn failed<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.field(py, "failed")
    }

    /// Every field of tvmd-sim's `RunSummary` as a dict (a fresh dict per access).
    #[getter]
    fn summary<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.field(py, "summary")
    }

    /// tvmd-sim's `PaperMetrics` (SPEC "Reproduction targets") as a dict.
    #[getter]
    fn paper_metrics<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.field(py, "paper_metrics")
    }

    /// Name of the scenario that ran (`"<name>-s<s>"` in a relaxation sweep).
    #[getter]
    fn scenario_name(&self) -> &str {
        &self.scenario.name
    }

    /// Planner relaxation `s` of the run.
    #[getter]
    fn relaxation(&self) -> f64 {
        self.scenario.relaxation
    }

    /// Allocator of the run.
    #[getter]
    fn allocator(&self) -> &str {
        &self.scenario.allocator
    }

    /// Path of the MCAP log written, or None.
    #[getter]
    fn mcap_path(&self) -> Option<String> {
        self.mcap_string()
    }

    /// Number of agents `n`.
    #[getter]
    fn n_agents(&self) -> usize {
        self.n
    }

    /// Team mass `m_C` (kg).
    #[getter]
    fn mass(&self) -> Option<f64> {
        self.mass
    }

    /// Gravity `g` of the run (m/s^2).
    #[getter]
    fn gravity(&self) -> f64 {
        self.scenario.physics.gravity
    }

    /// `atan(c_y(1, s))` (rad): the planned roll at which the planner saturates in hover for
    /// this team, limits and `s`.
    #[getter]
    fn hover_roll_limit(&self) -> Option<f64> {
        self.hover_roll_limit
    }

    /// The scenario that ran (overrides applied), as TOML text.
    #[getter]
    fn scenario_toml(&self) -> PyResult<String> {
        self.scenario
            .to_toml_string()
            .map_err(|e| sim_error(e, "", None))
    }

    /// The field names, in `to_dict` order.
    #[classattr]
    #[pyo3(name = "FIELDS")]
    fn field_names<'py>(py: Python<'py>) -> PyResult<Bound<'py, PyTuple>> {
        PyTuple::new(py, RESULT_FIELDS)
    }

    /// Every field as a dict (arrays, the summary dicts and the scenario TOML).
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let dict = PyDict::new(py);
        for name in RESULT_FIELDS {
            dict.set_item(*name, self.field(py, name)?)?;
        }
        Ok(dict)
    }

    fn __len__(&self) -> usize {
        self.samples.len()
    }

    fn __repr__(&self) -> String {
        format!(
            "SimResult(scenario_name='{}', relaxation={}, allocator='{}', samples={}, \
             n_agents={}, mcap_path={})",
            self.scenario.name,
            self.scenario.relaxation,
            self.scenario.allocator,
            self.samples.len(),
            self.n,
            self.mcap_string()
                .map_or_else(|| "None".to_string(), |p| format!("'{p}'"))
        )
    }
}

/// Registers the submodule `sim` (`tvmd._tvmd.sim`).
pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    let sim = PyModule::new(py, "tvmd.sim")?;
    sim.setattr(
        "__doc__",
        "The tvmd-sim simulator: the paper's simulation and other scenarios with the tvmd \
         controller in the loop (see tvmd/sim.py).",
    )?;
    sim.add_function(wrap_pyfunction!(builtin_scenarios, &sim)?)?;
    sim.add_function(wrap_pyfunction!(scenario_toml, &sim)?)?;
    sim.add_function(wrap_pyfunction!(run, &sim)?)?;
    sim.add_function(wrap_pyfunction!(run_many, &sim)?)?;
    sim.add_function(wrap_pyfunction!(relaxation_sweep, &sim)?)?;
    sim.add_class::<PySimResult>()?;
    m.add_submodule(&sim)
}
