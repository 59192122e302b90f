//! What a flight with PX4 showed: PX4's events (armed, airborne, landed), its messages, its
//! estimate against the truth, and per window the hold, the settling, the tilt.

use std::collections::VecDeque;

use nalgebra::{Rotation3, Vector3};
use serde::Serialize;
use tvmd_plant::physics::PlantState;

use crate::flight::Window;
use crate::frames::{euler_ned, flip, rotation_of_px4_quaternion};
use crate::gcs::Telemetry;
use crate::geo::Home;

/// Truth kept to match PX4's time-stamped estimate (s of simulated time).
const TRUTH_MEMORY: f64 = 5.0;

/// PX4's events over the flight (simulated s), `None` if never seen.
#[derive(Clone, Debug, Default, Serialize)]
pub struct Events {
    /// First heartbeat saying armed.
    pub armed: Option<f64>,
    /// First landed state "in air".
    pub airborne: Option<f64>,
    /// First landed state "on ground" after being airborne.
    pub landed: Option<f64>,
    /// First heartbeat saying disarmed after being armed.
    pub disarmed: Option<f64>,
    /// When the estimator's origin was first reported.
    pub origin: Option<f64>,
}

/// One sample of the truth and PX4's view, at a controller tick.
#[derive(Clone, Copy, Debug)]
struct TruthSample {
    t: f64,
    /// North, east, up from home (m).
    position: Vector3<f64>,
    /// Roll, pitch, yaw NED (rad).
    euler: [f64; 3],
}

/// A matched estimate: simulated time, position error NED (m).
#[derive(Clone, Copy, Debug)]
struct PositionError {
    t: f64,
    error: Vector3<f64>,
}

/// The measures of one window.
#[derive(Clone, Debug, Serialize)]
pub struct WindowReport {
    /// The window's name.
    pub name: String,
    /// Start, end (simulated s).
    pub from: f64,
    /// End.
    pub to: f64,
    /// Largest distance of the true position from the target (m).
    pub hold_max: Option<f64>,
    /// Root mean square distance from the target (m).
    pub hold_rms: Option<f64>,
    /// Time from the window's start until the true position stays within `settle_band` of the
    /// target to the window's end (s); `None` if it never does.
    pub settling_time: Option<f64>,
    /// Largest distance beyond the target along the way from the window's start position (m).
    pub overshoot: Option<f64>,
    /// Largest estimator position error (m).
    pub ekf_position_max: Option<f64>,
    /// Root mean square estimator position error (m).
    pub ekf_position_rms: Option<f64>,
    /// Largest estimator attitude error (rad).
    pub ekf_attitude_max: Option<f64>,
    /// Root mean square estimator attitude error (rad).
    pub ekf_attitude_rms: Option<f64>,
    /// Mean true roll (rad, PX4's sign: right side down positive).
    pub roll_mean: f64,
    /// Largest true |roll| (rad).
    pub roll_max: f64,
    /// Standard deviation of the true roll about its mean (rad): the oscillation.
    pub roll_std: f64,
    /// Largest |roll| of PX4's attitude setpoint (rad): the planned roll.
    pub planned_roll_max: Option<f64>,
    /// Mean roll of PX4's attitude setpoint (rad).
    pub planned_roll_mean: Option<f64>,
    /// Largest true |pitch| (rad).
    pub pitch_max: f64,
    /// Largest true height (m above home).
    pub height_max: f64,
    /// Ticks in the window.
    pub samples: usize,
}

/// Everything recorded over a flight.
pub struct FlightRecord {
    home: Home,
    events: Events,
    texts: Vec<(f64, u8, String)>,
    origin_ned: Option<Vector3<f64>>,
    truth: Vec<TruthSample>,
    recent: VecDeque<(f64, PlantState)>,
    position_errors: Vec<PositionError>,
    attitude_errors: Vec<(f64, f64)>,
    setpoint_roll: Vec<(f64, f64)>,
    was_airborne: bool,
    was_armed: bool,
}

impl FlightRecord {
    /// An empty record at `home`.
    pub fn new(home: Home) -> Self {
        Self {
            home,
            events: Events::default(),
            texts: Vec::new(),
            origin_ned: None,
            truth: Vec::new(),
            recent: VecDeque::new(),
            position_errors: Vec::new(),
            attitude_errors: Vec::new(),
            setpoint_roll: Vec::new(),
            was_airborne: false,
            was_armed: false,
        }
    }

    /// The truth at a tick.
    pub fn truth(&mut self, t: f64, state: &PlantState) {
        let ned = flip(&state.position);
        self.truth.push(TruthSample {
            t,
            position: Vector3::new(ned.x, ned.y, -ned.z),
            euler: euler_ned(&state.rotation),
        });
        self.recent.push_back((t, *state));
        while self
            .recent
            .front()
            .is_some_and(|(t0, _)| t - t0 > TRUTH_MEMORY)
        {
            self.recent.pop_front();
        }
    }

