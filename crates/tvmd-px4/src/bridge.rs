//! The bridge as the loop's flight controller: at each controller tick it sends PX4 the sensors
//! of the tick (HIL_SENSOR; HIL_GPS and HIL_STATE_QUATERNION at their rates), runs the flight
//! script over the GCS link and returns the team's commands of PX4's 16 controls
//! (HIL_ACTUATOR_CONTROLS). Two pacings ([`Pacing`]):
//! - lockstep (PX4's default SITL build): the sensors' `time_usec` is PX4's clock; the bridge
//!   waits for the controls PX4 computes for that time. Until PX4 sends its first controls (it
//!   boots), the ticks go at wall-clock pace with the actuators idle; from then on PX4 and the
//!   plant advance in lockstep, as fast as both compute;
//! - real time (a PX4 build without lockstep, `px4_sitl_nolockstep`): PX4's clock is the wall
//!   clock and it stamps the sensors on arrival, so the ticks go at wall-clock pace the whole
//!   flight and each tick applies the newest controls received (one period of delay, as a
//!   real-time simulator). PX4's telemetry times are mapped onto the simulated time through
//!   the controls' time stamps. There PX4's `perf` counters measure real time.

use std::time::{Duration, Instant};

use nalgebra::Vector3;
use tvmd_sim::{BoxedError, FlightController, FlightInput, FlightOutput};

use crate::flight::FlightPlan;
use crate::gcs::GcsLink;
use crate::link::{Received, SimLink};
use crate::mapping::{ControlMapping, CONTROLS};
use crate::measure::FlightRecord;
use crate::messages::{controls_of, hil_gps, hil_sensor, hil_state, time_of_usec, time_usec};
use crate::script::Script;
use crate::sensors::SensorModel;
use crate::Px4Error;

/// Real time: how long the bridge sleeps between looks for PX4's controls before a tick.
const REAL_TIME_SLICE: Duration = Duration::from_micros(250);

/// Timing of the bridge.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BridgeTiming {
    /// The controller period: PX4's sensor period (s); 0.004 (250 Hz, PX4's simulators').
    pub period: f64,
    /// Lockstep or real time.
    pub pacing: Pacing,
    /// Wall time PX4 may take to answer one tick's sensors in lockstep (in real time: the
    /// longest time without controls once they started).
    pub stall_timeout: Duration,
    /// Wall time PX4 may take from connecting to its first actuator controls.
    pub boot_timeout: Duration,
}

/// How the bridge keeps time with PX4.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Pacing {
    /// Lockstep: PX4's clock is the sensors' time; each tick waits for PX4's controls of its
    /// time (PX4's default SITL build, `ENABLE_LOCKSTEP_SCHEDULER`).
    #[default]
    Lockstep,
    /// Real time: a tick every period on the wall clock, the newest controls applied (a PX4
    /// build without lockstep, `px4_sitl_nolockstep`, whose clock is the wall clock).
    RealTime,
}

/// Wall-clock accounting of the lockstep (in real time: of the paced flight).
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct LockstepStats {
    /// Simulated time when PX4 sent its first controls (s).
    pub lockstep_from: Option<f64>,
    /// Ticks flown in lockstep.
    pub lockstep_ticks: u64,
    /// Wall time of the lockstep ticks (s).
    pub lockstep_wall: f64,
    /// Wall time spent waiting for PX4 in lockstep (s).
    pub waiting_for_px4: f64,
    /// Controls messages that arrived late (time before the tick's) and were skipped.
    pub stale_controls: u64,
    /// Real time: ticks sent more than one period after their wall-clock time (the machine
    /// was busy; PX4 stamps each on arrival).
    pub late_ticks: u64,
    /// Real time: PX4's clock minus the simulated time (s), from the controls' time stamps.
    pub px4_clock_offset: Option<f64>,
}

/// The bridge: the links, the sensors, the mapping, the script and the record.
pub struct Bridge {
    link: SimLink,
    gcs: GcsLink,
    sensors: SensorModel,
    mapping: ControlMapping,
    plan: FlightPlan,
    timing: BridgeTiming,
    script: Script,
    tick: u64,
    last_velocity: Option<Vector3<f64>>,
    controls: [f32; CONTROLS],
    boot_started: Option<Instant>,
    lockstep_started: Option<Instant>,
    stats: LockstepStats,
    record: FlightRecord,
    every: [u64; 3],
    heard: bool,
    wall_anchor: Option<Instant>,
    last_controls: Option<Instant>,
}

