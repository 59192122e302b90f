//! The simulator `tvmd-sim` as the submodule `tvmd._tvmd.sim` (re-exported as `tvmd.sim`;
//! documented in `python/tvmd/sim.pyi`). Thin like the rest: tvmd-sim loads (`Scenario::load`),
//! overrides (`Overrides`) and runs (`runner::run_many`, `runner::sweep_specs`) the scenarios;
//! this module converts arguments, results and errors. Runs release the GIL.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

use pyo3::exceptions::{PyKeyboardInterrupt, PyOSError, PyRuntimeError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString};

use tvmd_sim::actuators::ActuatorCommand;
use tvmd_sim::control::hover_roll_limit;
use tvmd_sim::control::pil::PilTarget;
use tvmd_sim::runner::{self, sweep_specs, RunOutcome, RunSpec};
use tvmd_sim::scenario::{NullSpaceConfig, Overrides, Precision, Scenario, BUILTIN_NAMES};
use tvmd_sim::sim::{PaperMetrics, RunResult, RunSummary, Sample, SampleRetention};
use tvmd_sim::SimError;

use crate::convert::{scalars, shape_error, shaped};
use crate::record::record;

/// The default scenario of `run` and `relaxation_sweep`.
const DEFAULT_SCENARIO: &str = "paper-tilt";

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
];

/// What was done with the file an I/O error names.
const READ: &str = "cannot read the scenario file";
const WRITE: &str = "cannot write the MCAP log";

/// The Python exception of a tvmd-sim error, the message prefixed with `context`; an I/O error
/// names `file` (an `OSError` of the errno's subclass when the OS gave one).
fn sim_error(error: SimError, context: &str, file: Option<(&str, &Path)>) -> PyErr {
    let (message, errno) = match &error {
        SimError::Io(io) => {
            let what = file.map_or("I/O error", |(what, _)| what);
            (format!("{context}{what}: {io}"), io.raw_os_error())
        }
        SimError::File { source, path, .. } => {
            let message = format!("{context}{error}");
            let path = path.display().to_string();
            return match source.raw_os_error() {
                Some(errno) => PyOSError::new_err((errno, message, path)),
                None => PyOSError::new_err(message),
            };
        }
        SimError::Interrupted => return PyKeyboardInterrupt::new_err(format!("{context}{error}")),
        SimError::Mcap(_) | SimError::LogRead(_) | SimError::LogFinished => {
            (format!("{context}{error}"), None)
        }
        SimError::PathClash(_)
        | SimError::InvalidArgument { .. }
        | SimError::InvalidTeam(_)
        | SimError::InvalidScenario { .. }
        | SimError::ScenarioParse { .. }
        | SimError::UnknownScenario { .. } => {
            return PyValueError::new_err(format!("{context}{error}"))
        }
        _ => return PyRuntimeError::new_err(format!("{context}{error}")),
    };
    match (errno, file.map(|(_, path)| path.display().to_string())) {
        (Some(errno), Some(path)) => PyOSError::new_err((errno, message, path)),
        (Some(errno), None) => PyOSError::new_err((errno, message)),
        (None, Some(path)) => PyOSError::new_err(format!("{message}: '{path}'")),
        (None, None) => PyOSError::new_err(message),
    }
}

/// A tvmd-sim error without a file.
pub(crate) fn value_error(error: SimError) -> PyErr {
    sim_error(error, "", None)
}

/// The scenario of a `scenario` argument: a `str` by the CLI's name-or-file rule
/// (`Scenario::load`), an `os.PathLike` a file.
pub(crate) fn scenario_arg(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<Scenario> {
    if let Ok(s) = obj.cast::<PyString>() {
        let s = s.to_cow()?;
        return Scenario::load(&s).map_err(|e| sim_error(e, "", Some((READ, Path::new(&*s)))));
    }
    if obj.hasattr("__fspath__")? {
        let path: PathBuf = obj.extract().map_err(|e| {
            PyTypeError::new_err(format!("`{name}` is not a usable file path: {e}"))
        })?;
        return Scenario::from_file(&path).map_err(|e| sim_error(e, "", Some((READ, &path))));
    }
    let got = obj.get_type().name()?;
    Err(PyTypeError::new_err(format!(
        "`{name}` must be a built-in scenario name or a path to a TOML file (str or \
         os.PathLike), got {got}"
    )))
}

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
    pub(crate) max_samples: Option<i64>,
    pub(crate) team: Option<String>,
}

