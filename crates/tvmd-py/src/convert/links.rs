//! The command links' counts (`Simulation.link_stats()`): tvmd-sim's per-agent
//! [`LinkStats`] as a dict of `(n,)` int64 arrays, one per count.

use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use tvmd_sim::LinkStats;

/// A count's name and how to read it off an agent's stats.
type Column = (&'static str, fn(&LinkStats) -> u64);

/// `{"sent", "lost", "stale", "failsafes"}`, each `(n,)` int64 in the agents' order.
pub(crate) fn link_stats_to_py<'py>(
    py: Python<'py>,
    stats: &[LinkStats],
) -> PyResult<Bound<'py, PyDict>> {
    let dict = PyDict::new(py);
    let columns: [Column; 4] = [
        ("sent", |s| s.sent),
        ("lost", |s| s.lost),
        ("stale", |s| s.stale),
        ("failsafes", |s| s.failsafes),
    ];
    for (name, count) in columns {
        // Counts of a flight's periods: far below i64::MAX; saturate rather than wrap.
        let values: Vec<i64> = stats
            .iter()
            .map(|s| i64::try_from(count(s)).unwrap_or(i64::MAX))
            .collect();
        dict.set_item(name, PyArray1::from_vec(py, values))?;
    }
    Ok(dict)
}
