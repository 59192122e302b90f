//! The interface between the loop and a controller: [`FlightController`] and its output
//! [`FlightOutput`] (commands and [`Diagnostics`]). The loop (module `sim`) calls it; the tvmd
//! adapter (module `control`) and test controllers implement it.

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

/// A digital flight controller.
///
/// `state` is the (possibly noisy) fed-back state; `failed[i]` is true if agent `i` failed
/// and the controller is told so. Closures with the same signature implement the trait.
pub trait FlightController {
    /// Computes the commands for the next controller period.
    fn step(
        &mut self,
        t: f64,
        state: &PlantState,
        reference: &ReferenceSample,
        failed: &[bool],
    ) -> Result<FlightOutput, BoxedError>;
}

impl<F> FlightController for F
where
    F: FnMut(f64, &PlantState, &ReferenceSample, &[bool]) -> Result<FlightOutput, BoxedError>,
{
    fn step(
        &mut self,
        t: f64,
        state: &PlantState,
        reference: &ReferenceSample,
        failed: &[bool],
    ) -> Result<FlightOutput, BoxedError> {
        self(t, state, reference, failed)
    }
}
