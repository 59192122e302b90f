//! Conversions at the Python boundary: array-likes in, float64 NumPy arrays out.
//!
//! Inputs may be NumPy arrays of any real dtype, nested lists/tuples or Python numbers; they
//! are read as float64 (integers are converted; booleans, complex numbers, strings and objects
//! raise `TypeError`). Shapes are checked here and a wrong one raises `ValueError` naming the
//! argument and the expected shape. Nothing here panics: every access is checked.

use nalgebra::{Matrix3, Vector3};
use numpy::ndarray::{Array1, Array2, ArrayD, IxDyn};
use numpy::{PyArray1, PyArray2, PyArrayDyn, PyArrayMethods, PyReadonlyArrayDyn};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyFloat};
use pyo3::{intern, IntoPyObjectExt};

use tvmd_core::AgentCommand;

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

/// Reads any real array-like as a float64 NumPy array (no copy for a float64 array).
pub(crate) fn float_array<'py>(
    obj: &Bound<'py, PyAny>,
    name: &str,
) -> PyResult<PyReadonlyArrayDyn<'py, f64>> {
    let array = match obj.cast::<PyArrayDyn<f64>>() {
        Ok(array) => array.clone(),
        Err(_) => {
            let converted = as_numeric_array(obj, name, "real numbers", &["i", "u", "f"])?;
            let py = obj.py();
            let floats =
                converted.call_method1(intern!(py, "astype"), (intern!(py, "float64"),))?;
            floats.cast_into::<PyArrayDyn<f64>>().map_err(|_| {
                PyTypeError::new_err(format!("`{name}` could not be read as a float64 array"))
            })?
        }
    };
    array
        .try_readonly()
        .map_err(|e| PyValueError::new_err(format!("`{name}` cannot be read: {e}")))
}

/// Reads an integer array-like (any shape) as `i64`. Floats, booleans and the rest raise
/// `TypeError`.
pub(crate) fn int_array(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<(Vec<i64>, Vec<usize>)> {
    let py = obj.py();
    let converted = as_numeric_array(obj, name, "integers", &["i", "u"])?;
    let ints = converted
        .call_method1(intern!(py, "astype"), (intern!(py, "int64"),))?
        .cast_into::<PyArrayDyn<i64>>()
        .map_err(|_| PyTypeError::new_err(format!("`{name}` could not be read as integers")))?;
    let view = ints
        .try_readonly()
        .map_err(|e| PyValueError::new_err(format!("`{name}` cannot be read: {e}")))?;
    let array = view.as_array();
    Ok((array.iter().copied().collect(), array.shape().to_vec()))
}

/// `numpy.asarray(obj)` with its dtype kind checked against `kinds`.
fn as_numeric_array<'py>(
    obj: &Bound<'py, PyAny>,
    name: &str,
    what: &str,
    kinds: &[&str],
) -> PyResult<Bound<'py, PyAny>> {
    let py = obj.py();
    let numpy = py.import(intern!(py, "numpy"))?;
    let converted = numpy
        .call_method1(intern!(py, "asarray"), (obj,))
        .map_err(|e| {
            PyValueError::new_err(format!(
                "`{name}` is not a rectangular array of {what}: {e}"
            ))
        })?;
    let dtype = converted.getattr(intern!(py, "dtype"))?;
    let kind: String = dtype.getattr(intern!(py, "kind"))?.extract()?;
    if kinds.contains(&kind.as_str()) {
        Ok(converted)
    } else {
        Err(PyTypeError::new_err(format!(
            "`{name}` must contain {what}, got an array of dtype {}",
            dtype.str()?
        )))
    }
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

/// Exactly `K` values in row-major order from an array of shape `shape`.
pub(crate) fn fixed<const K: usize>(
    obj: &Bound<'_, PyAny>,
    name: &str,
    shape: &[usize],
) -> PyResult<[f64; K]> {
    let view = float_array(obj, name)?;
    let array = view.as_array();
    if array.shape() != shape || array.len() != K {
        return Err(shape_error(name, &shape_str(shape), array.shape()));
    }
    let mut out = [0.0; K];
    for (o, x) in out.iter_mut().zip(array.iter()) {
        *o = *x;
    }
    Ok(out)
}

