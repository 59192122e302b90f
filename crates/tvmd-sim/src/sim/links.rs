//! Each agent's command link (`[links]`, [`CommandLinks`]): commands sent at a controller tick
//! arrive later or never, an agent applies the newest that has arrived, and one whose link has
//! been silent for `hold` fails safe.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use tvmd_plant::actuators::ActuatorCommand;
use tvmd_scenario::{CommandLinks, LinkFailsafe};

/// Times closer than this are the same instant (the physics steps are multiples of `dt`).
const SAME_TIME: f64 = 1e-12;

/// A command in flight: when it arrives, when it was sent, what it says.
#[derive(Clone, Copy, Debug)]
struct Packet {
    arrival: f64,
    sent: f64,
    command: ActuatorCommand,
}

/// What one agent's link did over the flight.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LinkStats {
    /// Commands sent to the agent.
    pub sent: u64,
    /// Commands lost (on their own, in bursts, or to a silent link).
    pub lost: u64,
    /// Commands that arrived after a newer one and were dropped.
    pub stale: u64,
    /// Times the agent failed safe.
    pub failsafes: u64,
}

/// One agent's end of its link.
#[derive(Clone, Debug)]
struct AgentLink {
    in_flight: Vec<Packet>,
    applied_sent: f64,
    last_arrival: f64,
    applied: ActuatorCommand,
    failed_safe: bool,
    burst_left: u64,
    silent_from: Option<f64>,
    stats: LinkStats,
}

/// Every agent's link.
#[derive(Clone, Debug)]
pub struct Links {
    spec: CommandLinks,
    rng: ChaCha8Rng,
    agents: Vec<AgentLink>,
    applied: Vec<ActuatorCommand>,
}

impl Links {
    /// Links of `n` agents, at rest (nothing applied: zero thrust, gimbals level).
    pub fn new(spec: CommandLinks, n: usize) -> Self {
        let agent = AgentLink {
            in_flight: Vec::new(),
            applied_sent: f64::NEG_INFINITY,
            last_arrival: 0.0,
            applied: ActuatorCommand::default(),
            failed_safe: false,
            burst_left: 0,
            silent_from: None,
            stats: LinkStats::default(),
        };
        Self {
            spec,
            rng: ChaCha8Rng::seed_from_u64(spec.seed),
            agents: vec![agent; n],
            applied: vec![ActuatorCommand::default(); n],
        }
    }

    /// Agent `i`'s link carries nothing sent from `t` on (a `link-loss` failure).
    pub fn silence(&mut self, i: usize, t: f64) {
        if let Some(a) = self.agents.get_mut(i) {
            a.silent_from = Some(a.silent_from.map_or(t, |s| s.min(t)));
        }
    }

    /// Sends each agent its command at the controller tick `t`. Every agent draws four
    /// uniforms per command whatever happens to it, so one agent's losses never shift
    /// another's draws.
    pub fn send(&mut self, t: f64, commands: &[ActuatorCommand]) {
        let spec = self.spec;
        for (a, c) in self.agents.iter_mut().zip(commands) {
            let [burst, loss, jitter, length]: [f64; 4] =
                core::array::from_fn(|_| self.rng.random());
            a.stats.sent += 1;
            let lost = if a.silent_from.is_some_and(|s| t >= s - SAME_TIME) {
                true
            } else if a.burst_left > 0 {
                a.burst_left -= 1;
                true
            } else if burst < spec.burst_start {
                // A geometric burst of mean `burst_length`, this command its first.
                let p = 1.0 / spec.burst_length;
                let k = if p >= 1.0 {
                    1.0
                } else {
                    ((1.0 - length).ln() / (1.0 - p).ln()).floor() + 1.0
                };
                a.burst_left = (k.min(1e9) as u64).saturating_sub(1);
                true
            } else {
                loss < spec.loss
            };
            if lost {
                a.stats.lost += 1;
                continue;
            }
            a.in_flight.push(Packet {
                arrival: t + spec.latency + jitter * spec.jitter,
                sent: t,
                command: *c,
            });
        }
    }

    /// The commands the agents apply at physics time `t`, and whether any changed since the
    /// last call.
    pub fn deliver(&mut self, t: f64) -> (&[ActuatorCommand], bool) {
        let spec = self.spec;
        let mut changed = false;
        for (a, out) in self.agents.iter_mut().zip(self.applied.iter_mut()) {
            let mut k = 0;
            while k < a.in_flight.len() {
                let p = a.in_flight[k];
                if p.arrival > t + SAME_TIME {
                    k += 1;
                    continue;
                }
                a.in_flight.swap_remove(k);
                if p.sent > a.applied_sent {
                    a.applied_sent = p.sent;
                    a.applied = p.command;
                    a.last_arrival = t;
                    a.failed_safe = false;
                    changed = true;
                } else {
                    a.stats.stale += 1;
                }
            }
            if !a.failed_safe && t - a.last_arrival > spec.hold + SAME_TIME {
                a.failed_safe = true;
                a.stats.failsafes += 1;
                if spec.failsafe == LinkFailsafe::Idle {
                    a.applied = ActuatorCommand::default();
                    changed = true;
                }
            }
            *out = a.applied;
        }
        (&self.applied, changed)
    }

