//! The `max_rounds` argument (`Controller(max_rounds=...)`, `tvmd.allocate(max_rounds=...)`):
//! `None` for the core's default cap, an int >= 0 of walk rounds, or `"uncapped"`.

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyString;

use tvmd_core::RoundCap;
use tvmd_scenario::ROUND_CAP_UNCAPPED as UNCAPPED;

use super::Int;

/// The cap of a `max_rounds` argument (`None`: the allocator's default): `ValueError` for a
/// negative int or another word, `TypeError` for any other type.
pub(crate) fn round_cap_arg(obj: Option<&Bound<'_, PyAny>>) -> PyResult<Option<RoundCap>> {
    let Some(obj) = obj.filter(|o| !o.is_none()) else {
        return Ok(None);
    };
    if let Ok(text) = obj.cast::<PyString>() {
        let text = text.to_cow()?;
        return if text == UNCAPPED {
            Ok(Some(RoundCap::Uncapped))
        } else {
            Err(PyValueError::new_err(format!(
                "`max_rounds` must be an int >= 0 or \"{UNCAPPED}\", got \"{text}\""
            )))
        };
    }
    let k: Int = obj.extract()?;
    Ok(Some(RoundCap::Rounds(k.to(
        "max_rounds",
        0,
        u32::MAX.into(),
    )?)))
}
