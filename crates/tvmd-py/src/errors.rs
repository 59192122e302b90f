//! The Python exceptions (all `ValueError`s) and the one mapping of the core's and tvmd-sim's
//! errors onto Python exceptions. A leaf: it imports no other module of the crate.

use std::path::Path;

use pyo3::exceptions::{PyKeyboardInterrupt, PyOSError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;

use tvmd_sim::SimError;

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

/// A [`CycleError`] with the held `commands` (the caller's array of the first `n` agents' held
/// commands) and the offending field.
pub(crate) fn cycle_error<'py, const N: usize>(
    py: Python<'py>,
    error: &tvmd_core::CycleError<f64, N>,
    commands: PyResult<Bound<'py, PyAny>>,
) -> PyErr {
    let err = CycleError::new_err(error.to_string());
    let value = err.value(py);
    let field = error.error.field();
    let _ = commands.map(|c| value.setattr("commands", c));
    let _ = value.setattr("field", field);
    err
}

/// What was done with the file an I/O error names: reading a scenario.
pub(crate) const READ: &str = "cannot read the scenario file";
/// What was done with the file an I/O error names: writing a run's log.
pub(crate) const WRITE: &str = "cannot write the MCAP log";

/// The Python exception of a tvmd-sim error, the message prefixed with `context`; an I/O error
/// names `file` (an `OSError` of the errno's subclass when the OS gave one).
pub(crate) fn sim_error(error: SimError, context: &str, file: Option<(&str, &Path)>) -> PyErr {
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

/// Registers the exceptions.
pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("ConfigError", py.get_type::<ConfigError>())?;
    m.add("InputError", py.get_type::<InputError>())?;
    m.add("CycleError", py.get_type::<CycleError>())?;
    Ok(())
}