    /// PX4's state at a tick (armed, landed state).
    pub fn px4_state(&mut self, t: f64, armed: bool, landed_state: u8, heard: bool) {
        if !heard {
            return;
        }
        if armed && !self.was_armed {
            self.events.armed.get_or_insert(t);
        }
        if !armed && self.was_armed {
            self.events.disarmed.get_or_insert(t);
        }
        self.was_armed = armed;
        if landed_state == 2 {
            self.was_airborne = true;
            self.events.airborne.get_or_insert(t);
        }
        if landed_state == 1 && self.was_airborne {
            self.events.landed.get_or_insert(t);
        }
    }

    fn truth_at(&self, t: f64) -> Option<&PlantState> {
        self.recent
            .iter()
            .min_by(|a, b| (a.0 - t).abs().total_cmp(&(b.0 - t).abs()))
            .filter(|(t0, _)| (t0 - t).abs() < 0.01)
            .map(|(_, s)| s)
    }

    /// One message of PX4's, at simulated time `now`.
    pub fn telemetry(&mut self, now: f64, message: Telemetry) {
        match message {
            Telemetry::Origin {
                latitude,
                longitude,
                altitude,
            } => {
                let (north, east) = self.home.project(latitude, longitude);
                self.origin_ned = Some(Vector3::new(north, east, self.home.altitude - altitude));
                self.events.origin.get_or_insert(now);
            }
            Telemetry::LocalPosition { t, position } => {
                let (Some(origin), Some(truth)) = (self.origin_ned, self.truth_at(t)) else {
                    return;
                };
                let truth_local = flip(&truth.position) - origin;
                let error = Vector3::from(position) - truth_local;
                self.position_errors.push(PositionError { t, error });
            }
            Telemetry::Attitude { t, q } => {
                if let Some(truth) = self.truth_at(t) {
                    let estimate = rotation_of_px4_quaternion(q);
                    let relative = Rotation3::from_matrix(&(estimate.transpose() * truth.rotation));
                    self.attitude_errors.push((t, relative.angle()));
                }
            }
            Telemetry::AttitudeTarget { t, q } => {
                let r = rotation_of_px4_quaternion(q);
                self.setpoint_roll.push((t, euler_ned(&r)[0]));
            }
            Telemetry::Text { severity, text } => self.texts.push((now, severity, text)),
            Telemetry::Ack { .. } => {}
        }
    }

    /// PX4's events.
    pub fn events(&self) -> &Events {
        &self.events
    }

    /// PX4's status texts (simulated s, severity, text).
    pub fn texts(&self) -> &[(f64, u8, String)] {
        &self.texts
    }

    /// The estimator's position and attitude errors were matched this many times.
    pub fn matched(&self) -> (usize, usize) {
        (self.position_errors.len(), self.attitude_errors.len())
    }

    /// The measures of `window`.
    pub fn window(&self, w: &Window) -> WindowReport {
        let inside = |t: f64| t >= w.from && t <= w.to;
        let truth: Vec<&TruthSample> = self.truth.iter().filter(|s| inside(s.t)).collect();
        let target = w.target.map(Vector3::from);
        let distances: Vec<f64> = target
            .map(|p| truth.iter().map(|s| (s.position - p).norm()).collect())
            .unwrap_or_default();
        let settling_time = target.and_then(|_| {
            let last_out = distances.iter().rposition(|d| *d > w.settle_band);
            match last_out {
                None => truth.first().map(|_| 0.0),
                Some(k) if k + 1 < truth.len() => Some(truth[k + 1].t - w.from),
                Some(_) => None,
            }
        });
        let overshoot = target.and_then(|p| {
            let start = truth.first()?.position;
            let way = p - start;
            let length = way.norm();
            (length > 1e-6).then(|| {
                let dir = way / length;
                truth
                    .iter()
                    .map(|s| (s.position - start).dot(&dir) - length)
                    .fold(0.0, f64::max)
            })
        });
        let positions: Vec<f64> = self
            .position_errors
            .iter()
            .filter(|e| inside(e.t))
            .map(|e| e.error.norm())
            .collect();
        let attitudes: Vec<f64> = self
            .attitude_errors
            .iter()
            .filter(|e| inside(e.0))
            .map(|e| e.1)
            .collect();
        let planned: Vec<f64> = self
            .setpoint_roll
            .iter()
            .filter(|e| inside(e.0))
            .map(|e| e.1)
            .collect();
        let rolls: Vec<f64> = truth.iter().map(|s| s.euler[0]).collect();
        let roll_mean = mean(&rolls).unwrap_or(0.0);
        WindowReport {
            name: w.name.clone(),
            from: w.from,
            to: w.to,
            hold_max: max(&distances),
            hold_rms: rms(&distances),
            settling_time,
            overshoot,
            ekf_position_max: max(&positions),
            ekf_position_rms: rms(&positions),
            ekf_attitude_max: max(&attitudes),
            ekf_attitude_rms: rms(&attitudes),
            roll_mean,
            roll_max: max(&rolls.iter().map(|r| r.abs()).collect::<Vec<_>>()).unwrap_or(0.0),
            roll_std: rms(&rolls.iter().map(|r| r - roll_mean).collect::<Vec<_>>()).unwrap_or(0.0),
            planned_roll_max: max(&planned.iter().map(|r| r.abs()).collect::<Vec<_>>()),
            planned_roll_mean: mean(&planned),
            pitch_max: truth.iter().map(|s| s.euler[1].abs()).fold(0.0, f64::max),
            height_max: truth
                .iter()
                .map(|s| s.position.z)
                .fold(f64::NEG_INFINITY, f64::max),
            samples: truth.len(),
        }
    }
}

