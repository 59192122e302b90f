//! The agents' reports argument (`Controller.set_reports`): an `(n, 4)` array-like of rows
//! `(thrust, eta_x, eta_y, age)`, as `tvmd.sim`'s `Observation.reports` gives them; a row all
//! NaN is an agent with no report.

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use tvmd_core::{AgentReading, Allocator, Controller, ReportError};

use super::table;

/// Per agent its reading (`None` for a row all NaN): `ValueError` for another shape than
/// `(n, 4)`, or a row with a NaN or infinite value among finite ones, a negative thrust or
/// age (the message names the row).
pub(crate) fn reports_arg(
    obj: &Bound<'_, PyAny>,
    n: usize,
) -> PyResult<Vec<Option<AgentReading<f64>>>> {
    table::<4>(obj, "reports", Some(n))?
        .iter()
        .enumerate()
        .map(|(i, row)| {
            if row.iter().all(|x| x.is_nan()) {
                return Ok(None);
            }
            AgentReading::new(row[0], row[1], row[2], row[3])
                .map(Some)
                .map_err(|e| report_error(i, &e))
        })
        .collect()
}

/// Gives `controller` each agent's reading (`ValueError` without fault detection).
pub(crate) fn set_reports<const N: usize, A: Allocator<f64, N>>(
    controller: &mut Controller<f64, N, A>,
    readings: &[Option<AgentReading<f64>>],
) -> PyResult<()> {
    for (i, r) in readings.iter().enumerate() {
        if let Some(r) = r {
            controller
                .set_report(i, *r)
                .map_err(|e| report_error(i, &e))?;
        }
    }
    Ok(())
}

fn report_error(row: usize, e: &ReportError) -> PyErr {
    match e {
        ReportError::DetectionOff => PyValueError::new_err(
            "`reports`: the controller has no fault detection (`fault_detection=...`) to read them",
        ),
        e => PyValueError::new_err(format!("`reports` row {row}: {e}")),
    }
}