/// A `(3,)` vector (not checked for finiteness).
pub(crate) fn vector3(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<Vector3<f64>> {
    fixed::<3>(obj, name, &[3]).map(Vector3::from)
}

/// A `(3,)` vector of finite values.
pub(crate) fn finite_vector3(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<Vector3<f64>> {
    let v = vector3(obj, name)?;
    check_finite(v.iter(), name)?;
    Ok(v)
}

/// A `(6,)` vector.
pub(crate) fn vector6(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<[f64; 6]> {
    fixed::<6>(obj, name, &[6])
}

/// A `(3, 3)` matrix (not checked for finiteness).
pub(crate) fn matrix3(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<Matrix3<f64>> {
    fixed::<9>(obj, name, &[3, 3]).map(|m| matrix_from_row_major(&m))
}

/// A matrix from 9 row-major values (NaN-filled if `values` has another length).
pub(crate) fn matrix_from_row_major(values: &[f64]) -> Matrix3<f64> {
    match values {
        [a, b, c, d, e, f, g, h, i] => Matrix3::new(*a, *b, *c, *d, *e, *f, *g, *h, *i),
        _ => Matrix3::from_element(f64::NAN),
    }
}

/// A `(3, 3)` matrix of finite values.
pub(crate) fn finite_matrix3(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<Matrix3<f64>> {
    let m = matrix3(obj, name)?;
    check_finite(m.iter(), name)?;
    Ok(m)
}

/// A `(3, 3)` matrix, or a `(3,)` diagonal.
pub(crate) fn matrix3_or_diagonal(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<Matrix3<f64>> {
    let view = float_array(obj, name)?;
    let array = view.as_array();
    match array.shape() {
        [3] => {
            let mut d = [0.0; 3];
            for (o, x) in d.iter_mut().zip(array.iter()) {
                *o = *x;
            }
            Ok(Matrix3::from_diagonal(&Vector3::from(d)))
        }
        [3, 3] => matrix3(obj, name),
        other => Err(shape_error(name, "(3,) (diagonal) or (3, 3)", other)),
    }
}

/// `(rows, K)` values, one `[f64; K]` per row; `rows` must equal `expected_rows` if given.
pub(crate) fn rows<const K: usize>(
    obj: &Bound<'_, PyAny>,
    name: &str,
    expected_rows: Option<usize>,
) -> PyResult<Vec<[f64; K]>> {
    let view = float_array(obj, name)?;
    let array = view.as_array();
    let expected = || match expected_rows {
        Some(n) => shape_str(&[n, K]),
        None => format!("(n, {K})"),
    };
    let shape = array.shape();
    let n = match shape {
        [n, k] if *k == K && expected_rows.is_none_or(|e| e == *n) => *n,
        _ => return Err(shape_error(name, &expected(), shape)),
    };
    let mut out = vec![[0.0; K]; n];
    for (slot, x) in out.iter_mut().flat_map(|r| r.iter_mut()).zip(array.iter()) {
        *slot = *x;
    }
    Ok(out)
}

/// A batch of 3-vectors of shape `(3,)` or `(..., 3)`.
pub(crate) struct Vectors {
    /// The vectors in row-major order.
    pub(crate) vectors: Vec<Vector3<f64>>,
    /// Shape without the trailing 3 (empty for one `(3,)` vector).
    pub(crate) leading: Vec<usize>,
}

/// Reads a `(3,)` or `(..., 3)` batch of finite 3-vectors.
pub(crate) fn vectors3(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<Vectors> {
    let view = float_array(obj, name)?;
    let array = view.as_array();
    let shape = array.shape();
    let Some((&3, leading)) = shape.split_last() else {
        return Err(shape_error(name, "(3,) or (N, 3)", shape));
    };
    check_finite(array.iter(), name)?;
    let values: Vec<f64> = array.iter().copied().collect();
    let vectors = values
        .chunks_exact(3)
        .map(|c| match c {
            [x, y, z] => Vector3::new(*x, *y, *z),
            _ => Vector3::zeros(),
        })
        .collect();
    Ok(Vectors {
        vectors,
        leading: leading.to_vec(),
    })
}

/// A float or array of floats of any shape, finite. Returns the values (row-major) and the
/// shape (empty for a scalar).
pub(crate) fn scalars(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<(Vec<f64>, Vec<usize>)> {
    let view = float_array(obj, name)?;
    let array = view.as_array();
    check_finite(array.iter(), name)?;
    Ok((array.iter().copied().collect(), array.shape().to_vec()))
}

/// Failure indices: `None` or an iterable of agent indices (ints, not booleans).
pub(crate) fn indices(obj: Option<&Bound<'_, PyAny>>, name: &str) -> PyResult<Vec<i64>> {
    let Some(obj) = obj else {
        return Ok(Vec::new());
    };
    if obj.is_none() {
        return Ok(Vec::new());
    }
    let mut out = Vec::new();
    let iter = obj.try_iter().map_err(|_| {
        PyTypeError::new_err(format!(
            "`{name}` must be None or an iterable of agent indices (ints)"
        ))
    })?;
    for item in iter {
        let item = item?;
        if item.is_instance_of::<PyBool>() || item.is_instance_of::<PyFloat>() {
            return Err(PyTypeError::new_err(format!(
                "`{name}` must list agent indices (ints), got {}",
                item.repr()?
            )));
        }
        let index: i64 = item.extract().map_err(|_| {
            PyTypeError::new_err(format!(
                "`{name}` must list agent indices (ints), got {}",
                item.repr()
                    .map(|r| r.to_string())
                    .unwrap_or_else(|_| "?".into())
            ))
        })?;
        out.push(index);
    }
    Ok(out)
}

/// A `tvmd` object argument of class `T`, else `TypeError` naming the argument.
pub(crate) fn class_arg<'a, 'py, T: pyo3::PyClass>(
    obj: &'a Bound<'py, PyAny>,
    name: &str,
) -> PyResult<&'a Bound<'py, T>> {
    obj.cast::<T>().map_err(|_| {
        let got = obj
            .get_type()
            .name()
            .map(|n| n.to_string())
            .unwrap_or_else(|_| "?".into());
        PyTypeError::new_err(format!("`{name}` must be a tvmd.{}, got {got}", T::NAME))
    })
}

/// A non-negative count argument.
pub(crate) fn count(value: i64, name: &str) -> PyResult<usize> {
    usize::try_from(value)
        .map_err(|_| PyValueError::new_err(format!("`{name}` must be >= 0, got {value}")))
}

// ---------------------------------------------------------------------------------------------
// Outputs
// ---------------------------------------------------------------------------------------------

/// A float64 1-D array.
pub(crate) fn array1<'py>(py: Python<'py>, values: &[f64]) -> Bound<'py, PyArray1<f64>> {
    PyArray1::from_slice(py, values)
}

/// A `(3, 3)` float64 array (row-major copy of a column-major nalgebra matrix).
pub(crate) fn matrix_array<'py>(py: Python<'py>, m: &Matrix3<f64>) -> Bound<'py, PyArray2<f64>> {
    let a = Array2::from_shape_fn((3, 3), |(i, j)| m.get((i, j)).copied().unwrap_or(f64::NAN));
    PyArray2::from_owned_array(py, a)
}

/// A `(rows.len(), K)` float64 array.
pub(crate) fn rows_array<'py, const K: usize>(
    py: Python<'py>,
    rows: &[[f64; K]],
) -> Bound<'py, PyArray2<f64>> {
    let a = Array2::from_shape_fn((rows.len(), K), |(i, j)| {
        rows.get(i)
            .and_then(|r| r.get(j))
            .copied()
            .unwrap_or(f64::NAN)
    });
    PyArray2::from_owned_array(py, a)
}

/// A `(rows, cols)` float64 array from row-major values.
pub(crate) fn dense_array<'py>(
    py: Python<'py>,
    rows: usize,
    cols: usize,
    values: &[f64],
) -> Bound<'py, PyArray2<f64>> {
    let a = Array2::from_shape_fn((rows, cols), |(i, j)| {
        values.get(i * cols + j).copied().unwrap_or(f64::NAN)
    });
    PyArray2::from_owned_array(py, a)
}

