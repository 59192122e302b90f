//! The interface between the loop and a controller: [`FlightController`] and its output
//! [`FlightOutput`] (commands and [`Diagnostics`]). The loop (module `sim`) calls it; the tvmd
//! adapter (module `control`) and test controllers implement it.

use serde::Serialize;

use crate::diagnostics::Diagnostics;
use crate::error::BoxedError;
use tvmd_plant::actuators::ActuatorCommand;
use tvmd_plant::physics::PlantState;
use tvmd_plant::reference::ReferenceSample;

/// Where an in-process controller runs (a summary's `controller_target`; a
/// processor-in-the-loop flight names its emulated target instead).
pub const HOST_TARGET: &str = "host";

/// What a controller returns at each tick.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FlightOutput {
    /// One command per agent (failed agents included; their commands are ignored as the
    /// failure dictates).
    pub commands: Vec<ActuatorCommand>,
    /// Diagnostics to log.
    pub diagnostics: Diagnostics,
}

/// The newest report of one agent at a tick (`[reports]`: the simulator's agents' own
/// reports).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct AgentReport {
    /// Rotor speed as the thrust `k omega^2` it makes with an intact propeller (N).
    pub thrust: f64,
    /// Inner gimbal angle `eta_x` (rad).
    pub eta_x: f64,
    /// Outer gimbal angle `eta_y` (rad).
    pub eta_y: f64,
    /// How long ago it was measured (s).
    pub age: f64,
}

/// What a flight controller is given at one controller tick `t_k`: the one definition of a
/// step's inputs, shared by every controller and by the loop.
#[derive(Clone, Copy, Debug)]
pub struct FlightInput<'a> {
    /// Simulation time `t_k` (s).
    pub t: f64,
    /// The fed-back state (the true state with the scenario's noise and feedback latency).
    pub state: &'a PlantState,
    /// The reference at `t_k`.
    pub reference: &'a ReferenceSample,
    /// `failed[i]`: agent `i` failed and the controller is told so.
    pub failed: &'a [bool],
    /// Per agent, its newest report arrived by `t_k` (`None`: none yet); empty without
    /// `[reports]`.
    pub reports: &'a [Option<AgentReport>],
}

impl<'a> FlightInput<'a> {
    /// The inputs of one tick.
    pub fn new(
        t: f64,
        state: &'a PlantState,
        reference: &'a ReferenceSample,
        failed: &'a [bool],
    ) -> Self {
        Self {
            t,
            state,
            reference,
            failed,
            reports: &[],
        }
    }

    /// The same inputs with the agents' reports.
    pub fn with_reports(self, reports: &'a [Option<AgentReport>]) -> Self {
        Self { reports, ..self }
    }
}

/// A digital flight controller. Closures taking a [`FlightInput`] implement the trait.
pub trait FlightController {
    /// Computes the commands for the next controller period.
    fn step(&mut self, input: &FlightInput<'_>) -> Result<FlightOutput, BoxedError>;
}

impl<F> FlightController for F
where
    F: FnMut(&FlightInput<'_>) -> Result<FlightOutput, BoxedError>,
{
    fn step(&mut self, input: &FlightInput<'_>) -> Result<FlightOutput, BoxedError> {
        self(input)
    }
}
