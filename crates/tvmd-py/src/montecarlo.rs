//! `tvmd.sim`'s Monte Carlo functions: thin adapters over `tvmd_studies::montecarlo`. Specs and rows
//! cross the boundary as JSON text so that any `concurrent.futures.Executor` (a process pool,
//! a Dask cluster) can ship them; `tvmd/sim.py`'s `monte_carlo` composes them.

use std::path::PathBuf;

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use tvmd_scenario::Scenario;
use tvmd_studies::montecarlo::{
    fly_all_until, fly_flight_until, with_law, Distributions, FlightRow, FlightSpec, Study,
    StudyReport, DEFAULT_SCENARIO,
};

use crate::convert::{jobs_arg, law_arg, record_to_py, scenario_arg, Int, USIZE_MAX};
use crate::errors::value_error;
use crate::interrupt::{interruptible, Ended};

#[doc = include_str!("../docstrings/tvmd.sim.monte_carlo_specs.txt")]
#[pyfunction]
#[pyo3(
    signature = (scenario = None, *, toml = None, runs = Int::of(100), seed = Int::of(0), teams = None, allocators = None, model_errors = None, distributions = None, law = None),
    text_signature = "(scenario=None, *, toml=None, runs=100, seed=0, teams=None, allocators=None, model_errors=None, distributions=None, law=None)"
)]
#[allow(clippy::too_many_arguments)]
fn monte_carlo_specs(
    scenario: Option<&Bound<'_, PyAny>>,
    toml: Option<String>,
    runs: Int,
    seed: Int,
    teams: Option<Vec<String>>,
    allocators: Option<Vec<String>>,
    model_errors: Option<Vec<f64>>,
    distributions: Option<&Bound<'_, PyAny>>,
    law: Option<&Bound<'_, PyAny>>,
) -> PyResult<Vec<String>> {
    let law = law
        .filter(|l| !l.is_none())
        .map(|l| law_arg(l, "law"))
        .transpose()?;
    let base = match (scenario.filter(|s| !s.is_none()), toml) {
        (Some(_), Some(_)) => {
            return Err(PyValueError::new_err(
                "give either `scenario` (a name or a file) or `toml` (TOML text), not both",
            ))
        }
        (Some(s), None) => scenario_arg(s, "scenario")?,
        (None, Some(text)) => Scenario::from_toml_str(&text).map_err(value_error)?,
        (None, None) => Scenario::builtin(DEFAULT_SCENARIO).map_err(value_error)?,
    };
    let base = with_law(base, law).map_err(value_error)?;
    let runs = runs.to("runs", 1, USIZE_MAX)?;
    let seed = seed.to("seed", 0, u64::MAX.into())?;
    let distributions = match distributions.filter(|d| !d.is_none()) {
        None => Distributions::default(),
        Some(d) => {
            let py = d.py();
            let text: String = py
                .import(pyo3::intern!(py, "json"))?
                .call_method1(pyo3::intern!(py, "dumps"), (d,))?
                .extract()?;
            serde_json::from_str(&text)
                .map_err(|e| PyValueError::new_err(format!("`distributions`: {e}")))?
        }
    };
    let study = Study {
        scenario: base,
        runs,
        seed,
        teams: teams.unwrap_or_default(),
        allocators: allocators.unwrap_or_default(),
        model_errors: model_errors.unwrap_or_default(),
        distributions,
    };
    let specs = study.specs().map_err(value_error)?;
    specs
        .iter()
        .map(|s| s.to_json().map_err(value_error))
        .collect()
}

#[doc = include_str!("../docstrings/tvmd.sim.monte_carlo_flight.txt")]
#[pyfunction]
fn monte_carlo_flight(py: Python<'_>, spec: &str) -> PyResult<String> {
    let spec = FlightSpec::from_json(spec).map_err(value_error)?;
    // Ctrl-C stops the flight at its next controller tick (an executor's task too).
    let row = match interruptible(py, |cancel| fly_flight_until(&spec, Some(cancel)))? {
        Ended::Finished(row) => row.map_err(value_error)?,
        Ended::Interrupted { signal, .. } => return Err(signal),
    };
    let row = row.ok_or_else(|| PyValueError::new_err("the flight was stopped"))?;
    serde_json::to_string(&row).map_err(|e| PyValueError::new_err(e.to_string()))
}

#[doc = include_str!("../docstrings/tvmd.sim.monte_carlo_fly.txt")]
#[pyfunction]
#[pyo3(signature = (specs, *, jobs = None))]
fn monte_carlo_fly(py: Python<'_>, specs: Vec<String>, jobs: Option<Int>) -> PyResult<Vec<String>> {
    let jobs = jobs_arg(jobs.as_ref())?;
    let specs = specs
        .iter()
        .map(|s| FlightSpec::from_json(s))
        .collect::<Result<Vec<_>, _>>()
        .map_err(value_error)?;
    let json = |rows: &[FlightRow]| -> PyResult<Vec<String>> {
        rows.iter()
            .map(|r| serde_json::to_string(r).map_err(|e| PyValueError::new_err(e.to_string())))
            .collect()
    };
    match interruptible(py, |cancel| fly_all_until(&specs, jobs, None, Some(cancel)))? {
        Ended::Finished(flown) => json(&flown.map_err(value_error)?.rows),
        // Ctrl-C: the flights in the air stop at their next tick; the finished rows travel
        // with the exception (`partial`), so that nothing finished is silently lost.
        Ended::Interrupted { signal, partial } => {
            let rows = partial.map(|f| f.rows).unwrap_or_default();
            let message = format!(
                "monte_carlo stopped: {} of {} flights finished (their rows: the exception's \
                 `partial`)",
                rows.len(),
                specs.len()
            );
            let value = signal.value(py);
            let _ = value.setattr("partial", json(&rows)?);
            // Python 3.11+: the note prints under the traceback.
            let _ = value.call_method1("add_note", (message,));
            Err(signal)
        }
    }
}

#[doc = include_str!("../docstrings/tvmd.sim.monte_carlo_report.txt")]
#[pyfunction]
#[pyo3(signature = (rows, *, out = None))]
fn monte_carlo_report<'py>(
    py: Python<'py>,
    rows: Vec<String>,
    out: Option<PathBuf>,
) -> PyResult<Bound<'py, PyAny>> {
    let rows = rows
        .iter()
        .map(|r| serde_json::from_str::<FlightRow>(r))
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| PyValueError::new_err(format!("`rows`: not a flight row: {e}")))?;
    let report = py
        .detach(|| StudyReport::new(rows, out.as_deref()))
        .map_err(value_error)?;
    record_to_py(py, &report)
}

/// Checks a report directory before a study flies (`monte_carlo(out=...)`): not a file, made
/// if missing, writable; the error names the path.
#[pyfunction]
#[pyo3(name = "_check_report_dir")]
fn check_report_dir(out: PathBuf) -> PyResult<()> {
    tvmd_log::paths::check_output_dir(&out, "the report directory (`out`)").map_err(value_error)
}

/// Adds the Monte Carlo functions to the `sim` submodule.
pub(crate) fn register(sim: &Bound<'_, PyModule>) -> PyResult<()> {
    sim.add_function(wrap_pyfunction!(monte_carlo_specs, sim)?)?;
    sim.add_function(wrap_pyfunction!(monte_carlo_flight, sim)?)?;
    sim.add_function(wrap_pyfunction!(monte_carlo_fly, sim)?)?;
    sim.add_function(wrap_pyfunction!(monte_carlo_report, sim)?)?;
    sim.add_function(wrap_pyfunction!(check_report_dir, sim)?)?;
    Ok(())
}
