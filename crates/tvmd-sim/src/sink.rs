//! The loop's listener: what it hands over at each controller tick, and the trait through which
//! it hands it ([`TickSink`]). The loop knows no log; a run's MCAP log is one sink
//! (`McapSink`, module `tick_log`), a test's recorder another.

use std::sync::Arc;

use nalgebra::Vector3;
use tvmd_plant::actuators::ActuatorCommand;
use tvmd_plant::physics::{PlantState, TeamBody};
use tvmd_plant::reference::ReferenceSample;

use crate::flight::FlightOutput;
use crate::SimError;

/// A listener of the loop: it gets every controller tick, in order, and a flush at the end.
pub trait TickSink {
    /// Whether the sink draws scenes (the loop then builds [`SceneRecord`]s every scene period).
    fn wants_scenes(&self) -> bool {
        true
    }
    /// Takes one controller tick.
    fn tick(&mut self, tick: LoggedTick) -> Result<(), SimError>;
    /// Called once when the loop ends, whatever ended it (the end, an error, an interrupt):
    /// everything still buffered is handed on.
    fn flush(&mut self) -> Result<(), SimError>;
    /// Called after each tick with the simulation time: a live view paces the run to the wall
    /// clock here. Nothing by default.
    fn pace(&mut self, _t: f64) {}
}

/// The scene of a tick: the team (one copy per run) and the forces to draw.
pub struct SceneRecord {
    /// The team.
    pub team: Arc<TeamBody>,
    /// The agents' body-frame forces to draw (N).
    pub forces_body: Vec<Vector3<f64>>,
    /// The largest thrust, the arrows' scale (N).
    pub max_thrust: f64,
}

/// Everything the log writes for one controller tick.
pub struct LoggedTick {
    /// The tick's values.
    pub tick: Tick,
    /// Whether the heavy topics are written on this tick (the scenario's `[log] decimation`).
    pub heavy: bool,
    /// The scene, on the ticks that draw one.
    pub scene: Option<SceneRecord>,
}

/// The values of one tick to log.
pub struct Tick {
    /// Time (s).
    pub t: f64,
    /// True state.
    pub state: PlantState,
    /// Reference.
    pub reference: ReferenceSample,
    /// The controller's output.
    pub output: FlightOutput,
    /// Actual actuator outputs.
    pub actual: Vec<ActuatorCommand>,
    /// Body-frame forces of the actual outputs.
    pub forces_body: Vec<Vector3<f64>>,
    /// True failure flags.
    pub failed: Vec<bool>,
}
