//! The one conversion layer at the Python boundary: array-likes in, NumPy arrays out
//! (conventions in the stub `python/tvmd/_tvmd.pyi`), and the parsers of the plain arguments
//! (relaxation, iteration cap, null-space stage, sample retention, scenario) and, in [`law`],
//! of the control law. Nothing here panics: every shape is checked. It imports only
//! [`crate::errors`].

use std::path::PathBuf;

use nalgebra::{Matrix3, SMatrix, SVector, Vector3};
use numpy::ndarray::ArrayD;
use numpy::{Element, PyArray1, PyArrayDyn, PyArrayMethods};
use pyo3::exceptions::{PyRuntimeError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyFloat, PyInt, PyString};
use pyo3::{intern, IntoPyObjectExt};

use tvmd_core::{AgentCommand, Relaxation};
use tvmd_scenario::Scenario;
use tvmd_sim::sim::SampleRetention;
use tvmd_sim::ScenarioSource;

use crate::errors::{sim_error, OrRaise, READ};

mod commands;
mod law;
mod links;
mod reports;
mod round_cap;

pub(crate) use commands::{batch_commands_arg, batch_wrench_arg, commands_arg, wrench_arg};

pub(crate) use law::{fault_detection_arg, law_arg};
pub(crate) use links::link_stats_to_py;
pub(crate) use reports::{reports_arg, set_reports};
pub(crate) use round_cap::round_cap_arg;

/// Agent capacity of the bindings: `TeamConfig<f64, 64>`.
pub(crate) const CAPACITY: usize = 64;

/// `(a, b, c)` as Python prints a shape.
pub(crate) fn shape_str(shape: &[usize]) -> String {
    match shape {
        [one] => format!("({one},)"),
        _ => {
            let parts: Vec<String> = shape.iter().map(ToString::to_string).collect();
            format!("({})", parts.join(", "))
        }
    }
}

/// `ValueError: `name` must have shape EXPECTED, got (..)`.
pub(crate) fn shape_error(name: &str, expected: &str, got: &[usize]) -> PyErr {
    PyValueError::new_err(format!(
        "`{name}` must have shape {expected}, got {}",
        shape_str(got)
    ))
}

/// `numpy.asarray(obj).astype(dtype)` of a real (`kinds` "iuf") or integer ("iu") array-like;
/// other dtypes raise `TypeError`.
fn numeric<T: Element>(
    obj: &Bound<'_, PyAny>,
    name: &str,
    what: &str,
    kinds: &[&str],
) -> PyResult<ArrayD<T>> {
    let py = obj.py();
    let converted = py
        .import(intern!(py, "numpy"))?
        .call_method1(intern!(py, "asarray"), (obj,))
        .map_err(|e| {
            PyValueError::new_err(format!(
                "`{name}` is not a rectangular array of {what}: {e}"
            ))
        })?;
    let dtype = converted.getattr(intern!(py, "dtype"))?;
    let kind: String = dtype.getattr(intern!(py, "kind"))?.extract()?;
    // An empty list converts to float64: it is no evidence of the wrong kind of values.
    let size: usize = converted.getattr(intern!(py, "size"))?.extract()?;
    if size > 0 && !kinds.contains(&kind.as_str()) {
        return Err(PyTypeError::new_err(format!(
            "`{name}` must contain {what}, got an array of dtype {}",
            dtype.str()?
        )));
    }
    let target = T::get_dtype(py);
    let array = converted
        .call_method1(intern!(py, "astype"), (target,))?
        .cast_into::<PyArrayDyn<T>>()
        .map_err(|_| PyTypeError::new_err(format!("`{name}` could not be read as {what}")))?;
    Ok(array.to_owned_array())
}

/// Reads any real array-like as float64 values (integers converted).
pub(crate) fn array(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<ArrayD<f64>> {
    numeric(obj, name, "real numbers", &["i", "u", "f"])
}

/// Reads an integer array-like as `i64` (floats, booleans and the rest raise `TypeError`).
pub(crate) fn int_array(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<ArrayD<i64>> {
    numeric(obj, name, "integers", &["i", "u"])
}

/// `ValueError` unless every value is finite.
pub(crate) fn check_finite<'a>(
    values: impl IntoIterator<Item = &'a f64>,
    name: &str,
) -> PyResult<()> {
    if values.into_iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(PyValueError::new_err(format!(
            "`{name}` contains NaN or infinite values"
        )))
    }
}

/// A float argument that must be finite.
pub(crate) fn finite_scalar(value: f64, name: &str) -> PyResult<f64> {
    check_finite([value].iter(), name)?;
    Ok(value)
}

