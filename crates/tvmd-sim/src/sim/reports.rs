//! The agents' own reports (`[reports]`, [`AgentReports`]): sampled at the physics steps at the
//! stated rate from what each agent's actuators do, noised, sent back over its link, and the
//! newest arrived per agent handed to the controller's tick with its age.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;
use tvmd_plant::actuators::{ActuatorBank, ActuatorCommand, ActuatorModel};
use tvmd_scenario::{AgentReports, DeadEsc};

pub use crate::flight::AgentReport;

/// Times closer than this are the same instant.
const SAME_TIME: f64 = 1e-12;

/// A report on its way: when it arrives, whose, when measured, what it says.
#[derive(Clone, Copy, Debug)]
struct InFlight {
    arrival: f64,
    agent: usize,
    measured: f64,
    values: [f64; 3],
    /// What the agent would have reported had it not failed (same noise).
    healthy: [f64; 3],
}

/// Every agent's reports.
#[derive(Clone, Debug)]
pub(super) struct Reports {
    spec: AgentReports,
    rng: ChaCha8Rng,
    period: f64,
    next_sample: f64,
    in_flight: Vec<InFlight>,
    newest: Vec<Option<(f64, [f64; 3])>>,
    /// The newest arrived report as the agent would have sent it had it not failed.
    newest_healthy: Vec<Option<(f64, [f64; 3])>>,
    lying: Vec<bool>,
    /// The agents' actuators as they would be without failures: stepped with the same applied
    /// commands ([`Reports::step_twin`]).
    twin: ActuatorBank,
}

impl Reports {
    /// The reports of `n` agents whose actuators are `model`: the first is measured at `t = 0`.
    pub(super) fn new(spec: &AgentReports, n: usize, model: ActuatorModel) -> Self {
        let mut lying = vec![false; n];
        for i in &spec.lying {
            if let Some(l) = lying.get_mut(*i) {
                *l = true;
            }
        }
        Self {
            spec: spec.clone(),
            rng: ChaCha8Rng::seed_from_u64(spec.seed),
            period: 1.0 / spec.rate,
            next_sample: 0.0,
            in_flight: Vec::new(),
            newest: vec![None; n],
            newest_healthy: vec![None; n],
            lying,
            twin: ActuatorBank::new(model, n),
        }
    }

    /// Steps the actuators' healthy twin by `dt` with the commands the agents applied (as the
    /// plant's [`ActuatorBank::step`]).
    pub(super) fn step_twin(&mut self, applied: &[ActuatorCommand], dt: f64) {
        self.twin.step(applied, dt);
    }

    /// At physics time `t`, when a sample is due: each agent measures what its actuators do
    /// (`bank`; a lying one its `applied` command) unless `silent(i)` (its link is gone). Every
    /// agent draws three normals and a uniform per sample whatever happens to it.
    pub(super) fn sample(
        &mut self,
        t: f64,
        bank: &ActuatorBank,
        applied: &[ActuatorCommand],
        silent: impl Fn(usize) -> bool,
    ) {
        if t < self.next_sample - SAME_TIME {
            return;
        }
        while self.next_sample <= t + SAME_TIME {
            self.next_sample += self.period;
        }
        let spec = &self.spec;
        for (i, a) in bank.agents.iter().enumerate() {
            let noise: [f64; 3] = core::array::from_fn(|_| self.rng.sample(StandardNormal));
            let lost = self.rng.random::<f64>() < spec.loss;
            let lying = self.lying.get(i).copied().unwrap_or(false);
            let c = applied.get(i).copied().unwrap_or_default();
            let healthy = match (lying, self.twin.agents.get(i)) {
                (false, Some(h)) => h.actual,
                _ => c,
            };
            let (thrust, eta_x, eta_y) = if lying {
                (c.thrust, c.eta_x, c.eta_y)
            } else if a.thrust_failed {
                if spec.dead_esc == DeadEsc::Silent {
                    continue;
                }
                (0.0, a.actual.eta_x, a.actual.eta_y)
            } else if a.thrust_halved {
                // The rotor spins as commanded; the damaged propeller makes half the thrust.
                (2.0 * a.actual.thrust, a.actual.eta_x, a.actual.eta_y)
            } else {
                (a.actual.thrust, a.actual.eta_x, a.actual.eta_y)
            };
            if lost || silent(i) {
                continue;
            }
            self.in_flight.push(InFlight {
                arrival: t + spec.latency,
                agent: i,
                measured: t,
                values: [
                    thrust + spec.thrust_noise * noise[0],
                    eta_x + spec.angle_noise * noise[1],
                    eta_y + spec.angle_noise * noise[2],
                ],
                healthy: [
                    healthy.thrust + spec.thrust_noise * noise[0],
                    healthy.eta_x + spec.angle_noise * noise[1],
                    healthy.eta_y + spec.angle_noise * noise[2],
                ],
            });
        }
    }

    /// Per agent, the newest report arrived by `t` (`None`: none yet).
    pub(super) fn at(&mut self, t: f64) -> Vec<Option<AgentReport>> {
        let (newest, healthy) = (&mut self.newest, &mut self.newest_healthy);
        self.in_flight.retain(|r| {
            if r.arrival > t + SAME_TIME {
                return true;
            }
            if let (Some(slot), Some(h)) = (newest.get_mut(r.agent), healthy.get_mut(r.agent)) {
                if slot.is_none_or(|(m, _)| r.measured > m) {
                    *slot = Some((r.measured, r.values));
                    *h = Some((r.measured, r.healthy));
                }
            }
            false
        });
        aged(newest, t)
    }

    /// Per agent, the newest report arrived by the last [`Reports::at`] as the agent would
    /// have sent it had it not failed, aged to `t`.
    pub(super) fn healthy_at(&self, t: f64) -> Vec<Option<AgentReport>> {
        aged(&self.newest_healthy, t)
    }
}

/// The reports `(measured, [thrust, eta_x, eta_y])`, aged to `t`.
fn aged(reports: &[Option<(f64, [f64; 3])>], t: f64) -> Vec<Option<AgentReport>> {
    reports
        .iter()
        .map(|r| {
            r.map(|(m, [thrust, eta_x, eta_y])| AgentReport {
                thrust,
                eta_x,
                eta_y,
                age: t - m,
            })
        })
        .collect()
}
