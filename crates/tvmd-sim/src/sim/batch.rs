//! Many simulations of one scenario stepped together: one call steps every team one controller
//! period on the crate's worker pool ([`crate::pool`]), each with its own action, so a caller
//! (a vectorized Gymnasium environment) pays one call per batch step, not one per team.
//!
//! Every team is a [`Simulation`] of its own: its failures, noise and errors are its own, and
//! one team's error (a bad action, a divergence) is that team's result, never the batch's.

use std::sync::Mutex;

use super::step::Observation;
use super::{SimOptions, Simulation};
use crate::pool::{map_in_order, worker_count};
use crate::SimError;
use tvmd_scenario::Scenario;

/// One team after a batch call: its next observation and whether its run is over.
#[derive(Clone, Debug, PartialEq)]
pub struct TeamStep {
    /// The team's observation of its current tick.
    pub observation: Observation,
    /// The team's scenario duration is reached.
    pub finished: bool,
    /// Per agent, by how much the plant clamped the team's last commands
    /// ([`Simulation::saturation`]).
    pub saturation: Vec<tvmd_plant::actuators::ActuatorCommand>,
}

/// The action of every team of a batch step.
#[derive(Clone, Copy, Debug)]
pub enum BatchAction<'a> {
    /// One body wrench `[u_tau; u_f]` per team ([`Simulation::step_wrench`]).
    Wrench(&'a [[f64; 6]]),
    /// Per-agent commands per team ([`Simulation::step`]).
    Commands(&'a [Vec<tvmd_plant::actuators::ActuatorCommand>]),
}

impl BatchAction<'_> {
    fn len(&self) -> usize {
        match self {
            Self::Wrench(w) => w.len(),
            Self::Commands(c) => c.len(),
        }
    }
}

/// `count` simulations of one scenario, stepped together on `jobs` worker threads.
pub struct SimulationBatch {
    teams: Vec<Mutex<Simulation>>,
    workers: usize,
}

impl SimulationBatch {
    /// `count` (at least 1) simulations of `scenario`; `jobs` worker threads (default: the
    /// available cores).
    pub fn new(
        scenario: &Scenario,
        count: usize,
        options: SimOptions,
        jobs: Option<usize>,
    ) -> Result<Self, SimError> {
        if count == 0 {
            return Err(SimError::InvalidArgument {
                name: "count".into(),
                reason: "a batch needs at least one team".into(),
            });
        }
        let first = Simulation::with_options(scenario, options)?;
        let mut teams = Vec::with_capacity(count);
        for _ in 1..count {
            teams.push(Mutex::new(Simulation::with_options(scenario, options)?));
        }
        teams.insert(0, Mutex::new(first));
        Ok(Self {
            workers: worker_count(jobs, count),
            teams,
        })
    }

    /// The number of teams.
    pub fn len(&self) -> usize {
        self.teams.len()
    }

    /// Never true: a batch has at least one team.
    pub fn is_empty(&self) -> bool {
        self.teams.is_empty()
    }

    /// `f` on team `k`'s simulation.
    pub fn with<R>(&self, k: usize, f: impl FnOnce(&mut Simulation) -> R) -> Result<R, SimError> {
        let team = self.teams.get(k).ok_or_else(|| SimError::InvalidArgument {
            name: "team".into(),
            reason: format!("{k} is not a team of a batch of {}", self.teams.len()),
        })?;
        let mut sim = team
            .lock()
            .map_err(|_| SimError::Internal("a team's simulation panicked".into()))?;
        Ok(f(&mut sim))
    }

    /// Steps every team `k` with `active[k]` (every team without `active`) one controller
    /// period with its action, in parallel; then every team's observation (inactive teams
    /// keep theirs). `Err` only for a batch-wide mistake (the number of actions or flags); a
    /// team's own error is its entry.
    pub fn step(
        &self,
        action: BatchAction<'_>,
        active: Option<&[bool]>,
    ) -> Result<Vec<Result<TeamStep, SimError>>, SimError> {
        let n = self.teams.len();
        let counted = [
            ("actions", action.len()),
            ("active", active.map_or(n, <[bool]>::len)),
        ];
        if let Some((name, len)) = counted.into_iter().find(|(_, len)| *len != n) {
            return Err(SimError::InvalidArgument {
                name: name.into(),
                reason: format!("{len} entries for a batch of {n} teams"),
            });
        }
        let indices: Vec<usize> = (0..n).collect();
        let out = map_in_order(&indices, self.workers, |_, &k| {
            self.with(k, |sim| {
                if active.is_none_or(|a| a.get(k).copied().unwrap_or(false)) {
                    let stepped = match action {
                        BatchAction::Wrench(w) => w.get(k).map(|w| sim.step_wrench(w)),
                        BatchAction::Commands(c) => c.get(k).map(|c| sim.step(c)),
                    };
                    if let Some(Err(e)) = stepped {
                        return Err(e);
                    }
                }
                team_step(sim)
            })
            .and_then(|r| r)
        });
        Ok(out
            .into_iter()
            .map(|r| r.unwrap_or_else(|| Err(SimError::Internal("a team's step panicked".into()))))
            .collect())
    }

    /// Resets team `k` ([`Simulation::reset_at`]); its first observation.
    pub fn reset(
        &self,
        k: usize,
        seed: Option<u64>,
        position: Option<[f64; 3]>,
        roll_pitch_yaw: Option<[f64; 3]>,
    ) -> Result<TeamStep, SimError> {
        self.with(k, |sim| {
            sim.reset_at(seed, position, roll_pitch_yaw)?;
            team_step(sim)
        })?
    }
}

fn team_step(sim: &mut Simulation) -> Result<TeamStep, SimError> {
    let finished = sim.is_finished();
    let observation = sim.observe()?.clone();
    Ok(TeamStep {
        observation,
        finished,
        saturation: sim.saturation().to_vec(),
    })
}
