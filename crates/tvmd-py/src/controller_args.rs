//! `tvmd.Controller`'s arguments: the checks and errors that name them, and the copy of them
//! that `pickle` rebuilds the controller from.

use pyo3::exceptions::PyValueError;
use pyo3::intern;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use tvmd_core::controller::{MAX_PERIOD, MIN_PERIOD};
use tvmd_scenario::ScenarioError;
use tvmd_sim::SimError;

use crate::errors::{config_error_of, value_error};

/// A tvmd-sim error about the controller's argument `argument` (`law`, `fault_detection`,
/// `null_space`): the argument and its key, not a scenario field.
pub(crate) fn argument_error(argument: &str, e: impl Into<SimError>) -> PyErr {
    match e.into() {
        SimError::Scenario(ScenarioError::InvalidScenario { field, reason }) => {
            // The scenario's path of the key, without the argument's own table.
            let key = field
                .strip_prefix(argument)
                .map_or(field.as_str(), |k| k.trim_start_matches('.'));
            let key = if key.is_empty() {
                String::new()
            } else {
                format!(", key `{key}`")
            };
            PyValueError::new_err(format!("invalid `{argument}` argument{key}: {reason}"))
        }
        other => value_error(other),
    }
}

/// The control period, in the core's range; else a `tvmd.ConfigError` with the value and the
/// range (1e300 is finite, but no control period).
pub(crate) fn period_arg(period: f64) -> PyResult<()> {
    if (MIN_PERIOD..=MAX_PERIOD).contains(&period) {
        return Ok(());
    }
    let message = format!(
        "`period` = {period:?} s is out of range: the control period must be in \
         [{MIN_PERIOD:?}, {MAX_PERIOD:?}] s"
    );
    Err(config_error_of(message, "period"))
}

/// A deep copy of the arguments, taken once they are known good (a caller's array may change
/// later).
pub(crate) fn deep_copy(arguments: Bound<'_, PyDict>) -> PyResult<Py<PyDict>> {
    let py = arguments.py();
    Ok(py
        .import(intern!(py, "copy"))?
        .call_method1(intern!(py, "deepcopy"), (arguments,))?
        .cast_into::<PyDict>()?
        .unbind())
}
