//! The `law` argument (`Controller(law=...)`, `tvmd.sim.run(law=...)`, a `run_many` item's
//! `"law"`): a name of `tvmd_scenario::LAW_NAMES` or a dict with the keys of a scenario's TOML `[law]` table,
//! read by the scenario's own deserializer ([`LawConfig`]) so that its errors name the same
//! fields, then range-checked ([`LawConfig::validate`]).

use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::intern;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};
use serde_json::{Map, Number, Value};

use tvmd_scenario::{FaultDetectionConfig, FaultResponseConfig, LawConfig, ScenarioError};

/// What a `law` argument may be, for `TypeError`s.
const EXPECTED: &str = "\"paper\", \"offset-free\" or a dict with the keys of the TOML [law] \
                        table (gains, offset_free, attitude_rate)";

/// The law of a `law` argument named `name` (`law`, `runs[0]['law']`): `ValueError` naming the
/// field for an unknown name or key or a value out of range, `TypeError` for a value of the
/// wrong type.
pub(crate) fn law_arg(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<LawConfig> {
    let law = if let Ok(text) = obj.cast::<PyString>() {
        LawConfig::named(text.to_cow()?.trim())
            .map_err(|e| PyValueError::new_err(format!("invalid `{name}`: {e}")))?
    } else if obj.is_instance_of::<PyDict>() {
        from_value(to_json(obj, name)?, name)?
    } else {
        let got = obj.get_type().name()?;
        return Err(PyTypeError::new_err(format!(
            "`{name}` must be {EXPECTED}, got {got}"
        )));
    };
    law.validate().map_err(|e| match e {
        // The field is `law.<path>`: named here as the argument's path.
        ScenarioError::InvalidScenario { field, reason } => {
            let rest = field.strip_prefix("law").unwrap_or(&field);
            PyValueError::new_err(format!("invalid `{name}{rest}`: {reason}"))
        }
        other => PyValueError::new_err(format!("invalid `{name}`: {other}")),
    })?;
    Ok(law)
}

/// The `fault_detection` argument: `"report"` or `"mask"` (the recommended detector with that
/// response), or a dict with the keys of a scenario's `[fault_detection]` table (`model_error`,
/// `threshold`, `persistence`, `response`; a key left out takes the recommended value).
/// `ValueError` names the field; the numbers are range-checked by the core where it is built.
pub(crate) fn fault_detection_arg(
    obj: &Bound<'_, PyAny>,
    name: &str,
) -> PyResult<FaultDetectionConfig> {
    if let Ok(text) = obj.cast::<PyString>() {
        return match text.to_cow()?.trim() {
            "report" => Ok(FaultDetectionConfig::with_response(
                FaultResponseConfig::Report,
            )),
            "mask" => Ok(FaultDetectionConfig::with_response(
                FaultResponseConfig::Mask,
            )),
            other => Err(PyValueError::new_err(format!(
                "invalid `{name}`: `{other}` (expected \"report\", \"mask\" or a dict)"
            ))),
        };
    }
    if obj.is_instance_of::<PyDict>() {
        return serde_path_to_error::deserialize::<_, FaultDetectionConfig>(to_json(obj, name)?)
            .map_err(|e| {
                PyValueError::new_err(format!("invalid `{name}.{}`: {}", e.path(), e.inner()))
            });
    }
    let got = obj.get_type().name()?;
    Err(PyTypeError::new_err(format!(
        "`{name}` must be \"report\", \"mask\" or a dict with the keys of the TOML \
         [fault_detection] table, got {got}"
    )))
}

/// Deserializes the `[law]` table with the path of a bad key in the message.
fn from_value(value: Value, name: &str) -> PyResult<LawConfig> {
    serde_path_to_error::deserialize::<_, LawConfig>(value).map_err(|e| {
        let path = e.path().to_string();
        let field = if path.is_empty() || path == "." {
            name.to_string()
        } else {
            format!("{name}.{path}")
        };
        let inner = e.into_inner().to_string();
        // serde's own wording for a value of the wrong kind (a number for a table, ...).
        if inner.starts_with("invalid type") {
            PyTypeError::new_err(format!("`{field}`: {inner}"))
        } else {
            PyValueError::new_err(format!("invalid `{field}`: {inner}"))
        }
    })
}

/// A Python value as JSON: dicts with string keys, lists, tuples and arrays (anything with
/// `tolist`), strings, booleans, integers and finite floats. `path` names the value in errors.
fn to_json(obj: &Bound<'_, PyAny>, path: &str) -> PyResult<Value> {
    let py = obj.py();
    if let Ok(dict) = obj.cast::<PyDict>() {
        let mut map = Map::new();
        for (key, value) in dict.iter() {
            let Ok(key) = key.extract::<String>() else {
                let got = key.repr()?;
                return Err(PyTypeError::new_err(format!(
                    "`{path}` keys must be strings, got {got}"
                )));
            };
            let value = to_json(&value, &format!("{path}.{key}"))?;
            map.insert(key, value);
        }
        return Ok(Value::Object(map));
    }
    if obj.is_instance_of::<PyString>() {
        return Ok(Value::String(obj.extract()?));
    }
    if obj.is_instance_of::<PyBool>() {
        return Ok(Value::Bool(obj.extract()?));
    }
    if obj.is_instance_of::<PyList>() || obj.is_instance_of::<PyTuple>() {
        let items = obj.try_iter()?.enumerate();
        let items = items.map(|(i, item)| to_json(&item?, &format!("{path}[{i}]")));
        return Ok(Value::Array(items.collect::<PyResult<_>>()?));
    }
    if obj.is_instance_of::<PyInt>() {
        return match obj.extract::<i64>() {
            Ok(v) => Ok(Value::Number(v.into())),
            Err(_) => Err(PyValueError::new_err(format!(
                "invalid `{path}`: {} is out of range",
                obj.repr()?
            ))),
        };
    }
    if obj.is_instance_of::<PyFloat>() {
        let v: f64 = obj.extract()?;
        return Number::from_f64(v).map(Value::Number).ok_or_else(|| {
            PyValueError::new_err(format!("invalid `{path}`: must be finite, got {v}"))
        });
    }
    // A NumPy array or scalar: its Python equivalent.
    if obj.hasattr(intern!(py, "tolist"))? {
        let plain = obj.call_method0(intern!(py, "tolist"))?;
        // Only a change of type recurses (a `tolist` returning its own kind would not end).
        if !plain.get_type().is(obj.get_type()) {
            return to_json(&plain, path);
        }
    }
    let got = obj.get_type().name()?;
    Err(PyTypeError::new_err(format!(
        "`{path}` must be a str, a number, a list or a dict, got {got}"
    )))
}