/// A `max_samples` argument: `None` keeps every tick, `n >= 0` at most `n` evenly spaced.
fn retention_arg(max_samples: Option<i64>) -> PyResult<SampleRetention> {
    let Some(n) = max_samples else {
        return Ok(SampleRetention::All);
    };
    let n = usize::try_from(n).map_err(|_| {
        PyValueError::new_err(format!("`max_samples` must be >= 0 or None, got {n}"))
    })?;
    Ok(SampleRetention::AtMost(n))
}

/// A `null_space` argument ("margin", "inward-tilt=<rad>"), checked.
pub(crate) fn null_space_arg(spec: Option<&str>) -> PyResult<Option<NullSpaceConfig>> {
    let Some(spec) = spec else {
        return Ok(None);
    };
    let config: NullSpaceConfig = spec
        .parse()
        .map_err(|e| PyValueError::new_err(format!("`null_space`: {e}")))?;
    config.validate().map_err(value_error)?;
    Ok(Some(config))
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
            (None, Some(text)) => Scenario::from_toml_str(&text).map_err(value_error)?,
            (None, None) => Scenario::builtin(DEFAULT_SCENARIO).map_err(value_error)?,
        };
        let precision = self.precision.as_deref().map(str::parse::<Precision>);
        let precision = precision.transpose().map_err(value_error)?;
        let pil = self.pil.as_deref().map(str::parse::<PilTarget>);
        let pil = pil
            .transpose()
            .map_err(|e| PyValueError::new_err(format!("`pil`: {e}")))?;
        let overrides = Overrides {
            relaxation: self.relaxation,
            allocator: self.allocator,
            precision,
            null_space: null_space_arg(self.null_space.as_deref())?,
            team: self.team,
        };
        overrides.apply(&mut scenario).map_err(value_error)?;
        let samples = retention_arg(self.max_samples)?;
        let spec = RunSpec::on_target(scenario, self.mcap, pil, precision);
        let mut spec = spec.map_err(value_error)?;
        spec.samples = samples;
        Ok(spec)
    }
}