impl Bridge {
    /// A bridge over a connected simulator link and a GCS link.
    pub fn new(
        mut link: SimLink,
        gcs: GcsLink,
        plan: FlightPlan,
        mapping: ControlMapping,
        timing: BridgeTiming,
    ) -> Result<Self, Px4Error> {
        let sensors = SensorModel::new(plan.sensors, plan.home)?;
        if timing.pacing == Pacing::RealTime {
            link.set_nonblocking(REAL_TIME_SLICE)?;
        }
        let every = |rate: f64| ((1.0 / (rate * timing.period)).round() as u64).max(1);
        let c = sensors.config();
        let every = [
            every(c.mag_baro_rate),
            every(c.gps_rate),
            every(c.truth_rate),
        ];
        Ok(Self {
            link,
            gcs,
            mapping,
            timing,
            script: Script::new(&plan),
            tick: 0,
            last_velocity: None,
            controls: [0.0; CONTROLS],
            boot_started: None,
            lockstep_started: None,
            stats: LockstepStats::default(),
            record: FlightRecord::new(plan.home),
            every,
            plan,
            sensors,
            heard: false,
            wall_anchor: None,
            last_controls: None,
        })
    }

    /// The record of the flight so far.
    pub fn record(&self) -> &FlightRecord {
        &self.record
    }

    /// The lockstep's accounting so far.
    pub fn stats(&self) -> LockstepStats {
        let mut s = self.stats;
        if let Some(start) = self.lockstep_started {
            s.lockstep_wall = start.elapsed().as_secs_f64();
        }
        s
    }

    /// The flight plan.
    pub fn plan(&self) -> &FlightPlan {
        &self.plan
    }

    fn send_sensors(&mut self, t: f64, input: &FlightInput<'_>) -> Result<(), Px4Error> {
        let state = input.state;
        let accel = match self.last_velocity {
            Some(v) => (state.velocity - v) / self.timing.period,
            None => Vector3::zeros(),
        };
        self.last_velocity = Some(state.velocity);
        let time = time_usec(t);
        let imu = self
            .sensors
            .imu(state, &accel, self.tick.is_multiple_of(self.every[0]));
        self.link.send(&hil_sensor(time, &imu))?;
        if self.tick.is_multiple_of(self.every[1]) {
            let gps = self.sensors.gps(state);
            self.link.send(&hil_gps(time, &gps))?;
        }
        if self.tick.is_multiple_of(self.every[2]) {
            let truth = self.sensors.truth(state, &accel);
            self.link.send(&hil_state(time, &truth))?;
        }
        Ok(())
    }

    fn run_script(&mut self, t: f64) -> Result<(), Px4Error> {
        self.script.advance(t, &mut self.gcs)?;
        for message in self.gcs.poll()? {
            let message = match self.timing.pacing {
                Pacing::Lockstep => Some(message),
                // PX4's wall clock onto the simulated time; none before the first controls.
                Pacing::RealTime => match self.stats.px4_clock_offset {
                    Some(offset) => Some(message.shifted(-offset)),
                    None => message.untimed(),
                },
            };
            if let Some(message) = message {
                self.record.telemetry(t, message);
            }
        }
        let s = self.gcs.state();
        self.heard |= s.heartbeats > 0;
        self.record
            .px4_state(t, s.armed, s.landed_state, self.heard);
        Ok(())
    }