/// A fixed-size vector `(R,)` or matrix `(R, C)` argument, read as nalgebra's `SMatrix`.
pub(crate) fn arg<const R: usize, const C: usize>(
    obj: &Bound<'_, PyAny>,
    name: &str,
) -> PyResult<SMatrix<f64, R, C>> {
    let a = array(obj, name)?;
    let shape: &[usize] = if C == 1 { &[R] } else { &[R, C] };
    if a.shape() != shape {
        return Err(shape_error(name, &shape_str(shape), a.shape()));
    }
    Ok(SMatrix::from_row_iterator(a.iter().copied()))
}

/// As [`arg`], every value finite.
pub(crate) fn finite<const R: usize, const C: usize>(
    obj: &Bound<'_, PyAny>,
    name: &str,
) -> PyResult<SMatrix<f64, R, C>> {
    let m: SMatrix<f64, R, C> = arg(obj, name)?;
    check_finite(m.iter(), name)?;
    Ok(m)
}

/// An optional [`arg`]: `default` for a missing or `None` argument.
pub(crate) fn opt_arg<const R: usize, const C: usize>(
    obj: Option<&Bound<'_, PyAny>>,
    name: &str,
    default: SMatrix<f64, R, C>,
) -> PyResult<SMatrix<f64, R, C>> {
    match obj.filter(|o| !o.is_none()) {
        Some(o) => arg(o, name),
        None => Ok(default),
    }
}

