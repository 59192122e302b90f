//! The scenario's `[log]` table: how much of a run its log keeps.

use serde::{Deserialize, Serialize};

/// The scenario's `[log]` table: how much of a run its log keeps.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct LogSettings {
    /// Write the heavy diagnostics topics (`/planner`, `/control`, `/allocation`,
    /// `/actuators`) at every `decimation`-th controller tick; 1 (every tick). `/state`,
    /// `/reference`, `/lyapunov` and `/tf` are written every tick, `/hover` whenever it
    /// changes, so the paper's plots keep their resolution.
    pub decimation: usize,
    /// Period of `/scene` messages (s), rounded to a multiple of the controller period; 0.05.
    pub scene_period: f64,
}

impl Default for LogSettings {
    fn default() -> Self {
        Self {
            decimation: 1,
            scene_period: 0.05,
        }
    }
}
