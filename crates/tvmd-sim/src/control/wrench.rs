//! The second action mode of a stepped simulation: a body wrench `u = [u_tau; u_f]` turned into
//! admissible per-agent commands by tvmd's planner-free allocation, the allocation stage of the
//! core controller ([`tvmd_core::Controller::allocate`]) built from the scenario, in f64.

use nalgebra::Vector6;
use tvmd_core::FailureMask;

use super::{convert, core_of_scenario, CoreController, MAX_AGENTS};
use crate::SimError;
use tvmd_plant::actuators::ActuatorCommand;
use tvmd_plant::PhysicsError;
use tvmd_scenario::Scenario;

/// The allocation stage of the scenario's controller (its team, limits, allocator, rate
/// limits and null-space stage), in f64: a body wrench in, commands inside `E_f` out.
///
/// It follows the failures it is told of as the controller in the loop does: a mask the core
/// refuses (the remaining team cannot produce every wrench) leaves the old one in place.
#[derive(Debug)]
pub struct WrenchAllocation {
    inner: CoreController<f64>,
    n: usize,
    mask: Vec<bool>,
}

impl WrenchAllocation {
    /// The allocation stage of `scenario`'s controller. Errors name the scenario field the
    /// core rejected.
    pub fn from_scenario(scenario: &Scenario) -> Result<Self, SimError> {
        let (inner, n) = core_of_scenario::<f64>(scenario)?;
        Ok(Self {
            inner,
            n,
            mask: vec![false; n],
        })
    }

    /// The number of agents.
    pub fn len(&self) -> usize {
        self.n
    }

    /// True for a team without agents (never: the core refuses one).
    pub fn is_empty(&self) -> bool {
        self.n == 0
    }

    /// Per-agent commands for the body wrench `wrench = [u_tau; u_f]` (N m, N; body frame,
    /// about the centre of mass) with the agents `failed` (the failures the controller is
    /// told of) idle.
    ///
    /// A wrench with a non-finite component is an error at `t` (nothing changes). A wrench the
    /// allocation cannot serve (zero thrust for a non-zero force, an overflow) holds the
    /// previous commands, as the controller in the loop does.
    pub fn commands(
        &mut self,
        t: f64,
        wrench: &[f64; 6],
        failed: &[bool],
    ) -> Result<Vec<ActuatorCommand>, SimError> {
        if let Some(i) = wrench.iter().position(|x| !x.is_finite()) {
            return Err(SimError::Physics(PhysicsError::InvalidCommand {
                t,
                reason: format!("non-finite wrench component {i}"),
            }));
        }
        self.update_failures(failed);
        let u = Vector6::from_column_slice(wrench);
        let commands = match self.inner.allocate(&u) {
            Ok(stage) => stage.commands,
            Err(e) => e.commands,
        };
        Ok(commands[..self.n]
            .iter()
            .map(convert::sim_command)
            .collect())
    }

    fn update_failures(&mut self, failed: &[bool]) {
        let wanted: Vec<bool> = (0..self.n)
            .map(|i| failed.get(i).copied().unwrap_or(false))
            .collect();
        if wanted == self.mask {
            return;
        }
        let mut mask = FailureMask::<MAX_AGENTS>::none();
        for (i, f) in wanted.iter().enumerate() {
            // i < n <= MAX_AGENTS, so this cannot fail.
            let _ = mask.set(i, *f);
        }
        // A refused mask keeps the old one (the loop's controller reports it; here the
        // commands show it).
        let _ = self.inner.set_failures(mask);
        self.mask = wanted;
    }
}
