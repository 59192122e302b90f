//! The simulator `tvmd-sim` as the submodule `tvmd._tvmd.sim` (re-exported by
//! `python/tvmd/sim.py` as `tvmd.sim`): built-in scenarios, one run ([`run`]), a batch of runs
//! in parallel threads ([`run_many`], [`relaxation_sweep`]) and the result record
//! [`PySimResult`] (`tvmd.sim.SimResult`).
//!
//! Thin like the rest of the bindings: scenarios are loaded (`Scenario::load`, the CLI's
//! name-or-file rule), overridden (`Overrides`) and run by `tvmd-sim` (`runner::run_many` on
//! its one worker pool, `runner::sweep_specs`); the metrics come from `RunSummary` and
//! `sim::PaperMetrics`; this module converts arguments and results. Runs release the GIL
//! (`Python::detach`) and come back in input order.
//!
//! Errors: a scenario, TOML text or override that cannot be used raises `ValueError` (the
//! message is tvmd-sim's, naming the field), wrong argument types `TypeError`, I/O errors
//! `OSError` (its errno subclass, e.g. `FileNotFoundError`, with the file name), a run that
//! fails while flying (divergence, controller error) `RuntimeError`. A panic inside tvmd-sim is
//! caught and raised as `RuntimeError` too, never as `PanicException`.

use std::path::{Path, PathBuf};

use numpy::ndarray::{Array1, Array2, Array3};
use numpy::{PyArray1, PyArray2, PyArray3};
use pyo3::exceptions::{PyOSError, PyRuntimeError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString};

use tvmd_sim::actuators::ActuatorCommand;
use tvmd_sim::control::hover_roll_limit;
use tvmd_sim::runner::{self, sweep_specs, RunOutcome, RunSpec};
use tvmd_sim::scenario::{Overrides, Scenario, BUILTIN_NAMES};
use tvmd_sim::sim::{PaperMetrics, RunResult, RunSummary, Sample};
use tvmd_sim::SimError;

use crate::convert::{array1, bool_array, scalars};
use crate::record::record;

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

/// The `jobs` argument: `None` (the available cores) or at least 1.
fn jobs_arg(jobs: Option<i64>) -> PyResult<Option<usize>> {
    jobs.map(|j| {
        usize::try_from(j)
            .ok()
            .filter(|j| *j >= 1)
            .ok_or_else(|| PyValueError::new_err(format!("`jobs` must be >= 1, got {j}")))
    })
    .transpose()
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
    let jobs = jobs_arg(jobs)?;
    let outcomes = py.detach(|| runner::run_many(specs, jobs, None));
    outcomes
        .into_iter()
        .enumerate()
        .map(|(k, RunOutcome { spec, result })| match result {
            Ok(result) => Ok(PySimResult {
                inner: SimData::new(spec, result),
            }),
            Err(e) => Err(run_error(e, &label(k, &spec), spec.log.as_deref())),
        })
        .collect()
}

// ---------------------------------------------------------------------------------------------
// Functions
// ---------------------------------------------------------------------------------------------

/// The names of the built-in scenarios (`"paper-tilt"` is the paper's simulation, see
/// docs/method.md; `"relaxation-<s>"` the relaxation study; failures, A4-Con, ...).
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
    run_specs(py, vec![spec], Some(1), |_, _| String::new())?
        .pop()
        .ok_or_else(|| PyRuntimeError::new_err("tvmd-sim returned no result"))
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

/// One run as `SimResult` keeps it: the scenario that ran, its samples and metrics.
pub(crate) struct SimData {
    scenario: Scenario,
    mcap: Option<PathBuf>,
    samples: Vec<Sample>,
    summary: RunSummary,
    paper: PaperMetrics,
    hover_roll_limit: Option<f64>,
    mass: Option<f64>,
    n: usize,
}

impl SimData {
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

    fn mcap_string(&self) -> Option<String> {
        self.mcap.as_ref().map(|p| p.display().to_string())
    }

