//! Python exceptions of the bindings and the mapping of the core's error types onto them.
//!
//! Every exception is a subclass of `ValueError`, so `except ValueError` catches them all:
//!
//! - [`ConfigError`]: a `tvmd_core::ConfigError` (team, limits, gains, settings, failures),
//! - [`InputError`]: a `tvmd_core::InputError` (a non-finite or non-rotation cycle input),
//! - [`CycleError`] (an `InputError`): `Controller.step` rejected its input; the exception
//!   carries the commands to hold as `commands` (n, 4) and the offending input as `field`.
//!
//! The message is always the core's `Display` text.

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use crate::CAPACITY;

pyo3::create_exception!(
    tvmd,
    ConfigError,
    PyValueError,
    "A team, limit, gain, setting or failure mask that cannot be used (tvmd_core::ConfigError). \
Attribute `field`: the offending field (e.g. 'gains.k_x'), or None."
);

pyo3::create_exception!(
    tvmd,
    InputError,
    PyValueError,
    "A control-cycle input that cannot be used: not finite, or not a rotation (tvmd_core::InputError)."
);

pyo3::create_exception!(
    tvmd,
    CycleError,
    InputError,
    "Controller.step rejected its input. Attributes: `commands` (n, 4) float64, the previous \
period's commands to hold (columns eta_x, eta_y, thrust, omega; idle before the first period), \
and `field`, the offending input (e.g. 'state.position')."
);

/// Raises the core's errors as the matching Python exception.
pub(crate) trait OrRaise<T> {
    /// `Err(e)` becomes the Python exception of `e` with `e`'s `Display` message.
    fn or_raise(self) -> PyResult<T>;
}

impl<T> OrRaise<T> for Result<T, tvmd_core::ConfigError> {
    fn or_raise(self) -> PyResult<T> {
        self.map_err(|e| {
            let err = ConfigError::new_err(e.to_string());
            // The core's typed field (e.g. "gains.k_x"), None when the error names none.
            Python::attach(|py| {
                let _ = err
                    .value(py)
                    .setattr("field", e.field().map(|f| f.as_str()));
            });
            err
        })
    }
}

impl<T> OrRaise<T> for Result<T, tvmd_core::InputError> {
    fn or_raise(self) -> PyResult<T> {
        self.map_err(|e| InputError::new_err(e.to_string()))
    }
}

/// The field named by an input error.
fn input_field(e: &tvmd_core::InputError) -> &'static str {
    match *e {
        tvmd_core::InputError::NonFinite { field }
        | tvmd_core::InputError::NotRotation { field } => field,
    }
}

/// A [`CycleError`] exception with the held commands of the first `n` agents attached.
pub(crate) fn cycle_error(
    py: Python<'_>,
    error: &tvmd_core::CycleError<f64, CAPACITY>,
    n: usize,
) -> PyErr {
    let err = CycleError::new_err(error.to_string());
    let commands = crate::convert::commands_array(py, &error.commands, n);
    let value = err.value(py);
    // Attaching the attributes cannot fail on a fresh exception instance; if it somehow did,
    // the exception is still raised with its message.
    let _ = value.setattr("commands", commands);
    let _ = value.setattr("field", input_field(&error.error));
    err
}

/// Registers the exceptions in the module.
pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("ConfigError", py.get_type::<ConfigError>())?;
    m.add("InputError", py.get_type::<InputError>())?;
    m.add("CycleError", py.get_type::<CycleError>())?;
    Ok(())
}
