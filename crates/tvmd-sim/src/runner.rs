//! One call to run a scenario with the tvmd controller, optionally logging to an MCAP file.

use std::collections::BTreeMap;
use std::path::Path;

use crate::control::TvmdController;
use crate::error::BoxedError;
use crate::log::{McapLog, METADATA_SCENARIO};
use crate::physics::RigidState;
use crate::reference::Reference;
use crate::scenario::Scenario;
use crate::sim::{ControlOutput, FlightController, RunResult, SimOptions, Simulation};
use crate::SimError;

/// A controller that reports the time of every call to a callback (for progress bars).
pub struct WithProgress<'a> {
    inner: &'a mut dyn FlightController,
    progress: &'a mut dyn FnMut(f64),
}

impl<'a> WithProgress<'a> {
    /// Wraps `inner`; `progress(t)` is called before each controller call.
    pub fn new(inner: &'a mut dyn FlightController, progress: &'a mut dyn FnMut(f64)) -> Self {
        Self { inner, progress }
    }
}

impl FlightController for WithProgress<'_> {
    fn step(
        &mut self,
        t: f64,
        state: &RigidState,
        reference: &Reference,
        failed: &[bool],
    ) -> Result<ControlOutput, BoxedError> {
        (self.progress)(t);
        self.inner.step(t, state, reference, failed)
    }
}

/// Writes the scenario into the log's metadata record [`METADATA_SCENARIO`].
pub fn write_scenario_metadata(log: &mut McapLog, scenario: &Scenario) -> Result<(), SimError> {
    let mut meta = BTreeMap::new();
    meta.insert("name".to_string(), scenario.name.clone());
    meta.insert("relaxation".to_string(), scenario.relaxation.to_string());
    meta.insert("allocator".to_string(), scenario.allocator.clone());
    meta.insert("toml".to_string(), scenario.to_toml_string()?);
    log.write_metadata(METADATA_SCENARIO, meta)
}

/// Runs `scenario` with [`TvmdController`] to its end.
///
/// With `log`, writes an MCAP file there (parent directories created, the scenario stored as
/// metadata); the file is finalised even if the run fails. `progress(t)` is called at every
/// controller tick.
pub fn run_scenario(
    scenario: &Scenario,
    log: Option<&Path>,
    progress: Option<&mut dyn FnMut(f64)>,
) -> Result<RunResult, SimError> {
    let mut controller = TvmdController::from_scenario(scenario)?;
    let mut sim = Simulation::with_options(scenario, SimOptions::default())?;
    let mut mcap = match log {
        Some(path) => {
            if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
                std::fs::create_dir_all(dir)?;
            }
            let mut l = McapLog::create(path)?;
            write_scenario_metadata(&mut l, scenario)?;
            Some(l)
        }
        None => None,
    };
    let result = match progress {
        Some(p) => sim.run(&mut WithProgress::new(&mut controller, p), mcap.as_mut()),
        None => sim.run(&mut controller, mcap.as_mut()),
    };
    if let Some(l) = mcap.as_mut() {
        l.finish()?;
    }
    result
}
