//! [`record!`]: a read-only Python record declared once.
//!
//! One list of fields gives the frozen `#[pyclass]` (holding the Rust value), one getter per
//! field (converted on access, so every array is a fresh copy), the `FIELDS` tuple, `to_dict()`
//! (nested records become nested dicts), a dataclass-like `__repr__`, and `copy.copy` /
//! `copy.deepcopy` (the record itself: records are frozen).

use pyo3::prelude::*;
use pyo3::types::PyDict;

/// Declares a record class: `"Name" in "module" => PyName(Inner) [repr path] |py, o| { field
/// [as "py_name"] => expression, ... } [methods { ... }]`, where `o` is `&inner` and each
/// expression returns anything convertible into a Python object (`?` allowed).
macro_rules! record {
    (@name $field:ident) => { stringify!($field) };
    (@name $field:ident $py_name:literal) => { $py_name };
    (@repr $name:literal $this:ident $py:ident) => {
        $crate::record::repr($name, &$this.record_fields($py)?)
    };
    (@repr $name:literal $this:ident $py:ident $custom:path) => { Ok($custom(&$this.inner)) };
    (
        $(#[doc = $doc:expr])*
        $name:literal in $module:literal => $rust:ident($inner:ty) $(repr $custom:path)?
        |$py:ident, $o:ident| {
            $( $(#[doc = $fdoc:literal])* $field:ident $(as $py_name:literal)? => $value:expr ),* $(,)?
        }
        $(methods { $($extra:tt)* })?
    ) => {
        $(#[doc = $doc])*
        #[pyo3::pyclass(module = $module, name = $name, frozen)]
        pub struct $rust {
            pub(crate) inner: $inner,
        }

        impl $rust {
            /// The Python field names, in declaration order.
            pub(crate) const FIELD_NAMES: &'static [&'static str] =
                &[$( record!(@name $field $($py_name)?) ),*];

            /// `(name, value)` of every field.
            fn record_fields<'py>(
                &self,
                py: pyo3::Python<'py>,
            ) -> pyo3::PyResult<Vec<(&'static str, pyo3::Bound<'py, pyo3::PyAny>)>> {
                Ok(vec![$( (record!(@name $field $($py_name)?), self.$field(py)?) ),*])
            }
        }

        #[pyo3::pymethods]
        impl $rust {
            $(
                $(#[doc = $fdoc])*
                #[getter]
                $(#[pyo3(name = $py_name)])?
                fn $field<'py>(
                    &self,
                    $py: pyo3::Python<'py>,
                ) -> pyo3::PyResult<pyo3::Bound<'py, pyo3::PyAny>> {
                    let $o = &self.inner;
                    pyo3::IntoPyObjectExt::into_bound_py_any($value, $py)
                }
            )*

            /// The field names, in `to_dict` order.
            #[classattr]
            #[pyo3(name = "FIELDS")]
            fn record_field_names(
                py: pyo3::Python<'_>,
            ) -> pyo3::PyResult<pyo3::Bound<'_, pyo3::types::PyTuple>> {
                pyo3::types::PyTuple::new(py, Self::FIELD_NAMES)
            }

            /// The fields as a dict (nested records as dicts).
            fn to_dict<'py>(
                &self,
                py: pyo3::Python<'py>,
            ) -> pyo3::PyResult<pyo3::Bound<'py, pyo3::types::PyDict>> {
                $crate::record::to_dict(py, self.record_fields(py)?)
            }

            /// The record itself: it is immutable (`copy.copy`).
            fn __copy__<'py>(slf: &pyo3::Bound<'py, Self>) -> pyo3::Bound<'py, Self> {
                slf.clone()
            }

            /// The record itself: it is immutable, so a deep copy may share it
            /// (`copy.deepcopy`, as for a tuple of numbers).
            fn __deepcopy__<'py>(
                slf: &pyo3::Bound<'py, Self>,
                _memo: &pyo3::Bound<'py, pyo3::PyAny>,
            ) -> pyo3::Bound<'py, Self> {
                slf.clone()
            }

            fn __repr__(&self, py: pyo3::Python<'_>) -> pyo3::PyResult<String> {
                let _ = py;
                record!(@repr $name self py $($custom)?)
            }

            $($($extra)*)?
        }
    };
}

pub(crate) use record;

/// A dict of named values; values with a `to_dict` method (records) are converted too.
pub(crate) fn to_dict<'py>(
    py: Python<'py>,
    fields: Vec<(&'static str, Bound<'py, PyAny>)>,
) -> PyResult<Bound<'py, PyDict>> {
    let dict = PyDict::new(py);
    for (key, value) in fields {
        if value.hasattr(pyo3::intern!(py, "FIELDS"))? {
            dict.set_item(key, value.call_method0(pyo3::intern!(py, "to_dict"))?)?;
        } else {
            dict.set_item(key, value)?;
        }
    }
    Ok(dict)
}

/// `Name(field=repr, ...)`.
pub(crate) fn repr(name: &str, fields: &[(&'static str, Bound<'_, PyAny>)]) -> PyResult<String> {
    let mut parts = Vec::with_capacity(fields.len());
    for (key, value) in fields {
        parts.push(format!("{key}={}", value.repr()?));
    }
    Ok(format!("{name}({})", parts.join(", ")))
}