/// A boolean 1-D array.
pub(crate) fn bool_array<'py>(py: Python<'py>, values: &[bool]) -> Bound<'py, PyArray1<bool>> {
    PyArray1::from_owned_array(py, Array1::from(values.to_vec()))
}

/// An array of the given shape from row-major values (`values.len()` must match).
pub(crate) fn shaped<'py>(
    py: Python<'py>,
    shape: &[usize],
    values: Vec<f64>,
) -> PyResult<Bound<'py, PyAny>> {
    let a = ArrayD::from_shape_vec(IxDyn(shape), values)
        .map_err(|e| PyValueError::new_err(format!("internal shape error: {e}")))?;
    Ok(PyArrayDyn::from_owned_array(py, a).into_any())
}

/// A float for a scalar input, else an array of `shape`.
pub(crate) fn scalar_or_array<'py>(
    py: Python<'py>,
    shape: &[usize],
    values: Vec<f64>,
) -> PyResult<Bound<'py, PyAny>> {
    match (shape.is_empty(), values.first()) {
        (true, Some(x)) => Ok(PyFloat::new(py, *x).into_any()),
        _ => shaped(py, shape, values),
    }
}

/// A bool for a scalar input, else a boolean array of `shape`.
pub(crate) fn bool_or_array<'py>(
    py: Python<'py>,
    shape: &[usize],
    values: Vec<bool>,
) -> PyResult<Bound<'py, PyAny>> {
    match (shape.is_empty(), values.first()) {
        (true, Some(x)) => x.into_bound_py_any(py),
        _ => {
            let a = ArrayD::from_shape_vec(IxDyn(shape), values)
                .map_err(|e| PyValueError::new_err(format!("internal shape error: {e}")))?;
            Ok(PyArrayDyn::from_owned_array(py, a).into_any())
        }
    }
}

/// Commands of the first `n` agents as `(n, 4)`: columns `eta_x, eta_y, thrust, omega`.
pub(crate) fn commands_array<'py>(
    py: Python<'py>,
    commands: &[AgentCommand<f64>],
    n: usize,
) -> Bound<'py, PyArray2<f64>> {
    let rows: Vec<[f64; 4]> = commands
        .iter()
        .take(n)
        .map(|c| [c.eta_x, c.eta_y, c.thrust, c.omega])
        .collect();
    rows_array(py, &rows)
}
