//! The simulator's MAVLink messages: HIL_SENSOR, HIL_GPS and HIL_STATE_QUATERNION from the
//! sensor readings, the controls and the armed flag of PX4's HIL_ACTUATOR_CONTROLS.

use mavlink::dialects::common::{
    HilActuatorControlsFlags, HilSensorUpdatedFlags, MavMessage, MavModeFlag, HIL_GPS_DATA,
    HIL_SENSOR_DATA, HIL_STATE_QUATERNION_DATA,
};

use crate::mapping::CONTROLS;
use crate::sensors::{GpsReading, ImuReading, TruthReading};

/// PX4's simulator clock starts at this tvmd time offset: HIL_SENSOR's `time_usec` is
/// `t + TIME_OFFSET_US` (PX4 reads a zero time as unset).
pub const TIME_OFFSET_US: u64 = 1;

/// The `time_usec` of simulation time `t` (s).
pub fn time_usec(t: f64) -> u64 {
    (t * 1e6).round() as u64 + TIME_OFFSET_US
}

/// The simulation time (s) of a PX4 `time_usec`.
pub fn time_of_usec(time_usec: u64) -> f64 {
    time_usec.saturating_sub(TIME_OFFSET_US) as f64 * 1e-6
}

/// HIL_SENSOR of one IMU reading.
pub fn hil_sensor(time: u64, r: &ImuReading) -> MavMessage {
    MavMessage::HIL_SENSOR(HIL_SENSOR_DATA {
        time_usec: time,
        xacc: r.accel[0],
        yacc: r.accel[1],
        zacc: r.accel[2],
        xgyro: r.gyro[0],
        ygyro: r.gyro[1],
        zgyro: r.gyro[2],
        xmag: r.mag[0],
        ymag: r.mag[1],
        zmag: r.mag[2],
        abs_pressure: r.pressure,
        diff_pressure: 0.0,
        pressure_alt: r.pressure_alt,
        temperature: r.temperature,
        fields_updated: HilSensorUpdatedFlags::from_bits_truncate(r.fields_updated),
        ..Default::default()
    })
}

/// HIL_GPS of one fix (3-D fix, 10 satellites, eph 0.3 m, epv 0.4 m).
pub fn hil_gps(time: u64, g: &GpsReading) -> MavMessage {
    MavMessage::HIL_GPS(HIL_GPS_DATA {
        time_usec: time,
        fix_type: 3,
        lat: g.lat,
        lon: g.lon,
        alt: g.alt,
        eph: 30,
        epv: 40,
        vel: g.speed,
        vn: g.vel_ned[0],
        ve: g.vel_ned[1],
        vd: g.vel_ned[2],
        cog: g.cog,
        satellites_visible: 10,
        ..Default::default()
    })
}

/// HIL_STATE_QUATERNION of the ground truth.
pub fn hil_state(time: u64, s: &TruthReading) -> MavMessage {
    MavMessage::HIL_STATE_QUATERNION(HIL_STATE_QUATERNION_DATA {
        time_usec: time,
        attitude_quaternion: s.q,
        rollspeed: s.rates[0],
        pitchspeed: s.rates[1],
        yawspeed: s.rates[2],
        lat: s.lat_lon_alt[0],
        lon: s.lat_lon_alt[1],
        alt: s.lat_lon_alt[2],
        vx: s.vel_ned[0],
        vy: s.vel_ned[1],
        vz: s.vel_ned[2],
        ind_airspeed: 0,
        true_airspeed: 0,
        xacc: s.accel_mg[0],
        yacc: s.accel_mg[1],
        zacc: s.accel_mg[2],
    })
}

/// PX4's actuator message: its time, the 16 controls, armed, lockstep.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Controls {
    /// PX4's time of the outputs (us).
    pub time_usec: u64,
    /// The controls (motors in `[0, 1]`, servos in `[-1, 1]`, zero while disarmed).
    pub controls: [f32; CONTROLS],
    /// PX4 is armed.
    pub armed: bool,
    /// PX4 runs in lockstep (flags bit 0).
    pub lockstep: bool,
}

/// The controls of a HIL_ACTUATOR_CONTROLS message, `None` for any other message.
pub fn controls_of(message: &MavMessage) -> Option<Controls> {
    match message {
        MavMessage::HIL_ACTUATOR_CONTROLS(m) => Some(Controls {
            time_usec: m.time_usec,
            controls: m.controls,
            armed: m.mode.contains(MavModeFlag::MAV_MODE_FLAG_SAFETY_ARMED),
            lockstep: m
                .flags
                .contains(HilActuatorControlsFlags::HIL_ACTUATOR_CONTROLS_FLAGS_LOCKSTEP),
        }),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mavlink::dialects::common::HIL_ACTUATOR_CONTROLS_DATA;

    #[test]
    fn time_round_trips_and_never_sends_zero() {
        assert_eq!(time_usec(0.0), 1);
        assert_eq!(time_usec(0.004), 4001);
        assert!((time_of_usec(time_usec(12.348)) - 12.348).abs() < 1e-9);
    }

    #[test]
    fn controls_read_armed_and_lockstep() {
        let m = MavMessage::HIL_ACTUATOR_CONTROLS(HIL_ACTUATOR_CONTROLS_DATA {
            time_usec: 42,
            controls: [0.5; CONTROLS],
            mode: MavModeFlag::MAV_MODE_FLAG_SAFETY_ARMED
                | MavModeFlag::MAV_MODE_FLAG_CUSTOM_MODE_ENABLED,
            flags: HilActuatorControlsFlags::HIL_ACTUATOR_CONTROLS_FLAGS_LOCKSTEP,
        });
        let c = controls_of(&m).unwrap();
        assert!(c.armed && c.lockstep && c.time_usec == 42 && c.controls[15] == 0.5);
        assert!(controls_of(&hil_gps(
            1,
            &GpsReading {
                lat: 0,
                lon: 0,
                alt: 0,
                vel_ned: [0; 3],
                speed: 0,
                cog: 0
            }
        ))
        .is_none());
    }
}
