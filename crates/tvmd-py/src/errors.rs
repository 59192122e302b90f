//! The Python exceptions (all `ValueError`s) and the one mapping of the core's and tvmd-sim's
//! errors onto Python exceptions. A leaf: it imports no other module of the crate.

use std::path::Path;

use pyo3::exceptions::{PyKeyboardInterrupt, PyOSError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;

use tvmd_log::LogError;
use tvmd_plant::PhysicsError;
use tvmd_scenario::ScenarioError;
use tvmd_sim::SimError;
use tvmd_studies::StudyError;

pyo3::create_exception!(
    tvmd,
    ConfigError,
    PyValueError,
    include_str!("../docstrings/tvmd.ConfigError.txt")
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

/// A `tvmd.ConfigError` of the binding's own with `message` and `field`.
pub(crate) fn config_error_of(message: String, field: &str) -> PyErr {
    let err = ConfigError::new_err(message);
    Python::attach(|py| {
        let _ = err.value(py).setattr("field", field);
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

/// How the Python layer raises an error of the simulator's crates.
pub(crate) enum ErrorKind<'a> {
    /// An I/O error without a known file.
    Io(&'a std::io::Error),
    /// An I/O error on a named file.
    File(&'a std::io::Error, &'a Path),
    /// Stopped by Ctrl-C / a signal.
    Interrupted,
    /// A log could not be written or read back.
    Log,
    /// A bad argument, scenario or team.
    Value,
    /// Anything else.
    Runtime,
}

/// The simulator crates' errors, each classified once for the Python mapping.
pub(crate) trait SimErrorKind: std::fmt::Display {
    /// How this error is raised.
    fn kind(&self) -> ErrorKind<'_>;
}

impl SimErrorKind for PhysicsError {
    fn kind(&self) -> ErrorKind<'_> {
        match self {
            PhysicsError::InvalidTeam(_)
            | PhysicsError::InvalidScenario { .. }
            | PhysicsError::InvalidCommand { .. } => ErrorKind::Value,
            _ => ErrorKind::Runtime,
        }
    }
}

impl SimErrorKind for LogError {
    fn kind(&self) -> ErrorKind<'_> {
        match self {
            LogError::Io(io) => ErrorKind::Io(io),
            LogError::File { source, path, .. } => ErrorKind::File(source, path),
            LogError::Mcap(_) | LogError::LogRead(_) | LogError::LogFinished => ErrorKind::Log,
            LogError::PathClash(_) | LogError::InvalidArgument { .. } => ErrorKind::Value,
            LogError::Foxglove(_) => ErrorKind::Runtime,
        }
    }
}

impl SimErrorKind for ScenarioError {
    fn kind(&self) -> ErrorKind<'_> {
        match self {
            ScenarioError::File { source, path, .. } => ErrorKind::File(source, path),
            ScenarioError::Physics(e) => e.kind(),
            _ => ErrorKind::Value,
        }
    }
}

impl SimErrorKind for SimError {
    fn kind(&self) -> ErrorKind<'_> {
        match self {
            SimError::Scenario(e) => e.kind(),
            SimError::Physics(e) => e.kind(),
            SimError::Log(e) => e.kind(),
            SimError::Interrupted => ErrorKind::Interrupted,
            SimError::InvalidArgument { .. } => ErrorKind::Value,
            _ => ErrorKind::Runtime,
        }
    }
}

impl SimErrorKind for StudyError {
    fn kind(&self) -> ErrorKind<'_> {
        match self {
            StudyError::Sim(e) => e.kind(),
            StudyError::Scenario(e) => e.kind(),
            StudyError::Log(e) => e.kind(),
            StudyError::Physics(e) => e.kind(),
            StudyError::Io(io) => ErrorKind::Io(io),
            StudyError::InvalidArgument { .. } => ErrorKind::Value,
            _ => ErrorKind::Runtime,
        }
    }
}

/// The Python exception of a simulator error, the message prefixed with `context`; an I/O
/// error names `file` (an `OSError` of the errno's subclass when the OS gave one).
pub(crate) fn sim_error<E: SimErrorKind>(
    error: E,
    context: &str,
    file: Option<(&str, &Path)>,
) -> PyErr {
    let (message, errno) = match error.kind() {
        ErrorKind::Io(io) => {
            let what = file.map_or("I/O error", |(what, _)| what);
            (format!("{context}{what}: {io}"), io.raw_os_error())
        }
        ErrorKind::File(source, path) => {
            let message = format!("{context}{error}");
            let path = path.display().to_string();
            return match source.raw_os_error() {
                Some(errno) => PyOSError::new_err((errno, message, path)),
                None => PyOSError::new_err(message),
            };
        }
        ErrorKind::Interrupted => return PyKeyboardInterrupt::new_err(format!("{context}{error}")),
        ErrorKind::Log => (format!("{context}{error}"), None),
        ErrorKind::Value => return PyValueError::new_err(format!("{context}{error}")),
        ErrorKind::Runtime => return PyRuntimeError::new_err(format!("{context}{error}")),
    };
    match (errno, file.map(|(_, path)| path.display().to_string())) {
        (Some(errno), Some(path)) => PyOSError::new_err((errno, message, path)),
        (Some(errno), None) => PyOSError::new_err((errno, message)),
        (None, Some(path)) => PyOSError::new_err(format!("{message}: '{path}'")),
        (None, None) => PyOSError::new_err(message),
    }
}

/// A tvmd-sim error without a file.
pub(crate) fn value_error<E: SimErrorKind>(error: E) -> PyErr {
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
