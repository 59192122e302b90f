//! A flight file: what PX4 is told when (the script, in simulated time), how its controls map
//! onto the team, the sensors, the home point and the windows a flight is measured over.
//!
//! ```toml
//! [mapping]
//! layout = "quad"                      # or "authors", or channels = ["rotor:0", ...]
//! [sensors]
//! gps_horizontal_noise = 0.02
//! [[step]]
//! at = 10.0                            # simulated seconds
//! action = "arm"
//! [[step]]
//! at = 11.0
//! action = "takeoff"
//! altitude = 1.5                       # above home (m)
//! [[window]]
//! name = "hover"
//! from = 20.0
//! to = 25.0
//! target = [0.0, 0.0, 1.5]             # north, east, up (m) from home
//! ```
//!
//! Actions: `arm`, `disarm`, `takeoff` (`altitude`), `goto` (`north`, `east`, `altitude`:
//! DO_REPOSITION in hold mode), `land`, `mode` (`mode` = manual, stabilized, altitude,
//! position, hold, offboard), `param` (`name`, `value`, `integer`), `sticks` (`roll`, `pitch`,
//! `yaw` in `[-1, 1]`, `throttle` in `[0, 1]`: MANUAL_CONTROL from then on, 50 Hz), `release`
//! (no more stick input).

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::geo::Home;
use crate::mapping::MappingConfig;
use crate::sensors::SensorConfig;
use crate::Px4Error;

/// One scripted action.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "action", rename_all = "lowercase", deny_unknown_fields)]
pub enum Action {
    /// Arm (MAV_CMD_COMPONENT_ARM_DISARM 1).
    Arm,
    /// Disarm.
    Disarm,
    /// Take off to `altitude` metres above home (MAV_CMD_NAV_TAKEOFF).
    Takeoff {
        /// Metres above home.
        altitude: f64,
    },
    /// Fly to a point and hold there (MAV_CMD_DO_REPOSITION, switching to hold).
    Goto {
        /// Metres north of home.
        north: f64,
        /// Metres east of home.
        east: f64,
        /// Metres above home.
        altitude: f64,
    },
    /// Land where it is (MAV_CMD_NAV_LAND).
    Land,
    /// Switch PX4's mode.
    Mode {
        /// manual, stabilized, altitude, position, hold or offboard.
        mode: String,
    },
    /// Set a parameter.
    Param {
        /// The parameter.
        name: String,
        /// Its value.
        value: f64,
        /// An INT32 parameter (else REAL32).
        #[serde(default)]
        integer: bool,
    },
    /// Stick input from now on (MANUAL_CONTROL at 50 Hz).
    Sticks {
        /// Roll stick in `[-1, 1]`.
        #[serde(default)]
        roll: f64,
        /// Pitch stick in `[-1, 1]`.
        #[serde(default)]
        pitch: f64,
        /// Yaw stick in `[-1, 1]`.
        #[serde(default)]
        yaw: f64,
        /// Throttle in `[0, 1]` (0.5: hold altitude in PX4's altitude and position modes).
        #[serde(default = "half")]
        throttle: f64,
    },
    /// No more stick input.
    Release,
}

fn half() -> f64 {
    0.5
}

/// An action and when (simulated seconds). (A flattened action cannot deny unknown keys at
/// this level: the action's own variant does.)
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Step {
    /// Simulated time (s).
    pub at: f64,
    /// The action.
    #[serde(flatten)]
    pub action: Action,
}

/// A stretch of the flight measured on its own (hover hold, a step's settling, a tilt).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Window {
    /// Its name in the report.
    pub name: String,
    /// Start (simulated s).
    pub from: f64,
    /// End (simulated s).
    pub to: f64,
    /// The position PX4 was told to hold, north, east, up from home (m); the settling time and
    /// the hold are measured against it.
    #[serde(default)]
    pub target: Option<[f64; 3]>,
    /// The band of the settling time (m); 0.1.
    #[serde(default = "settle_band")]
    pub settle_band: f64,
}

fn settle_band() -> f64 {
    0.1
}

/// A flight file.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct FlightPlan {
    /// Free text.
    pub description: String,
    /// The controls' mapping.
    pub mapping: MappingConfig,
    /// The sensors.
    pub sensors: SensorConfig,
    /// The home point.
    pub home: Home,
    /// The script, in time order.
    pub step: Vec<Step>,
    /// The measured windows.
    pub window: Vec<Window>,
}

