//! What `tvmd.sim`'s batch functions need to fly on any `concurrent.futures.Executor` (a
//! process pool, a Dask cluster): a `SimResult` that pickles, the batch checks `run_many` does
//! before flying, and a relaxation study as `run_many` items. `tvmd/sim.py` composes them.

use std::path::PathBuf;

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use tvmd_sim::runner::RunSpec;
use tvmd_sim::sim::SampleRetention;

use crate::convert::{retention_arg, Int};
use crate::errors::value_error;
use crate::runs::RunArgs;
use crate::runs::{batch_label, check_logs, run_item, run_items, run_specs};
use crate::runs::{sweep_label, sweep_run_specs};
use crate::sim_result::{PySimResult, SimData};

/// A `SimResult` from its pickle (`SimResult.__reduce__`).
#[pyfunction]
#[pyo3(name = "_sim_result_from_state")]
fn sim_result_from_state(state: &[u8]) -> PyResult<PySimResult> {
    let inner: SimData = ciborium::from_reader(state)
        .map_err(|e| PyValueError::new_err(format!("not a pickled SimResult: {e}")))?;
    Ok(PySimResult { inner })
}

/// Checks a batch as `run_many` would before flying (every item, and no two runs on one log),
/// for `run_many(executor=...)`, whose items fly one task each.
#[pyfunction]
#[pyo3(name = "_check_runs")]
fn check_runs(runs: &Bound<'_, PyAny>) -> PyResult<usize> {
    let specs = run_items(runs)?;
    check_logs(&specs, &batch_label)?;
    Ok(specs.len())
}

/// Flies item `index` of a `run_many` batch (or, with `sweep`, of a relaxation study's runs) as
/// one executor task; a failure is named as the threads name it (`runs[index] (name): ...`).
#[pyfunction]
#[pyo3(name = "_run_item")]
#[pyo3(signature = (item, index, *, sweep = false))]
fn run_one_item(
    py: Python<'_>,
    item: &Bound<'_, PyAny>,
    index: usize,
    sweep: bool,
) -> PyResult<PySimResult> {
    let spec = run_item(item, index)?;
    let label = |_: usize, spec: &tvmd_sim::runner::RunSpec| {
        if sweep {
            sweep_label(spec)
        } else {
            batch_label(index, spec)
        }
    };
    run_specs(py, vec![spec], Some(1), label)?
        .pop()
        .ok_or_else(|| pyo3::exceptions::PyRuntimeError::new_err("tvmd-sim returned no result"))
}

/// The runs of a relaxation study as `run_many` items (TOML text, log, target, retention), for
/// `relaxation_sweep(executor=...)`.
#[pyfunction]
#[pyo3(name = "_relaxation_sweep_runs")]
#[pyo3(signature = (relaxations = None, scenario = None, *, toml = None, allocator = None, precision = None, mcap_dir = None, pil = None, max_samples = None))]
#[allow(clippy::too_many_arguments)]
fn relaxation_sweep_runs<'py>(
    py: Python<'py>,
    relaxations: Option<&Bound<'py, PyAny>>,
    scenario: Option<&Bound<'py, PyAny>>,
    toml: Option<String>,
    allocator: Option<String>,
    precision: Option<String>,
    mcap_dir: Option<PathBuf>,
    pil: Option<String>,
    max_samples: Option<Int>,
) -> PyResult<Vec<Bound<'py, PyDict>>> {
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
    check_logs(&specs, &|_, s: &RunSpec| sweep_label(s))?;
    specs
        .into_iter()
        .map(|spec| {
            let d = PyDict::new(py);
            d.set_item("toml", spec.scenario.to_toml_string().map_err(value_error)?)?;
            d.set_item("mcap", spec.log)?;
            d.set_item("pil", spec.pil.map(|p| p.to_string()))?;
            let kept = match spec.samples {
                SampleRetention::All => None,
                SampleRetention::AtMost(n) => Some(n),
                SampleRetention::None => Some(0),
            };
            d.set_item("max_samples", kept)?;
            Ok(d)
        })
        .collect()
}

/// Adds the executor helpers to the `sim` submodule.
pub(crate) fn register(sim: &Bound<'_, PyModule>) -> PyResult<()> {
    sim.add_function(wrap_pyfunction!(sim_result_from_state, sim)?)?;
    sim.add_function(wrap_pyfunction!(check_runs, sim)?)?;
    sim.add_function(wrap_pyfunction!(run_one_item, sim)?)?;
    sim.add_function(wrap_pyfunction!(relaxation_sweep_runs, sim)?)?;
    Ok(())
}
