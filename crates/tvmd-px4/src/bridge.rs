//! The lockstep bridge as the loop's flight controller: at each controller tick it sends PX4
//! the sensors of the tick (HIL_SENSOR, whose `time_usec` is PX4's clock; HIL_GPS and
//! HIL_STATE_QUATERNION at their rates), runs the flight script over the GCS link, waits for
//! the HIL_ACTUATOR_CONTROLS PX4 computes for that time, and returns the team's commands of its
//! 16 controls. Until PX4 sends its first controls (it boots), the ticks go at wall-clock pace
//! with the actuators idle; from then on PX4 and the plant advance in lockstep, as fast as
//! both compute.

use std::time::{Duration, Instant};

use nalgebra::Vector3;
use tvmd_sim::{BoxedError, FlightController, FlightInput, FlightOutput};

use crate::flight::FlightPlan;
use crate::gcs::GcsLink;
use crate::link::{Received, SimLink};
use crate::mapping::{ControlMapping, CONTROLS};
use crate::measure::FlightRecord;
use crate::messages::{controls_of, hil_gps, hil_sensor, hil_state, time_usec};
use crate::script::Script;
use crate::sensors::SensorModel;
use crate::Px4Error;

/// Timing of the bridge.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BridgeTiming {
    /// The controller period: PX4's sensor period (s); 0.004 (250 Hz, PX4's simulators').
    pub period: f64,
    /// Wall time PX4 may take to answer one tick's sensors in lockstep.
    pub stall_timeout: Duration,
    /// Wall time PX4 may take from connecting to its first actuator controls.
    pub boot_timeout: Duration,
}

/// Wall-clock accounting of the lockstep.
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
}

impl Bridge {
    /// A bridge over a connected simulator link and a GCS link.
    pub fn new(
        link: SimLink,
        gcs: GcsLink,
        plan: FlightPlan,
        mapping: ControlMapping,
        timing: BridgeTiming,
    ) -> Result<Self, Px4Error> {
        let sensors = SensorModel::new(plan.sensors, plan.home)?;
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
            .imu(state, &accel, self.tick % self.every[0] == 0);
        self.link.send(&hil_sensor(time, &imu))?;
        if self.tick % self.every[1] == 0 {
            let gps = self.sensors.gps(state);
            self.link.send(&hil_gps(time, &gps))?;
        }
        if self.tick % self.every[2] == 0 {
            let truth = self.sensors.truth(state, &accel);
            self.link.send(&hil_state(time, &truth))?;
        }
        Ok(())
    }

    fn run_script(&mut self, t: f64) -> Result<(), Px4Error> {
        self.script.advance(t, &mut self.gcs)?;
        for message in self.gcs.poll()? {
            self.record.telemetry(t, message);
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

    fn step_inner(&mut self, input: &FlightInput<'_>) -> Result<FlightOutput, Px4Error> {
        let t = input.t;
        self.record.truth(t, input.state);
        let sent = self.send_sensors(t, input);
        if let Err(Px4Error::Disconnected { .. }) = sent {
            return Err(Px4Error::Disconnected { t });
        }
        sent?;
        self.run_script(t)?;
        self.await_controls(t)?;
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
