//! The flight script run over the GCS link in PX4's time: each step's action when its time has
//! come, a ground station's heartbeat every second and the stick input at 50 Hz while set.

use mavlink::dialects::common::MavCmd;

use crate::flight::{main_mode, Action, FlightPlan, Step};
use crate::gcs::GcsLink;
use crate::geo::Home;
use crate::Px4Error;

/// Stick input period (s): 50 Hz.
const STICK_PERIOD: f64 = 0.02;
/// Heartbeat period (s).
const HEARTBEAT_PERIOD: f64 = 1.0;

/// A flight script being run.
pub struct Script {
    steps: Vec<Step>,
    home: Home,
    next: usize,
    sticks: Option<[f64; 4]>,
    last_heartbeat: f64,
    last_sticks: f64,
}

impl Script {
    /// The script of `plan`, from its start.
    pub fn new(plan: &FlightPlan) -> Self {
        Self {
            steps: plan.step.clone(),
            home: plan.home,
            next: 0,
            sticks: None,
            last_heartbeat: f64::NEG_INFINITY,
            last_sticks: f64::NEG_INFINITY,
        }
    }

    /// Steps not run yet.
    pub fn remaining(&self) -> usize {
        self.steps.len() - self.next
    }

    /// Runs what is due at time `t` (s).
    pub fn advance(&mut self, t: f64, gcs: &mut GcsLink) -> Result<(), Px4Error> {
        if t - self.last_heartbeat >= HEARTBEAT_PERIOD - 1e-9 {
            gcs.heartbeat()?;
            self.last_heartbeat = t;
        }
        while let Some(step) = self.steps.get(self.next).filter(|s| s.at <= t + 1e-9) {
            let action = step.action.clone();
            self.next += 1;
            self.act(t, &action, gcs)?;
        }
        if let Some([roll, pitch, yaw, throttle]) = self.sticks {
            if t - self.last_sticks >= STICK_PERIOD - 1e-9 {
                gcs.manual(roll, pitch, yaw, throttle)?;
                self.last_sticks = t;
            }
        }
        Ok(())
    }

    fn act(&mut self, t: f64, action: &Action, gcs: &mut GcsLink) -> Result<(), Px4Error> {
        let home = self.home;
        let nan = f32::NAN;
        match action {
            Action::Arm => gcs.command(
                MavCmd::MAV_CMD_COMPONENT_ARM_DISARM,
                [1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
            ),
            Action::Disarm => gcs.command(MavCmd::MAV_CMD_COMPONENT_ARM_DISARM, [0.0; 7]),
            Action::Takeoff { altitude } => gcs.command(
                MavCmd::MAV_CMD_NAV_TAKEOFF,
                [
                    nan,
                    0.0,
                    0.0,
                    nan,
                    nan,
                    nan,
                    (home.altitude + altitude) as f32,
                ],
            ),
            Action::Goto {
                north,
                east,
                altitude,
            } => {
                let (lat, lon) = home.reproject(*north, *east);
                gcs.command_global(
                    MavCmd::MAV_CMD_DO_REPOSITION,
                    // Default ground speed, switch to hold, no radius, keep the yaw.
                    [-1.0, 1.0, 0.0, nan],
                    [(lat * 1e7).round() as i32, (lon * 1e7).round() as i32],
                    (home.altitude + altitude) as f32,
                )
            }
            Action::Land => gcs.command(
                MavCmd::MAV_CMD_NAV_LAND,
                [nan, 0.0, 0.0, nan, nan, nan, nan],
            ),
            Action::Mode { mode } => {
                let (main, sub) = main_mode(mode).ok_or_else(|| Px4Error::Script {
                    t,
                    reason: format!("unknown mode `{mode}`"),
                })?;
                gcs.command(
                    MavCmd::MAV_CMD_DO_SET_MODE,
                    [1.0, f32::from(main), f32::from(sub), 0.0, 0.0, 0.0, 0.0],
                )
            }
            Action::Param {
                name,
                value,
                integer,
            } => gcs.set_param(name, *value, *integer),
            Action::Sticks {
                roll,
                pitch,
                yaw,
                throttle,
            } => {
                self.sticks = Some([*roll, *pitch, *yaw, *throttle]);
                self.last_sticks = f64::NEG_INFINITY;
                Ok(())
            }
            Action::Release => {
                self.sticks = None;
                Ok(())
            }
        }
    }
}