impl FlightPlan {
    /// Parses and checks a flight file's text.
    pub fn from_toml_str(text: &str) -> Result<Self, Px4Error> {
        let plan: Self = toml::from_str(text).map_err(|e| Px4Error::Config {
            field: "flight file".into(),
            reason: e.to_string(),
        })?;
        plan.check()?;
        Ok(plan)
    }

    /// Reads a flight file.
    pub fn from_file(path: &Path) -> Result<Self, Px4Error> {
        let text = std::fs::read_to_string(path).map_err(|e| Px4Error::FlightFile {
            path: path.display().to_string(),
            reason: e.to_string(),
        })?;
        Self::from_toml_str(&text).map_err(|e| Px4Error::FlightFile {
            path: path.display().to_string(),
            reason: e.to_string(),
        })
    }

    /// Steps in time order at finite times, windows with `from < to`, known modes, sticks in
    /// range.
    pub fn check(&self) -> Result<(), Px4Error> {
        let bad = |field: String, reason: String| Px4Error::Config { field, reason };
        let mut last = f64::NEG_INFINITY;
        for (i, s) in self.step.iter().enumerate() {
            if !(s.at.is_finite() && s.at >= last) {
                return Err(bad(
                    format!("step[{i}].at"),
                    format!(
                        "{} must be finite and not before the step above ({last})",
                        s.at
                    ),
                ));
            }
            last = s.at;
            match &s.action {
                Action::Mode { mode } if main_mode(mode).is_none() => {
                    return Err(bad(
                        format!("step[{i}].mode"),
                        format!("unknown mode `{mode}` (manual, stabilized, altitude, position, hold, offboard)"),
                    ))
                }
                Action::Sticks { roll, pitch, yaw, throttle }
                    if ![roll, pitch, yaw].iter().all(|v| v.is_finite() && v.abs() <= 1.0)
                        || !(0.0..=1.0).contains(throttle) =>
                {
                    return Err(bad(
                        format!("step[{i}]"),
                        "sticks: roll, pitch, yaw in [-1, 1], throttle in [0, 1]".into(),
                    ))
                }
                _ => {}
            }
        }
        for (i, w) in self.window.iter().enumerate() {
            if !(w.from.is_finite() && w.to.is_finite() && w.from < w.to) {
                return Err(bad(
                    format!("window[{i}]"),
                    format!("`{}`: from {} must be before to {}", w.name, w.from, w.to),
                ));
            }
        }
        self.sensors.check()
    }
}

/// PX4's (main mode, sub mode) of a mode's name.
pub fn main_mode(name: &str) -> Option<(u8, u8)> {
    use crate::gcs::px4_mode::*;
    Some(match name {
        "manual" => (MANUAL, 0),
        "stabilized" => (STABILIZED, 0),
        "altitude" => (ALTCTL, 0),
        "position" => (POSCTL, 0),
        "hold" => (AUTO, AUTO_LOITER),
        "offboard" => (OFFBOARD, 0),
        _ => return None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_flight_file_reads_its_steps_and_windows() {
        let plan = FlightPlan::from_toml_str(
            r#"
            [mapping]
            layout = "quad"
            [[step]]
            at = 1.0
            action = "arm"
            [[step]]
            at = 2.0
            action = "takeoff"
            altitude = 1.5
            [[step]]
            at = 3.0
            action = "sticks"
            roll = 0.2
            [[window]]
            name = "hover"
            from = 5.0
            to = 9.0
            target = [0.0, 0.0, 1.5]
            "#,
        )
        .unwrap();
        assert_eq!(plan.step[1].action, Action::Takeoff { altitude: 1.5 });
        assert_eq!(
            plan.step[2].action,
            Action::Sticks {
                roll: 0.2,
                pitch: 0.0,
                yaw: 0.0,
                throttle: 0.5
            }
        );
        assert_eq!(plan.window[0].settle_band, 0.1);
    }

    #[test]
    fn bad_flight_files_are_refused_by_field() {
        let err = |t: &str| FlightPlan::from_toml_str(t).unwrap_err().to_string();
        assert!(
            err("[[step]]\nat = 2.0\naction = \"arm\"\n[[step]]\nat = 1.0\naction = \"land\"")
                .contains("step[1].at")
        );
        assert!(
            err("[[step]]\nat = 1.0\naction = \"mode\"\nmode = \"acro\"").contains("unknown mode")
        );
        assert!(err("[[step]]\nat = 1.0\naction = \"fly\"").contains("flight file"));
        assert!(err("[[window]]\nname = \"w\"\nfrom = 2.0\nto = 1.0").contains("window[0]"));
        assert!(err("[[step]]\nat = 1.0\naction = \"sticks\"\nroll = 2.0").contains("sticks"));
    }
}