    /// Waits for PX4's controls of `t`: at wall pace (returning the last controls) until PX4
    /// boots, then in lockstep.
    fn await_controls(&mut self, t: f64) -> Result<(), Px4Error> {
        let time = time_usec(t);
        let now = Instant::now();
        let booting = self.lockstep_started.is_none();
        let boot_started = *self.boot_started.get_or_insert(now);
        let deadline = if booting {
            if now.duration_since(boot_started) > self.timing.boot_timeout {
                return Err(Px4Error::Stalled {
                    t,
                    waited: now.duration_since(boot_started).as_secs_f64(),
                });
            }
            // Boot at wall-clock pace: PX4's clock follows the sensors' time.
            boot_started + Duration::from_secs_f64(t + self.timing.period)
        } else {
            now + self.timing.stall_timeout
        };
        loop {
            match self.link.recv_until(deadline)? {
                Received::Message(message) => {
                    let Some(c) = controls_of(&message) else {
                        continue;
                    };
                    if !c.lockstep {
                        return Err(Px4Error::Pacing {
                            px4_lockstep: false,
                        });
                    }
                    if c.time_usec < time {
                        self.stats.stale_controls += u64::from(!booting);
                        if booting {
                            self.controls = c.controls;
                        }
                        continue;
                    }
                    self.controls = c.controls;
                    if booting {
                        self.lockstep_started = Some(Instant::now());
                        self.stats.lockstep_from = Some(t);
                    } else {
                        self.stats.waiting_for_px4 += now.elapsed().as_secs_f64();
                    }
                    return Ok(());
                }
                Received::Timeout if booting => return Ok(()),
                Received::Timeout => {
                    return Err(Px4Error::Stalled {
                        t,
                        waited: now.elapsed().as_secs_f64(),
                    })
                }
                Received::Closed => return Err(Px4Error::Disconnected { t }),
            }
        }
    }

    /// Real time: receives PX4's controls until `due`, keeping the newest, and learns PX4's
    /// clock from their time stamps (sent no later than received: the largest difference).
    fn receive_until(&mut self, t: f64, due: Instant, anchor: Instant) -> Result<(), Px4Error> {
        loop {
            match self.link.recv_until(due)? {
                Received::Message(message) => {
                    let Some(c) = controls_of(&message) else {
                        continue;
                    };
                    if c.lockstep {
                        return Err(Px4Error::Pacing { px4_lockstep: true });
                    }
                    let now = Instant::now();
                    let offset =
                        time_of_usec(c.time_usec) - now.duration_since(anchor).as_secs_f64();
                    let best = self
                        .stats
                        .px4_clock_offset
                        .map_or(offset, |o| o.max(offset));
                    self.stats.px4_clock_offset = Some(best);
                    self.controls = c.controls;
                    self.last_controls = Some(now);
                    if self.lockstep_started.is_none() {
                        self.lockstep_started = Some(now);
                        self.stats.lockstep_from = Some(t);
                    }
                }
                Received::Timeout => return Ok(()),
                Received::Closed => return Err(Px4Error::Disconnected { t }),
            }
        }
    }

    /// Real time: waits for the tick's wall-clock time (receiving meanwhile) and checks that
    /// PX4 booted within the boot timeout and answers within the stall timeout.
    fn pace(&mut self, t: f64) -> Result<(), Px4Error> {
        let anchor = *self.wall_anchor.get_or_insert_with(Instant::now);
        let due = anchor + Duration::from_secs_f64(t);
        self.receive_until(t, due, anchor)?;
        let now = Instant::now();
        if now > due + Duration::from_secs_f64(self.timing.period) {
            self.stats.late_ticks += 1;
        }
        let (since, limit) = match self.last_controls {
            Some(last) => (last, self.timing.stall_timeout),
            None => (anchor, self.timing.boot_timeout),
        };
        if now.duration_since(since) > limit {
            return Err(Px4Error::Stalled {
                t,
                waited: now.duration_since(since).as_secs_f64(),
            });
        }
        Ok(())
    }

    fn step_inner(&mut self, input: &FlightInput<'_>) -> Result<FlightOutput, Px4Error> {
        let t = input.t;
        self.record.truth(t, input.state);
        if self.timing.pacing == Pacing::RealTime {
            self.pace(t)?;
        }
        let sent = self.send_sensors(t, input);
        if let Err(Px4Error::Disconnected { .. }) = sent {
            return Err(Px4Error::Disconnected { t });
        }
        sent?;
        self.run_script(t)?;
        if self.timing.pacing == Pacing::Lockstep {
            self.await_controls(t)?;
        }
        if self.lockstep_started.is_some() {
            self.stats.lockstep_ticks += 1;
        }
        self.tick += 1;
        Ok(FlightOutput {
            commands: self.mapping.commands(&self.controls),
            diagnostics: Default::default(),
        })
    }
}

impl FlightController for Bridge {
    fn step(&mut self, input: &FlightInput<'_>) -> Result<FlightOutput, BoxedError> {
        self.step_inner(input)
            .map_err(|e| Box::new(e) as BoxedError)
    }
}