/// A `run_many` entry: a scenario (name or path) or a dict of `run` keyword arguments.
fn run_item(item: &Bound<'_, PyAny>, k: usize) -> PyResult<RunSpec> {
    let name = format!("runs[{k}]");
    let Ok(dict) = item.cast::<PyDict>() else {
        if item.is_instance_of::<PyString>() || item.hasattr("__fspath__")? {
            let scenario = Some(item);
            return RunArgs {
                scenario,
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
        null_space: opt(dict, &name, "null_space")?,
        precision: opt(dict, &name, "precision")?,
        pil: opt(dict, &name, "pil")?,
        max_samples: opt(dict, &name, "max_samples")?,
        team: opt(dict, &name, "team")?,
    }
    .spec(&format!("{name}['scenario']"))
}

/// Runs the specs on tvmd-sim's worker pool with the GIL released; the first failure in input
/// order is raised, its message prefixed with `label(k)`.
fn run_specs(
    py: Python<'_>,
    specs: Vec<RunSpec>,
    jobs: Option<i64>,
    label: impl Fn(usize, &RunSpec) -> String,
) -> PyResult<Vec<PySimResult>> {
    let jobs = jobs
        .map(|j| {
            let error = || PyValueError::new_err(format!("`jobs` must be >= 1, got {j}"));
            usize::try_from(j)
                .ok()
                .filter(|j| *j >= 1)
                .ok_or_else(error)
        })
        .transpose()?;
    runner::check_batch_outputs(&specs, &[]).map_err(value_error)?;
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

/// How often a waiting batch looks for Python signals (Ctrl-C).
const SIGNAL_POLL: std::time::Duration = std::time::Duration::from_millis(20);

/// Runs the batch on tvmd-sim's pool while this thread, GIL released, checks for Python signals
/// every [`SIGNAL_POLL`]: on `KeyboardInterrupt` (or any signal handler's exception) the
/// flights stop at their next controller tick (logs finalised), and the exception is raised.
fn run_interruptibly(
    py: Python<'_>,
    specs: Vec<RunSpec>,
    jobs: Option<usize>,
) -> PyResult<Vec<RunOutcome>> {
    let cancel = AtomicBool::new(false);
    std::thread::scope(|scope| {
        let batch = scope.spawn(|| runner::run_many_until(specs, jobs, None, Some(&cancel)));
        while !batch.is_finished() {
            py.detach(|| std::thread::sleep(SIGNAL_POLL));
            if let Err(signal) = py.check_signals() {
                cancel.store(true, Ordering::Relaxed);
                // The flights stop within one controller tick; join them so that their logs
                // are complete when the exception reaches the caller.
                let _ = py.detach(|| batch.join());
                return Err(signal);
            }
        }
        batch
            .join()
            .map_err(|_| PyRuntimeError::new_err("tvmd-sim: the batch thread panicked"))
    })
}

/// The names of the built-in scenarios.
#[pyfunction]
fn builtin_scenarios() -> Vec<&'static str> {
    BUILTIN_NAMES.to_vec()
}

/// A built-in scenario as TOML text (every field). See the stub.
#[pyfunction]
fn scenario_toml(name: &str) -> PyResult<String> {
    let scenario = Scenario::builtin(name);
    scenario
        .and_then(|s| s.to_toml_string())
        .map_err(value_error)
}

/// Runs one scenario with the tvmd controller in the loop. See the stub for arguments.
#[pyfunction]
#[pyo3(signature = (scenario = None, *, toml = None, mcap = None, relaxation = None, allocator = None, precision = None, pil = None, null_space = None, max_samples = None, team = None))]
#[allow(clippy::too_many_arguments)]
fn run(
    py: Python<'_>,
    scenario: Option<&Bound<'_, PyAny>>,
    toml: Option<String>,
    mcap: Option<PathBuf>,
    relaxation: Option<f64>,
    allocator: Option<String>,
    precision: Option<String>,
    pil: Option<String>,
    null_space: Option<String>,
    max_samples: Option<i64>,
    team: Option<String>,
) -> PyResult<PySimResult> {
    let spec = RunArgs {
        scenario,
        toml,
        mcap,
        relaxation,
        allocator,
        null_space,
        precision,
        pil,
        max_samples,
        team,
    }
    .spec("scenario")?;
    run_specs(py, vec![spec], Some(1), |_, _| String::new())?
        .pop()
        .ok_or_else(|| PyRuntimeError::new_err("tvmd-sim returned no result"))
}

/// Runs many scenarios in parallel threads; results in input order. See the stub.
#[pyfunction]
#[pyo3(signature = (runs, *, jobs = None))]
fn run_many(
    py: Python<'_>,
    runs: &Bound<'_, PyAny>,
    jobs: Option<i64>,
) -> PyResult<Vec<PySimResult>> {
    let specs = run_items(runs)?;
    run_specs(py, specs, jobs, |k, s| {
        format!("runs[{k}] ({}): ", s.scenario.name)
    })
}

/// The runs of a `run_many` batch, each loaded and validated ([`run_item`]).
pub(crate) fn run_items(runs: &Bound<'_, PyAny>) -> PyResult<Vec<RunSpec>> {
    if runs.is_instance_of::<PyString>() || runs.is_instance_of::<PyDict>() {
        return Err(PyTypeError::new_err(
            "`runs` must be a sequence of runs (names, paths or dicts), not a single str or dict",
        ));
    }
    runs.try_iter()
        .map_err(|_| PyTypeError::new_err("`runs` must be an iterable of runs"))?
        .enumerate()
        .map(|(k, item)| run_item(&item?, k))
        .collect()
}

/// The paper's relaxation study: one scenario flown once per relaxation `s`. See the stub.
#[pyfunction]
#[pyo3(signature = (relaxations = None, scenario = None, *, toml = None, allocator = None, precision = None, mcap_dir = None, jobs = None, pil = None, max_samples = None))]
#[allow(clippy::too_many_arguments)]
fn relaxation_sweep(
    py: Python<'_>,
    relaxations: Option<&Bound<'_, PyAny>>,
    scenario: Option<&Bound<'_, PyAny>>,
    toml: Option<String>,
    allocator: Option<String>,
    precision: Option<String>,
    mcap_dir: Option<PathBuf>,
    jobs: Option<i64>,
    pil: Option<String>,
    max_samples: Option<i64>,
) -> PyResult<Vec<PySimResult>> {
    let args = RunArgs {
        scenario,
        toml,
        allocator,
        precision,
        pil,
        max_samples,
        ..RunArgs::default()
    };
    let specs = sweep_run_specs(relaxations, args, mcap_dir)?;
    run_specs(py, specs, jobs, |_, s| {
        format!("s = {} ({}): ", s.scenario.relaxation, s.scenario.name)
    })
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

/// A scenario in a `SimResult`'s pickle: its TOML (every field, validated on the way back).
mod scenario_as_toml {
    use serde::{Deserialize, Deserializer, Serializer};
    use tvmd_sim::scenario::Scenario;

    pub(super) fn serialize<S: Serializer>(s: &Scenario, out: S) -> Result<S::Ok, S::Error> {
        let text = s.to_toml_string().map_err(serde::ser::Error::custom)?;
        out.serialize_str(&text)
    }

    pub(super) fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Scenario, D::Error> {
        let text = String::deserialize(d)?;
        Scenario::from_toml_str(&text).map_err(serde::de::Error::custom)
    }
}

/// One run as `SimResult` keeps it: the scenario that ran, its samples and metrics.
#[derive(serde::Serialize, serde::Deserialize)]
pub(crate) struct SimData {
    #[serde(with = "scenario_as_toml")]
    scenario: Scenario,
    mcap: Option<PathBuf>,
    samples: Vec<Sample>,
    sample_stride: usize,
    summary: RunSummary,
    paper: PaperMetrics,
    hover_roll_limit: Option<f64>,
    mass: Option<f64>,
    n: usize,
}

impl SimData {
    fn new(spec: RunSpec, result: RunResult) -> Self {
        let scenario = spec.scenario;
        let team = scenario.team_body().ok();
        let n = result.samples.first().map(|s| s.commands.len());
        Self {
            mass: team.as_ref().map(|t| t.mass()),
            paper: result.paper,
            hover_roll_limit: hover_roll_limit(&scenario, scenario.relaxation).ok(),
            n: n.or_else(|| team.as_ref().map(|t| t.len())).unwrap_or(0),
            mcap: spec.log,
            samples: result.samples,
            sample_stride: result.sample_stride,
            summary: result.summary,
            scenario,
        }
    }

    fn mcap_string(&self) -> Option<String> {
        self.mcap.as_ref().map(|p| p.display().to_string())
    }

    /// A (K, ...) array of `K` per-sample values of `shape` each.
    fn column<'py, T: numpy::Element, I: IntoIterator<Item = T>>(
        &self,
        py: Python<'py>,
        shape: &[usize],
        f: impl Fn(&Sample) -> I,
    ) -> PyResult<Bound<'py, PyAny>> {
        let values = self.samples.iter().flat_map(f).collect();
        shaped(py, values, &[&[self.samples.len()], shape].concat())
    }

    /// (K,) values; NaN where a sample has none.
    fn scalar<'py>(
        &self,
        py: Python<'py>,
        f: impl Fn(&Sample) -> Option<f64>,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.column(py, &[], |s| [f(s).unwrap_or(f64::NAN)])
    }

    /// (K, 3) values; NaN rows where a sample has none.
    fn vector<'py>(
        &self,
        py: Python<'py>,
        f: impl Fn(&Sample) -> Option<[f64; 3]>,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.column(py, &[3], |s| f(s).unwrap_or([f64::NAN; 3]))
    }

    /// (K, n, 3) actuator values `eta_x, eta_y, thrust`.
    fn agents<'py>(
        &self,
        py: Python<'py>,
        f: impl Fn(&Sample) -> &[ActuatorCommand],
    ) -> PyResult<Bound<'py, PyAny>> {
        self.column(py, &[self.n, 3], |s| {
            let agent = |i| {
                f(s).get(i).map_or([f64::NAN; 3], |c: &ActuatorCommand| {
                    [c.eta_x, c.eta_y, c.thrust]
                })
            };
            (0..self.n).flat_map(agent).collect::<Vec<_>>()
        })
    }

    fn repr(&self) -> String {
        let mcap = self.mcap_string();
        format!(
            "SimResult(scenario_name='{}', relaxation={}, allocator='{}', precision='{}', \
             samples={}, n_agents={}, mcap_path={})",
            self.scenario.name,
            self.scenario.relaxation,
            self.scenario.allocator,
            self.scenario.controller_precision,
            self.samples.len(),
            self.n,
            mcap.map_or_else(|| "None".to_string(), |p| format!("'{p}'"))
        )
    }
}