fn max(v: &[f64]) -> Option<f64> {
    v.iter().copied().reduce(f64::max)
}

fn mean(v: &[f64]) -> Option<f64> {
    (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64)
}

fn rms(v: &[f64]) -> Option<f64> {
    (!v.is_empty()).then(|| (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn window(target: [f64; 3]) -> Window {
        Window {
            name: "step".into(),
            from: 0.0,
            to: 3.0,
            target: Some(target),
            settle_band: 0.1,
        }
    }

    #[test]
    fn settling_overshoot_and_hold_of_a_step_north() {
        let mut r = FlightRecord::new(Home::default());
        // North from 0 to 1 m: 0.0 .. 1.2 (overshoot) .. back to 1.0 from t = 2.
        for k in 0..=300 {
            let t = k as f64 * 0.01;
            let north = if t < 1.0 {
                1.2 * t
            } else if t < 2.0 {
                1.2 - 0.2 * (t - 1.0)
            } else {
                1.0
            };
            // tvmd x is north, z up.
            r.truth(t, &PlantState::at_rest(Vector3::new(north, 0.0, 1.5)));
        }
        let w = r.window(&window([1.0, 0.0, 1.5]));
        // Inside 0.1 m from 1.5 s (1.2 - 0.2 * 0.5 = 1.1) on.
        let settle = w.settling_time.unwrap();
        assert!((settle - 1.51).abs() < 0.011, "{settle}");
        assert!((w.overshoot.unwrap() - 0.2).abs() < 1e-9);
        assert!((w.hold_max.unwrap() - 1.0).abs() < 1e-9);
    }

    #[test]
    fn estimate_errors_are_measured_in_the_estimators_frame() {
        let home = Home::default();
        let mut r = FlightRecord::new(home);
        // The estimator's origin 2 m north of home and 1 m up; the team 3 m north, 1.5 m up.
        let (lat, lon) = home.reproject(2.0, 0.0);
        r.telemetry(
            0.0,
            Telemetry::Origin {
                latitude: lat,
                longitude: lon,
                altitude: home.altitude + 1.0,
            },
        );
        r.truth(1.0, &PlantState::at_rest(Vector3::new(3.0, 0.0, 1.5)));
        // PX4 says 1.05 m north and 0.5 m up of its origin: 5 cm off.
        r.telemetry(
            1.0,
            Telemetry::LocalPosition {
                t: 1.0,
                position: [1.05, 0.0, -0.5],
            },
        );
        r.telemetry(
            1.0,
            Telemetry::Attitude {
                t: 1.0,
                q: [1.0, 0.0, 0.0, 0.0],
            },
        );
        let w = r.window(&Window {
            target: None,
            ..window([0.0; 3])
        });
        assert!(
            (w.ekf_position_max.unwrap() - 0.05).abs() < 1e-6,
            "{:?}",
            w.ekf_position_max
        );
        assert!(w.ekf_attitude_max.unwrap() < 1e-6);
    }

    #[test]
    fn events_follow_px4s_state() {
        let mut r = FlightRecord::new(Home::default());
        r.px4_state(1.0, false, 1, true);
        r.px4_state(2.0, true, 1, true);
        r.px4_state(3.0, true, 2, true);
        r.px4_state(9.0, true, 1, true);
        r.px4_state(10.0, false, 1, true);
        let e = r.events();
        assert_eq!(
            (e.armed, e.airborne, e.landed, e.disarmed),
            (Some(2.0), Some(3.0), Some(9.0), Some(10.0))
        );
    }
}
