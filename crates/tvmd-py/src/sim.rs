//! The simulator `tvmd-sim` as the submodule `tvmd._tvmd.sim` (re-exported as `tvmd.sim`;
//! documented in `python/tvmd/sim.pyi`). Thin like the rest: tvmd-sim loads (`Scenario::load`),
//! overrides (`Overrides`) and runs (`runner::run_many`, `runner::sweep_specs`) the scenarios;
//! this module declares the functions, [`crate::runs`] converts the arguments and flies the
//! batches. Runs release the GIL.

use std::path::PathBuf;

use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;

use tvmd_scenario::{Scenario, BUILTIN_NAMES};

use crate::convert::{jobs_arg, law_arg, retention_arg, Int};
use crate::errors::value_error;
use crate::runs::{batch_label, run_items, run_items_keeping, run_specs};
use crate::runs::{control_args, team_arg, RunArgs};
use crate::runs::{sweep_label, sweep_run_specs};
use crate::sim_result::{PySimResult, SimData};
use tvmd_sim::runner::RunSpec;
use tvmd_sim::SampleRetention;

/// The names of the built-in scenarios.
#[pyfunction]
fn builtin_scenarios() -> Vec<&'static str> {
    BUILTIN_NAMES.to_vec()
}

#[doc = include_str!("../docstrings/tvmd.sim.scenario_toml.txt")]
#[pyfunction]
fn scenario_toml(name: &str) -> PyResult<String> {
    let scenario = Scenario::builtin(name);
    scenario
        .and_then(|s| s.to_toml_string())
        .map_err(value_error)
}

#[doc = include_str!("../docstrings/tvmd.sim.run.txt")]
#[pyfunction]
#[pyo3(signature = (scenario = None, *, toml = None, mcap = None, relaxation = None, allocator = None, precision = None, pil = None, null_space = None, max_samples = None, team = None, law = None, fault_detection = None, max_rounds = None))]
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
    max_samples: Option<Int>,
    team: Option<&Bound<'_, PyAny>>,
    law: Option<&Bound<'_, PyAny>>,
    fault_detection: Option<&Bound<'_, PyAny>>,
    max_rounds: Option<Bound<'_, PyAny>>,
) -> PyResult<PySimResult> {
    let (team, team_config) = team_arg(team)?;
    let (fault_detection, max_rounds) = control_args(fault_detection, max_rounds.as_ref())?;
    let samples = retention_arg(max_samples.as_ref(), "max_samples")?;
    let law = law.map(|l| law_arg(l, "law")).transpose()?;
    let spec = RunArgs {
        scenario,
        toml,
        mcap,
        relaxation,
        allocator,
        null_space,
        precision,
        pil,
        samples,
        team,
        team_config,
        law,
        fault_detection,
        max_rounds,
    }
    .spec("scenario")?;
    run_specs(py, vec![spec], Some(1), |_, _| String::new())?
        .pop()
        .ok_or_else(|| PyRuntimeError::new_err("tvmd-sim returned no result"))
}

#[doc = include_str!("../docstrings/tvmd.sim.run_many.txt")]
#[pyfunction]
#[pyo3(signature = (runs, *, jobs = None, errors = "raise"))]
fn run_many(
    py: Python<'_>,
    runs: &Bound<'_, PyAny>,
    jobs: Option<Int>,
    errors: &str,
) -> PyResult<Vec<Py<PyAny>>> {
    let jobs = jobs_arg(jobs.as_ref())?;
    match errors {
        "raise" => {
            let specs = run_items(runs)?;
            let results = run_specs(py, specs, jobs, batch_label)?;
            results
                .into_iter()
                .map(|r| Ok(Py::new(py, r)?.into_any()))
                .collect()
        }
        "keep" => run_items_keeping(py, runs, jobs),
        other => Err(PyValueError::new_err(format!(
            "`errors` must be \"raise\" or \"keep\", got {other:?}"
        ))),
    }
}

#[doc = include_str!("../docstrings/tvmd.sim.relaxation_sweep.txt")]
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
    jobs: Option<Int>,
    pil: Option<String>,
    max_samples: Option<Int>,
) -> PyResult<Vec<PySimResult>> {
    let jobs = jobs_arg(jobs.as_ref())?;
    let args = RunArgs {
        scenario,
        toml,
        allocator,
        precision,
        pil,
        samples: retention_arg(max_samples.as_ref(), "max_samples")?,
        ..RunArgs::default()
    };
    let specs = sweep_run_specs(relaxations, args, mcap_dir)?;
    run_specs(py, specs, jobs, |_, s| sweep_label(s))
}

#[doc = include_str!("../docstrings/tvmd.sim.load.txt")]
#[pyfunction]
#[pyo3(signature = (path))]
fn load(py: Python<'_>, path: PathBuf) -> PyResult<PySimResult> {
    const CONTEXT: &str = "cannot load the run log: ";
    let loaded = py
        .detach(|| tvmd_sim::load_run(&path))
        .map_err(|e| match e {
            // The file itself (missing, unreadable, not a regular file): an `OSError`, as in `run`.
            e @ tvmd_sim::SimError::Log(tvmd_log::LogError::File { .. }) => {
                crate::errors::sim_error(e, CONTEXT, None)
            }
            e => PyValueError::new_err(format!("{CONTEXT}{e}")),
        })?;
    if let Some(damage) = &loaded.damage {
        let message = format!(
            "{}: the log is damaged; loaded the {} ticks before the damage ({damage})",
            path.display(),
            loaded.result.samples.len()
        );
        let message = std::ffi::CString::new(message.replace('\0', " "))
            .map_err(|e| PyValueError::new_err(e.to_string()))?;
        let category = py.get_type::<pyo3::exceptions::PyUserWarning>();
        PyErr::warn(py, &category, &message, 1)?;
    }
    let spec = RunSpec {
        scenario: loaded.scenario,
        log: Some(path),
        pil: None,
        samples: SampleRetention::All,
    };
    Ok(PySimResult {
        inner: SimData::new(spec, loaded.result),
    })
}

/// Adds the documentation and the run functions to the `sim` submodule.
pub(crate) fn register(sim: &Bound<'_, PyModule>) -> PyResult<()> {
    sim.setattr(
        "__doc__",
        "The tvmd-sim simulator: the paper's simulation and other scenarios with the tvmd \
         controller in the loop (see tvmd/sim.py).",
    )?;
    sim.add_function(wrap_pyfunction!(builtin_scenarios, sim)?)?;
    sim.add_function(wrap_pyfunction!(scenario_toml, sim)?)?;
    sim.add_function(wrap_pyfunction!(run, sim)?)?;
    sim.add_function(wrap_pyfunction!(run_many, sim)?)?;
    sim.add_function(wrap_pyfunction!(relaxation_sweep, sim)?)?;
    sim.add_function(wrap_pyfunction!(load, sim)?)?;
    Ok(())
}