record! {
    /// One simulated run: time series (NumPy) and the summary dicts. See the stub.
    "SimResult" in "tvmd.sim" => PySimResult(SimData) repr SimData::repr |py, o| {
        /// Name of the scenario that ran.
        scenario_name => o.scenario.name.as_str(),
        /// Planner relaxation `s` of the run.
        relaxation => o.scenario.relaxation,
        /// Allocator of the run.
        allocator => o.scenario.allocator.as_str(),
        /// The null-space stage of the run ("margin", "inward-tilt=<rad>"), or None.
        null_space => o.scenario.null_space.map(|n| n.to_string()),
        /// The float type the controller flew in, "f64" or "f32".
        precision => o.scenario.controller_precision.as_str(),
        /// Where the controller ran: "host", or the emulated target of a processor-in-the-loop
        /// run (e.g. "cortex-m4 (qemu mps2-an386)").
        controller_target => o.summary.controller_target.as_str(),
        /// Path of the MCAP log written, or None.
        mcap_path => o.mcap_string(),
        /// Number of agents `n`.
        n_agents => o.n,
        /// Team mass `m_C` (kg).
        mass => o.mass,
        /// Gravity `g` (m/s^2).
        gravity => o.scenario.physics.gravity,
        /// `atan(c_y(1, s))` (rad), the planned roll at which the planner saturates in hover.
        hover_roll_limit => o.hover_roll_limit,
        /// Controller ticks between the kept samples (1: every tick; see `max_samples`).
        sample_stride => o.sample_stride,
        /// (K,) time (s).
        t => o.scalar(py, |x| Some(x.t))?,
        /// (K, 3) `x` (m).
        position => o.vector(py, |x| Some(x.position))?,
        /// (K, 3) `x_dot` (m/s).
        velocity => o.vector(py, |x| Some(x.velocity))?,
        /// (K, 3) `x_r` (m).
        reference_position => o.vector(py, |x| Some(x.reference_position))?,
        /// (K, 3) roll, pitch, yaw of `R` (rad, ZYX).
        attitude_rpy => o.vector(py, |x| Some(x.roll_pitch_yaw))?,
        /// (K, 3) roll, pitch, yaw of `R_r` (rad).
        reference_rpy => o.vector(py, |x| Some(x.reference_roll_pitch_yaw))?,
        /// (K,) `phi_r` (rad).
        reference_roll => o.scalar(py, |x| Some(x.reference_roll))?,
        /// (K,) `phi_d` of the planned `R_d` (rad).
        planned_roll => o.scalar(py, |x| x.planned_roll)?,
        /// (K, 3) roll, pitch, yaw of `R_d` (rad).
        planned_rpy => o.vector(py, |x| x.planned_roll_pitch_yaw)?,
        /// (K,) angle between `R` and `R_d` (rad).
        attitude_error => o.scalar(py, |x| x.attitude_error)?,
        /// (K,) angle between `R` and `R_r` (rad).
        reference_attitude_error => o.scalar(py, |x| Some(x.reference_attitude_error))?,
        /// (K,) planner angle `theta*` (rad).
        theta => o.scalar(py, |x| x.theta)?,
        /// (K,) allocation error `e_f` (N).
        e_f => o.scalar(py, |x| x.e_f)?,
        /// (K,) moment error `e_tau` (N m).
        e_tau => o.scalar(py, |x| x.e_tau)?,
        /// (K,) thrust efficiency `||u_f|| / sum_i ||f_i||`.
        thrust_efficiency => o.scalar(py, |x| x.thrust_efficiency)?,
        /// (K,) int64: agents the allocator saturated (-1 if not reported).
        saturated_agents => o.column(py, &[], |x| [x.saturated_agents.map_or(-1, |c| i64::try_from(c).unwrap_or(i64::MAX))])?,
        /// (K,) Lyapunov candidate `V_x`.
        v_x as "V_x" => o.scalar(py, |x| x.v_x)?,
        /// (K,) Lyapunov candidate `V_R`.
        v_r as "V_R" => o.scalar(py, |x| x.v_r)?,
        /// (K,) bool: the controller skipped the cycle.
        cycle_error => o.column(py, &[], |x| [x.cycle_error])?,
        /// (K, n, 3) commanded `eta_x, eta_y, thrust`.
        commands => o.agents(py, |x| &x.commands)?,
        /// (K, n, 3) actual actuator outputs.
        actual => o.agents(py, |x| &x.actual)?,
        /// (K, n) bool: true failure flags.
        failed => o.column(py, &[o.n], |x| (0..o.n).map(|i| x.failed.get(i).copied().unwrap_or(false)).collect::<Vec<_>>())?,
        /// Every field of tvmd-sim's `RunSummary` (a fresh dict per access).
        summary => record_to_py(py, &o.summary)?,
        /// tvmd-sim's `PaperMetrics` as a dict.
        paper_metrics => record_to_py(py, &o.paper)?,
        /// The scenario that ran (overrides applied), as TOML.
        scenario_toml => o.scenario.to_toml_string().map_err(value_error)?,
    }
    methods {
        fn __len__(&self) -> usize {
            self.inner.samples.len()
        }

        /// Pickles as `tvmd.sim._sim_result_from_state(bytes)`: every sample and summary in
        /// CBOR (NaN kept), so an executor's worker can send its result back.
        fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<(Bound<'py, PyAny>, (Bound<'py, pyo3::types::PyBytes>,))> {
            let mut bytes = Vec::new();
            ciborium::into_writer(&self.inner, &mut bytes)
                .map_err(|e| PyRuntimeError::new_err(format!("cannot pickle a SimResult: {e}")))?;
            let rebuild = py.import("tvmd.sim")?.getattr("_sim_result_from_state")?;
            Ok((rebuild, (pyo3::types::PyBytes::new(py, &bytes),)))
        }
    }
}

/// A tvmd-sim record (serde) as Python objects: `json.loads` of its JSON (NaN becomes None).
pub(crate) fn record_to_py<'py, T: serde::Serialize>(
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
    crate::executor::register(&sim)?;
    crate::montecarlo::register(&sim)?;
    m.add_submodule(&sim)
}
