//! What a `tvmd.sim.Simulation` did since its last successful reset, replayed to copy it:
//! `copy.deepcopy` replays it on a simulation of the same scenario, `pickle` carries it as
//! CBOR bytes. The simulator is deterministic (its noise comes from the seeded generator), so
//! the copy is in the same state and steps as the original would from there on.

use serde::{Deserialize, Serialize};

use tvmd_plant::actuators::ActuatorCommand;
use tvmd_sim::sim::Simulation;
use tvmd_sim::{Diagnostics, FlightOutput, SimError};

/// One call that reached the simulator.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub(crate) enum Action {
    /// `reset(seed, position=, attitude_rpy=)`.
    Reset {
        seed: Option<u64>,
        position: Option<[f64; 3]>,
        attitude: Option<[f64; 3]>,
    },
    /// `step` with commands (and a `ScenarioController`'s diagnostics).
    Output {
        commands: Vec<ActuatorCommand>,
        /// None: no diagnostics (`Simulation.step` with commands).
        diagnostics: Option<Box<Diagnostics>>,
    },
    /// `step_wrench`.
    Wrench([f64; 6]),
}

impl Action {
    /// The commands of `out` as an action.
    pub(crate) fn output(out: &FlightOutput) -> Self {
        Self::Output {
            commands: out.commands.clone(),
            diagnostics: Some(Box::new(out.diagnostics.clone())),
        }
    }

    fn apply(&self, sim: &mut Simulation) -> Result<(), SimError> {
        match self {
            Self::Reset {
                seed,
                position,
                attitude,
            } => sim.reset_at(*seed, *position, *attitude),
            Self::Output {
                commands,
                diagnostics,
            } => sim
                .step_output(FlightOutput {
                    commands: commands.clone(),
                    diagnostics: diagnostics.as_deref().cloned().unwrap_or_default(),
                })
                .map(drop),
            Self::Wrench(wrench) => sim.step_wrench(wrench).map(drop),
        }
    }
}

/// The actions since the last successful reset, each with whether it succeeded (a refused
/// action is replayed too, and must be refused again).
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub(crate) struct ReplayLog(Vec<(Action, bool)>);

impl ReplayLog {
    /// Applies `action` to `sim` and records it.
    pub(crate) fn apply(&mut self, sim: &mut Simulation, action: Action) -> Result<(), SimError> {
        let result = action.apply(sim);
        if matches!(action, Action::Reset { .. }) && result.is_ok() {
            self.0.clear();
        }
        self.0.push((action, result.is_ok()));
        result
    }

    /// Whether a step since the last reset came from your own controller (commands without
    /// a `ScenarioController`'s diagnostics, or a wrench).
    pub(crate) fn own_controller(&self) -> bool {
        self.0.iter().any(|(action, ok)| {
            *ok && matches!(
                action,
                Action::Wrench(_)
                    | Action::Output {
                        diagnostics: None,
                        ..
                    }
            )
        })
    }

    /// Replays the log on `sim`, a simulation of the same scenario as built.
    pub(crate) fn replay(&self, sim: &mut Simulation) -> Result<(), String> {
        for (k, (action, ok)) in self.0.iter().enumerate() {
            if action.apply(sim).is_ok() != *ok {
                return Err(format!(
                    "the copy's action {k} did not do what the original's did (a simulator \
                     that is not deterministic?)"
                ));
            }
        }
        Ok(())
    }

    /// The log as CBOR bytes.
    pub(crate) fn to_bytes(&self) -> Result<Vec<u8>, String> {
        let mut bytes = Vec::new();
        ciborium::into_writer(self, &mut bytes).map_err(|e| e.to_string())?;
        Ok(bytes)
    }

    /// The log of `to_bytes`.
    pub(crate) fn from_bytes(bytes: &[u8]) -> Result<Self, String> {
        ciborium::from_reader(bytes).map_err(|e| e.to_string())
    }
}