    /// A (K,) column; NaN where a sample has no value.
    fn column<'py>(
        &self,
        py: Python<'py>,
        f: impl Fn(&Sample) -> Option<f64>,
    ) -> Bound<'py, PyArray1<f64>> {
        let values: Vec<f64> = self
            .samples
            .iter()
            .map(|s| f(s).unwrap_or(f64::NAN))
            .collect();
        array1(py, &values)
    }

    /// A (K, 3) column; NaN rows where a sample has no value.
    fn column3<'py>(
        &self,
        py: Python<'py>,
        f: impl Fn(&Sample) -> Option<[f64; 3]>,
    ) -> Bound<'py, PyArray2<f64>> {
        let rows: Vec<[f64; 3]> = self
            .samples
            .iter()
            .map(|s| f(s).unwrap_or([f64::NAN; 3]))
            .collect();
        crate::convert::rows_array(py, &rows)
    }

    /// (K, n, 3) actuator values `eta_x, eta_y, thrust`.
    fn agents<'py>(
        &self,
        py: Python<'py>,
        f: impl Fn(&Sample) -> &[ActuatorCommand],
    ) -> Bound<'py, PyArray3<f64>> {
        let a = Array3::from_shape_fn((self.samples.len(), self.n, 3), |(k, i, j)| {
            self.samples
                .get(k)
                .and_then(|s| f(s).get(i))
                .and_then(|c| [c.eta_x, c.eta_y, c.thrust].get(j).copied())
                .unwrap_or(f64::NAN)
        });
        PyArray3::from_owned_array(py, a)
    }

    fn saturated_agents<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<i64>> {
        let v: Vec<i64> = self
            .samples
            .iter()
            .map(|x| {
                x.saturated_agents
                    .map_or(-1, |c| i64::try_from(c).unwrap_or(i64::MAX))
            })
            .collect();
        PyArray1::from_owned_array(py, Array1::from(v))
    }

    fn failed<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<bool>> {
        let a = Array2::from_shape_fn((self.samples.len(), self.n), |(k, i)| {
            self.samples
                .get(k)
                .and_then(|x| x.failed.get(i))
                .copied()
                .unwrap_or(false)
        });
        PyArray2::from_owned_array(py, a)
    }

    fn scenario_toml(&self) -> PyResult<String> {
        self.scenario
            .to_toml_string()
            .map_err(|e| sim_error(e, "", None))
    }

    fn repr(&self) -> String {
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

record! {
    /// The result of one simulated run (read-only; every array access returns a fresh float64
    /// copy, so bind it to a name before indexing in a loop).
    ///
    /// `K` samples, one per controller tick (`t_k = k controller_period`, true state before the
    /// tick's commands act); `n` agents. SI units, z up, angles in rad. Values a controller did
    /// not report at a tick (a skipped cycle) are NaN.
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
    "SimResult" in "tvmd.sim" => PySimResult(SimData) repr SimData::repr |py, o| {
        /// Name of the scenario that ran (`"<name>-s<s>"` in a relaxation sweep).
        scenario_name => o.scenario.name.as_str(),
        /// Planner relaxation `s` of the run.
        relaxation => o.scenario.relaxation,
        /// Allocator of the run.
        allocator => o.scenario.allocator.as_str(),
        /// Path of the MCAP log written, or None.
        mcap_path => o.mcap_string(),
        /// Number of agents `n`.
        n_agents => o.n,
        /// Team mass `m_C` (kg).
        mass => o.mass,
        /// Gravity `g` of the run (m/s^2).
        gravity => o.scenario.physics.gravity,
        /// `atan(c_y(1, s))` (rad): the planned roll at which the planner saturates in hover for
        /// this team, limits and `s`.
        hover_roll_limit => o.hover_roll_limit,
        /// (K,) time `t` (s).
        t => o.column(py, |x| Some(x.t)),
        /// (K, 3) position `x` of the centre of mass (m).
        position => o.column3(py, |x| Some(x.position)),
        /// (K, 3) world velocity `x_dot` (m/s).
        velocity => o.column3(py, |x| Some(x.velocity)),
        /// (K, 3) reference position `x_r` (m).
        reference_position => o.column3(py, |x| Some(x.reference_position)),
        /// (K, 3) roll, pitch, yaw of `R` (rad, ZYX: `R = R_z(yaw) R_y(pitch) R_x(roll)`).
        attitude_rpy => o.column3(py, |x| Some(x.roll_pitch_yaw)),
        /// (K, 3) roll, pitch, yaw of the reference `R_r` (rad).
        reference_rpy => o.column3(py, |x| Some(x.reference_roll_pitch_yaw)),
        /// (K,) reference roll `phi_r` (rad).
        reference_roll => o.column(py, |x| Some(x.reference_roll)),
        /// (K,) planned roll `phi_d = atan2(R_d[2,1], R_d[2,2])` (rad); NaN if not reported.
        planned_roll => o.column(py, |x| x.planned_roll),
        /// (K, 3) roll, pitch, yaw of the planned `R_d` (rad); NaN if not reported.
        planned_rpy => o.column3(py, |x| x.planned_roll_pitch_yaw),
        /// (K,) angle between `R` and the planned `R_d` (rad); NaN if not reported.
        attitude_error => o.column(py, |x| x.attitude_error),
        /// (K,) planner bisection angle `theta*` (rad); NaN if not reported.
        theta => o.column(py, |x| x.theta),
        /// (K,) allocation error `e_f = ||u_fd - u_f||` (N); NaN if not reported.
        e_f => o.column(py, |x| x.e_f),
        /// (K,) int64: agents the allocator saturated (-1 if not reported).
        saturated_agents => o.saturated_agents(py),
        /// (K,) Lyapunov candidate `V_x = ||e_x||_{K_x} + ||e_v||_{K_v}`; NaN if not reported.
        v_x as "V_x" => o.column(py, |x| x.v_x),
        /// (K,) Lyapunov candidate `V_R = Psi(R, R_d) + ||e_Omega||_{K_Omega}`; NaN if not
        /// reported.
        v_r as "V_R" => o.column(py, |x| x.v_r),
        /// (K,) bool: the controller skipped the cycle (held its previous commands).
        cycle_error => bool_array(py, &o.samples.iter().map(|x| x.cycle_error).collect::<Vec<_>>()),
        /// (K, n, 3) commands per agent: `eta_x`, `eta_y` (rad), `thrust` (N).
        commands => o.agents(py, |x| &x.commands),
        /// (K, n, 3) actual actuator outputs at each tick (before the new commands act).
        actual => o.agents(py, |x| &x.actual),
        /// (K, n) bool: true failure flags of the agents.
        failed => o.failed(py),
        /// Every field of tvmd-sim's `RunSummary` as a dict (a fresh dict per access).
        summary => record_to_py(py, &o.summary)?,
        /// tvmd-sim's `PaperMetrics` (see docs/method.md, "Reproduction targets") as a dict.
        paper_metrics => record_to_py(py, &o.paper)?,
        /// The scenario that ran (overrides applied), as TOML text.
        scenario_toml => o.scenario_toml()?,
    }
    methods {
        fn __len__(&self) -> usize {
            self.inner.samples.len()
        }
    }
}

/// A tvmd-sim record (serde) as Python objects (`json.loads` of its JSON: objects become
/// dicts, arrays lists, NaN None).
fn record_to_py<'py, T: serde::Serialize>(
    py: Python<'py>,
    record: &T,
) -> PyResult<Bound<'py, PyAny>> {
    let text = serde_json::to_string(record)
        .map_err(|e| PyRuntimeError::new_err(format!("cannot convert a tvmd-sim record: {e}")))?;
    py.import(pyo3::intern!(py, "json"))?
        .call_method1(pyo3::intern!(py, "loads"), (text,))
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
