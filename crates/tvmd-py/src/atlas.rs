//! `tvmd.afs_atlas`: the AFS atlas of `tvmd_studies::afs_atlas` (a thin adapter: arguments in, the
//! row as a dict out).

use std::path::PathBuf;

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use tvmd_core::Preset;
use tvmd_studies::afs_atlas::{run_until, AtlasRequest};

use crate::convert::{count, indices, record_to_py, Int};
use crate::errors::value_error;
use crate::interrupt::{interruptible, Ended};

/// Directions per cross-section: tvmd-sim's bounds (`afs_atlas::report::atlas_entry`).
const DIRECTIONS: (i128, i128) = (4, 3600);
/// Heights of the certification grid: tvmd-sim's bounds (`HeightRange::heights`).
const CERTIFY_HEIGHTS: (i128, i128) = (2, 200);

#[doc = include_str!("../docstrings/tvmd.afs_atlas.txt")]
#[pyfunction]
#[pyo3(
    signature = (team, *, failed = None, heights = None, directions = Int::of(36), relaxation = 1.0, certify_heights = Int::of(9), torque = None, plots = None),
    text_signature = "(team, *, failed=None, heights=None, directions=36, relaxation=1.0, certify_heights=9, torque=None, plots=None)"
)]
#[allow(clippy::too_many_arguments)]
fn afs_atlas<'py>(
    py: Python<'py>,
    team: &str,
    failed: Option<&Bound<'py, PyAny>>,
    heights: Option<Vec<f64>>,
    directions: Int,
    relaxation: f64,
    certify_heights: Int,
    torque: Option<[f64; 3]>,
    plots: Option<PathBuf>,
) -> PyResult<Bound<'py, PyAny>> {
    if team == "all" {
        return Err(PyValueError::new_err(
            "afs_atlas takes one team; loop over tvmd.Team.preset_names() for the catalogue",
        ));
    }
    // The names this function takes (the CLI's list adds `all`, which it refuses).
    let known: Vec<&str> = Preset::ALL.iter().map(|p| p.name()).collect();
    if !known.contains(&team) {
        return Err(PyValueError::new_err(format!(
            "unknown team `{team}` (known: {})",
            known.join(", ")
        )));
    }
    let failed = indices(failed, "failed")?
        .iter()
        .map(|i| count(i, "failed"))
        .collect::<PyResult<Vec<usize>>>()?;
    let (lo, hi) = DIRECTIONS;
    let directions = directions.to("directions", lo, hi)?;
    let (lo, hi) = CERTIFY_HEIGHTS;
    let certify_heights = certify_heights.to("certify_heights", lo, hi)?;
    let args = AtlasRequest {
        team: team.to_string(),
        failed,
        each_failure: false,
        heights: heights.unwrap_or_else(|| vec![0.5, 1.0, 1.5]),
        directions,
        relaxation,
        certify_heights,
        torque: torque.unwrap_or_default().to_vec(),
        plots,
        json: None,
    };
    let (mut rows, _) = match interruptible(py, |cancel| run_until(&args, Some(cancel)))? {
        Ended::Finished(done) => done.map_err(value_error)?,
        // Ctrl-C: the atlas stops within one ray; nothing is written.
        Ended::Interrupted { signal, .. } => return Err(signal),
    };
    let row = rows
        .pop()
        .ok_or_else(|| PyValueError::new_err("the atlas returned no row"))?;
    record_to_py(py, &row)
}

/// Registers `afs_atlas` on the top-level module.
pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(afs_atlas, m)?)
}
