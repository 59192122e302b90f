//! The Python exceptions (all `ValueError`s) and the one mapping of the core's errors onto them.

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use crate::CAPACITY;

pyo3::create_exception!(
    tvmd,
    ConfigError,
    PyValueError,
    "A team, limit, gain, setting or failure mask that cannot be used. See the stub."
);

pyo3::create_exception!(
    tvmd,
    InputError,
    PyValueError,
    "A control-cycle input that cannot be used: not finite, not a rotation, beyond the cycle's bound, or unattainable."
);

pyo3::create_exception!(
    tvmd,
    CycleError,
    InputError,
    "Controller.step rejected its input; `commands` (n, 4) are the commands to hold."
);

/// Raises the core's errors as the matching Python exception with the core's message.
pub(crate) trait OrRaise<T> {
    /// `Err(e)` becomes the Python exception of `e`.
    fn or_raise(self) -> PyResult<T>;
}

/// A `tvmd.ConfigError` with the core's message and its typed field as `field` (or None).
pub(crate) fn config_error(e: tvmd_core::ConfigError) -> PyErr {
    let err = ConfigError::new_err(e.to_string());
    // Setting an attribute of a fresh exception cannot fail; if it did, the message stays.
    Python::attach(|py| {
        let _ = err
            .value(py)
            .setattr("field", e.field().map(|f| f.as_str()));
    });
    err
}

impl<T> OrRaise<T> for Result<T, tvmd_core::ConfigError> {
    fn or_raise(self) -> PyResult<T> {
        self.map_err(config_error)
    }
}

impl<T> OrRaise<T> for Result<T, tvmd_core::InputError> {
    fn or_raise(self) -> PyResult<T> {
        self.map_err(|e| InputError::new_err(e.to_string()))
    }
}

/// A [`CycleError`] with the held commands of the first `n` agents and the offending field.
pub(crate) fn cycle_error(
    py: Python<'_>,
    error: &tvmd_core::CycleError<f64, CAPACITY>,
    n: usize,
) -> PyErr {
    let err = CycleError::new_err(error.to_string());
    let value = err.value(py);
    let field = error.error.field();
    let _ = crate::convert::commands_array(py, &error.commands, n)
        .map(|c| value.setattr("commands", c));
    let _ = value.setattr("field", field);
    err
}

/// Registers the exceptions.
pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("ConfigError", py.get_type::<ConfigError>())?;
    m.add("InputError", py.get_type::<InputError>())?;
    m.add("CycleError", py.get_type::<CycleError>())?;
    Ok(())
}