    /// The commands the agents apply now (as the last [`Self::deliver`] left them).
    pub fn applied(&self) -> &[ActuatorCommand] {
        &self.applied
    }

    /// Whether agent `i`'s link is silent at `t` (a `link-loss` failure).
    pub fn is_silent(&self, i: usize, t: f64) -> bool {
        self.agents
            .get(i)
            .and_then(|a| a.silent_from)
            .is_some_and(|s| t >= s - SAME_TIME)
    }

    /// Per agent, what its link did so far.
    pub fn stats(&self) -> Vec<LinkStats> {
        self.agents.iter().map(|a| a.stats).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn command(thrust: f64) -> ActuatorCommand {
        ActuatorCommand {
            eta_x: 0.1,
            eta_y: -0.1,
            thrust,
        }
    }

    fn thrusts(l: &mut Links, t: f64) -> (Vec<f64>, bool) {
        let (c, changed) = l.deliver(t);
        (c.iter().map(|c| c.thrust).collect(), changed)
    }

    #[test]
    fn an_ideal_link_applies_each_command_as_it_is_sent() {
        let mut l = Links::new(CommandLinks::default(), 2);
        l.send(0.0, &[command(1.0), command(2.0)]);
        assert_eq!(thrusts(&mut l, 0.0), (vec![1.0, 2.0], true));
        assert_eq!(thrusts(&mut l, 0.001), (vec![1.0, 2.0], false));
        assert_eq!(l.deliver(0.0).0[0], command(1.0));
    }

    #[test]
    fn latency_delays_and_a_silent_link_holds_then_idles() {
        let spec = CommandLinks {
            latency: 0.02,
            hold: 0.05,
            ..CommandLinks::default()
        };
        let mut l = Links::new(spec, 1);
        l.send(0.0, &[command(3.0)]);
        assert_eq!(thrusts(&mut l, 0.019).0, [0.0]);
        assert_eq!(thrusts(&mut l, 0.02), (vec![3.0], true));
        l.silence(0, 0.01);
        l.send(0.01, &[command(4.0)]);
        // Held for `hold` after the last arrival (0.02), then idle.
        assert_eq!(thrusts(&mut l, 0.07).0, [3.0]);
        assert_eq!(thrusts(&mut l, 0.071), (vec![0.0], true));
        assert_eq!(l.stats()[0].failsafes, 1);
        assert_eq!(l.stats()[0].lost, 1);
        let hold = CommandLinks {
            failsafe: LinkFailsafe::Hold,
            ..spec
        };
        let mut l = Links::new(hold, 1);
        l.send(0.0, &[command(3.0)]);
        assert_eq!(thrusts(&mut l, 10.0).0, [3.0]);
    }

    #[test]
    fn an_overtaken_command_is_dropped() {
        let mut l = Links::new(CommandLinks::default(), 1);
        l.agents[0].in_flight.push(Packet {
            arrival: 0.03,
            sent: 0.0,
            command: command(1.0),
        });
        l.agents[0].in_flight.push(Packet {
            arrival: 0.02,
            sent: 0.01,
            command: command(2.0),
        });
        assert_eq!(thrusts(&mut l, 0.025).0, [2.0]);
        assert_eq!(thrusts(&mut l, 0.03), (vec![2.0], false));
        assert_eq!(l.stats()[0].stale, 1);
    }

    #[test]
    fn losses_come_at_the_stated_rates_and_draws_are_per_agent() {
        let spec = CommandLinks {
            loss: 0.1,
            burst_start: 0.01,
            burst_length: 5.0,
            jitter: 0.01,
            ..CommandLinks::default()
        };
        let mut l = Links::new(spec, 3);
        let n = 20_000;
        for k in 0..n {
            l.send(k as f64 * 0.01, &[command(1.0); 3]);
        }
        // Independent 10%, plus bursts: a burst starts on about 0.9% of the commands not in
        // one and drops 5 on average: about 0.1 + 0.9 * 0.01 * 5 / (1 + 0.9 * 0.01 * 4).
        let expected = 0.1 + 0.9 * 0.01 * 5.0 / (1.0 + 0.9 * 0.01 * 4.0);
        for s in l.stats() {
            let rate = s.lost as f64 / n as f64;
            assert!((rate - expected).abs() < 0.01, "{rate} vs {expected}");
        }
        let again = {
            let mut m = Links::new(spec, 3);
            for k in 0..n {
                m.send(k as f64 * 0.01, &[command(1.0); 3]);
            }
            m.stats()
        };
        assert_eq!(again, l.stats(), "seeded: the same draws");
        let arrivals: Vec<f64> = l.agents[0]
            .in_flight
            .iter()
            .map(|p| p.arrival - p.sent)
            .collect();
        assert!(arrivals.iter().all(|d| (0.0..=0.01).contains(d)));
        assert!(arrivals.iter().any(|d| *d > 0.009) && arrivals.iter().any(|d| *d < 0.001));
    }
}