/// A `(3, 3)` matrix, or its `(3,)` diagonal.
pub(crate) fn matrix3_or_diagonal(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<Matrix3<f64>> {
    let a = array(obj, name)?;
    let values = a.iter().copied();
    match a.shape() {
        [3] => Ok(Matrix3::from_diagonal(&Vector3::from_iterator(values))),
        [3, 3] => Ok(Matrix3::from_row_iterator(values)),
        other => Err(shape_error(name, "(3,) (diagonal) or (3, 3)", other)),
    }
}

/// A `(K,)` or `(..., K)` batch of finite `K`-vectors, and the leading shape.
pub(crate) fn vectors<const K: usize>(
    obj: &Bound<'_, PyAny>,
    name: &str,
) -> PyResult<(Vec<SVector<f64, K>>, Vec<usize>)> {
    let a = array(obj, name)?;
    let Some((_, leading)) = a.shape().split_last().filter(|(k, _)| **k == K) else {
        return Err(shape_error(name, &format!("({K},) or (N, {K})"), a.shape()));
    };
    check_finite(a.iter(), name)?;
    let values: Vec<f64> = a.iter().copied().collect();
    let rows = values.chunks_exact(K).map(SVector::from_column_slice);
    Ok((rows.collect(), leading.to_vec()))
}

/// `(n, K)` values as `n` vectors; `n` must equal `expected` if given.
pub(crate) fn table<const K: usize>(
    obj: &Bound<'_, PyAny>,
    name: &str,
    expected: Option<usize>,
) -> PyResult<Vec<SVector<f64, K>>> {
    let a = array(obj, name)?;
    match a.shape() {
        [n, k] if *k == K && expected.is_none_or(|e| e == *n) => {
            let values: Vec<f64> = a.iter().copied().collect();
            Ok(values
                .chunks_exact(K)
                .map(SVector::from_column_slice)
                .collect())
        }
        other => {
            let rows = expected.map_or("n".into(), |n| n.to_string());
            Err(shape_error(name, &format!("({rows}, {K})"), other))
        }
    }
}

/// A float or array of floats of any shape, finite: the values (row-major) and the shape.
pub(crate) fn scalars(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<(Vec<f64>, Vec<usize>)> {
    let a = array(obj, name)?;
    check_finite(a.iter(), name)?;
    Ok((a.iter().copied().collect(), a.shape().to_vec()))
}

/// Failure indices: `None` or an iterable of agent indices (ints, not booleans).
pub(crate) fn indices(obj: Option<&Bound<'_, PyAny>>, name: &str) -> PyResult<Vec<Int>> {
    let Some(obj) = obj.filter(|o| !o.is_none()) else {
        return Ok(Vec::new());
    };
    let iter = obj.try_iter().map_err(|_| {
        PyTypeError::new_err(format!(
            "`{name}` must be None or an iterable of agent indices (ints)"
        ))
    })?;
    iter.map(|item| {
        let item = item?;
        let not_int = item.is_instance_of::<PyBool>() || item.is_instance_of::<PyFloat>();
        match item.extract::<Int>() {
            Ok(index) if !not_int => Ok(index),
            _ => Err(PyTypeError::new_err(format!(
                "`{name}` must list agent indices (ints), got {}",
                item.repr()?
            ))),
        }
    })
    .collect()
}

/// A `tvmd` object argument of class `T`, else `TypeError` naming the argument.
pub(crate) fn class_arg<'a, 'py, T: pyo3::PyClass>(
    obj: &'a Bound<'py, PyAny>,
    name: &str,
) -> PyResult<&'a Bound<'py, T>> {
    obj.cast::<T>().map_err(|_| {
        let got = obj.get_type().name().map_or("?".into(), |n| n.to_string());
        PyTypeError::new_err(format!("`{name}` must be a tvmd.{}, got {got}", T::NAME))
    })
}

/// The largest `usize`, as the bound of a count argument.
pub(crate) const USIZE_MAX: i128 = usize::MAX as i128;

/// A Python integer argument of any size: an `int` or anything with `__index__` (a NumPy
/// integer, a bool), read without overflow; floats, strings and the rest raise `TypeError`.
/// [`Int::to`] converts it, the one range check of every integer argument.
#[derive(Clone, Debug)]
pub(crate) struct Int {
    /// The value, saturated to the `i128` range.
    value: i128,
    /// The value as Python prints it when it is beyond `i128` (`value` saturated).
    big: Option<String>,
}

impl Int {
    /// An argument's default.
    pub(crate) const fn of(value: i64) -> Self {
        Self {
            value: value as i128,
            big: None,
        }
    }

    /// The value as `T`, if it is one.
    pub(crate) fn get<T: TryFrom<i128>>(&self) -> Option<T> {
        self.big
            .is_none()
            .then(|| T::try_from(self.value).ok())
            .flatten()
    }

    /// The value as `T` if it lies in `[min, max]` (a range within `T`'s), else a `ValueError`
    /// naming the argument `name` and the range.
    pub(crate) fn to<T: TryFrom<i128>>(&self, name: &str, min: i128, max: i128) -> PyResult<T> {
        self.get::<i128>()
            .filter(|v| (min..=max).contains(v))
            .and_then(|v| T::try_from(v).ok())
            .ok_or_else(|| {
                PyValueError::new_err(format!(
                    "`{name}` must be >= {} and <= {}, got {self}",
                    bound(min),
                    bound(max)
                ))
            })
    }
}

impl std::fmt::Display for Int {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match &self.big {
            Some(text) => f.write_str(text),
            None => write!(f, "{}", self.value),
        }
    }
}

/// A range bound as Python would write it: `2**64 - 1` rather than its digits.
fn bound(x: i128) -> String {
    let (sign, magnitude) = (if x < 0 { "-" } else { "" }, x.unsigned_abs());
    if magnitude >= 1 << 20 {
        if magnitude.is_power_of_two() {
            return format!("{sign}2**{}", magnitude.trailing_zeros());
        }
        if (magnitude + 1).is_power_of_two() && sign.is_empty() {
            return format!("2**{} - 1", (magnitude + 1).trailing_zeros());
        }
    }
    x.to_string()
}

impl<'a, 'py> FromPyObject<'a, 'py> for Int {
    type Error = PyErr;

    fn extract(obj: Borrowed<'a, 'py, PyAny>) -> PyResult<Self> {
        let py = obj.py();
        let int = match obj.cast::<PyInt>() {
            Ok(int) => int.to_owned().into_any(),
            Err(_) => py
                .import(intern!(py, "operator"))?
                .call_method1(intern!(py, "index"), (obj,))?,
        };
        match int.extract::<i128>() {
            Ok(value) => Ok(Self { value, big: None }),
            Err(_) => {
                let negative = int.lt(0)?;
                Ok(Self {
                    value: if negative { i128::MIN } else { i128::MAX },
                    big: Some(int.str()?.to_string()),
                })
            }
        }
    }
}

/// A non-negative count argument.
pub(crate) fn count(value: &Int, name: &str) -> PyResult<usize> {
    value.to(name, 0, USIZE_MAX)
}

/// An array of `shape` from row-major values.
pub(crate) fn shaped<'py, T: Element>(
    py: Python<'py>,
    values: Vec<T>,
    shape: &[usize],
) -> PyResult<Bound<'py, PyAny>> {
    Ok(PyArray1::from_vec(py, values).reshape(shape)?.into_any())
}

/// A `(R, C)` float64 array (`(R,)` for a vector).
pub(crate) fn matrix<'py, const R: usize, const C: usize>(
    py: Python<'py>,
    m: &SMatrix<f64, R, C>,
) -> PyResult<Bound<'py, PyAny>> {
    let shape: &[usize] = if C == 1 { &[R] } else { &[R, C] };
    shaped(py, m.transpose().as_slice().to_vec(), shape)
}

/// A Python scalar for a scalar input (empty `shape`), else an array of `shape`.
pub(crate) fn scalar_or_array<'py, T>(
    py: Python<'py>,
    values: Vec<T>,
    shape: &[usize],
) -> PyResult<Bound<'py, PyAny>>
where
    T: Element + Copy + IntoPyObject<'py>,
{
    match (shape, values.first()) {
        ([], Some(x)) => (*x).into_bound_py_any(py),
        _ => shaped(py, values, shape),
    }
}

/// Commands of the first `n` agents as `(n, 4)`: columns `eta_x, eta_y, thrust, omega`.
pub(crate) fn commands_array<'py>(
    py: Python<'py>,
    commands: &[AgentCommand<f64>],
    n: usize,
) -> PyResult<Bound<'py, PyAny>> {
    let values = commands.iter().take(n);
    let values = values.flat_map(|c| [c.eta_x, c.eta_y, c.thrust, c.omega]);
    shaped(py, values.collect(), &[n.min(commands.len()), 4])
}

/// A tvmd-sim record (serde) as Python objects: `json.loads` of its JSON (NaN becomes None).
pub(crate) fn record_to_py<'py, T: serde::Serialize>(
    py: Python<'py>,
    record: &T,
) -> PyResult<Bound<'py, PyAny>> {
    let text = serde_json::to_string(record)
        .map_err(|e| PyRuntimeError::new_err(format!("cannot convert a tvmd-sim record: {e}")))?;
    py.import(intern!(py, "json"))?
        .call_method1(intern!(py, "loads"), (text,))
}

/// The iteration cap argument `name`: default 64 (the core's), else in `[1, 2**32 - 1]`; 0 is
/// left to the core, whose `ConfigError` names its field.
pub(crate) fn iteration_cap(value: Option<&Int>, name: &str) -> PyResult<u32> {
    match value {
        None => Ok(64),
        Some(v) if v.get::<u32>() == Some(0) => Ok(0),
        Some(v) => v.to(name, 1, u32::MAX.into()),
    }
}

/// The relaxation `s` from the keyword `relaxation` or its alias `s` (not both), else `default`.
pub(crate) fn relaxation_arg(
    relaxation: Option<f64>,
    s: Option<f64>,
    default: Option<f64>,
) -> PyResult<Relaxation<f64>> {
    let value = match (relaxation, s) {
        (Some(_), Some(_)) => {
            return Err(PyTypeError::new_err(
                "give `relaxation` or its alias `s`, not both",
            ))
        }
        (Some(v), None) | (None, Some(v)) => v,
        (None, None) => {
            default.ok_or_else(|| PyTypeError::new_err("missing required argument `relaxation`"))?
        }
    };
    Relaxation::new(value).or_raise()
}

/// A `max_samples` argument (named `name`): `None` keeps every tick, `n >= 0` at most `n`
/// evenly spaced.
pub(crate) fn retention_arg(max_samples: Option<&Int>, name: &str) -> PyResult<SampleRetention> {
    match max_samples {
        None => Ok(SampleRetention::All),
        Some(n) => count(n, name).map(SampleRetention::AtMost),
    }
}

/// A `jobs` argument: `None` (every core) or a worker count >= 1.
pub(crate) fn jobs_arg(jobs: Option<&Int>) -> PyResult<Option<usize>> {
    jobs.map(|j| j.to("jobs", 1, USIZE_MAX)).transpose()
}

/// The scenario source of a `scenario` argument ([`ScenarioSource`]): a `str` by the CLI's
/// name-or-file rule (`Scenario::load`), an `os.PathLike` a file.
pub(crate) fn scenario_source(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<ScenarioSource> {
    if let Ok(s) = obj.cast::<PyString>() {
        return Ok(ScenarioSource::NameOrFile(s.to_cow()?.into_owned()));
    }
    if obj.hasattr("__fspath__")? {
        let path: PathBuf = obj.extract().map_err(|e| {
            PyTypeError::new_err(format!("`{name}` is not a usable file path: {e}"))
        })?;
        return Ok(ScenarioSource::File(path));
    }
    let got = obj.get_type().name()?;
    Err(PyTypeError::new_err(format!(
        "`{name}` must be a built-in scenario name or a path to a TOML file (str or \
         os.PathLike), got {got}"
    )))
}

/// The scenario of a `scenario` argument ([`scenario_source`], loaded); errors name the file.
pub(crate) fn scenario_arg(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<Scenario> {
    let source = scenario_source(obj, name)?;
    source.load().map_err(|e| {
        let file = source.file().map(|p| (READ, p));
        sim_error(e, "", file)
    })
}
