//! The ground-station link: MAVLink over UDP to PX4's GCS port (18570 + instance), the way a
//! ground station commands PX4 SITL. The bridge sends heartbeats, commands, parameters and
//! stick input; it reads PX4's state (armed, landed state, mode), its estimate (local
//! position, attitude, the estimator's origin), its attitude setpoint and its status texts.

use std::io::ErrorKind;
use std::net::{Ipv4Addr, SocketAddr, UdpSocket};

use mavlink::dialects::common::*;
use mavlink::{MavHeader, MavlinkReader, MavlinkVersion};

use crate::Px4Error;

/// PX4's GCS port of instance 0 (`px4-rc.mavlink`: `udp_gcs_port_local`).
pub const GCS_BASE_PORT: u16 = 18570;

/// PX4's main modes (`custom_mode` bits 16-23 of its heartbeat; `px4_custom_mode.h`).
pub mod px4_mode {
    /// Manual.
    pub const MANUAL: u8 = 1;
    /// Altitude.
    pub const ALTCTL: u8 = 2;
    /// Position.
    pub const POSCTL: u8 = 3;
    /// Auto (with a sub mode).
    pub const AUTO: u8 = 4;
    /// Offboard.
    pub const OFFBOARD: u8 = 6;
    /// Stabilized.
    pub const STABILIZED: u8 = 7;
    /// Auto sub mode: loiter (hold).
    pub const AUTO_LOITER: u8 = 3;
}

/// The last state PX4 reported over the GCS link.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Px4State {
    /// Armed (heartbeat `base_mode`).
    pub armed: bool,
    /// The main mode (`custom_mode` bits 16-23).
    pub main_mode: u8,
    /// MAV_LANDED_STATE (0 unknown, 1 on ground, 2 in air, 3 taking off, 4 landing).
    pub landed_state: u8,
    /// Heartbeats received.
    pub heartbeats: u64,
}

/// One message of PX4's that the bridge keeps.
#[derive(Clone, Debug, PartialEq)]
pub enum Telemetry {
    /// LOCAL_POSITION_NED: PX4's time (s), position and velocity NED of the estimate.
    LocalPosition {
        /// PX4's time (s).
        t: f64,
        /// Position NED (m) from the estimator's origin.
        position: [f64; 3],
    },
    /// ATTITUDE_QUATERNION: PX4's time (s), the estimated attitude `[w, x, y, z]`.
    Attitude {
        /// PX4's time (s).
        t: f64,
        /// FRD to NED.
        q: [f64; 4],
    },
    /// ATTITUDE_TARGET: PX4's time (s), the attitude setpoint.
    AttitudeTarget {
        /// PX4's time (s).
        t: f64,
        /// FRD to NED.
        q: [f64; 4],
    },
    /// GPS_GLOBAL_ORIGIN: the estimator's origin.
    Origin {
        /// Latitude (deg).
        latitude: f64,
        /// Longitude (deg).
        longitude: f64,
        /// Altitude AMSL (m).
        altitude: f64,
    },
    /// STATUSTEXT: severity and text.
    Text {
        /// MAV_SEVERITY (0 emergency .. 7 debug).
        severity: u8,
        /// The text.
        text: String,
    },
    /// COMMAND_ACK: the command and its MAV_RESULT.
    Ack {
        /// MAV_CMD.
        command: u16,
        /// MAV_RESULT (0 accepted).
        result: u8,
    },
}

impl Telemetry {
    /// The message with its PX4 time moved by `dt` seconds (untimed messages unchanged).
    pub fn shifted(self, dt: f64) -> Self {
        match self {
            Self::LocalPosition { t, position } => Self::LocalPosition {
                t: t + dt,
                position,
            },
            Self::Attitude { t, q } => Self::Attitude { t: t + dt, q },
            Self::AttitudeTarget { t, q } => Self::AttitudeTarget { t: t + dt, q },
            other => other,
        }
    }

    /// The message if it carries no PX4 time, else `None`.
    pub fn untimed(self) -> Option<Self> {
        match self {
            Self::LocalPosition { .. } | Self::Attitude { .. } | Self::AttitudeTarget { .. } => {
                None
            }
            other => Some(other),
        }
    }
}

/// The UDP link to PX4's GCS port.
pub struct GcsLink {
    socket: UdpSocket,
    px4: SocketAddr,
    sequence: u8,
    state: Px4State,
    buffer: Vec<u8>,
    system: u8,
}

/// The bridge's MAVLink identity on the GCS link: a ground station (system 255, component 190).
const GCS_HEADER: MavHeader = MavHeader {
    system_id: 255,
    component_id: 190,
    sequence: 0,
};

impl GcsLink {
    /// A link from a free local port to the GCS port of PX4 instance `instance` on this
    /// machine (port 18570 + instance; PX4's system id is instance + 1).
    pub fn new(instance: u8) -> Result<Self, Px4Error> {
        let port = GCS_BASE_PORT + u16::from(instance);
        let io = |what: &str| {
            let what = format!("GCS link: {what}");
            move |source| Px4Error::Link { what, source }
        };
        let socket = UdpSocket::bind((Ipv4Addr::LOCALHOST, 0)).map_err(io("bind"))?;
        socket.set_nonblocking(true).map_err(io("non-blocking"))?;
        Ok(Self {
            socket,
            px4: SocketAddr::from((Ipv4Addr::LOCALHOST, port)),
            sequence: 0,
            state: Px4State::default(),
            buffer: vec![0; 65536],
            system: instance + 1,
        })
    }

    /// The state PX4 last reported.
    pub fn state(&self) -> &Px4State {
        &self.state
    }

    /// Sends one message to PX4 (a lost datagram is PX4's to miss, as over any GCS link).
    pub fn send(&mut self, message: &MavMessage) -> Result<(), Px4Error> {
        let header = MavHeader {
            sequence: self.sequence,
            ..GCS_HEADER
        };
        self.sequence = self.sequence.wrapping_add(1);
        let mut bytes = Vec::with_capacity(300);
        mavlink::write_versioned_msg(&mut bytes, MavlinkVersion::V2, header, message).map_err(
            |e| Px4Error::Link {
                what: "GCS link: encode".into(),
                source: std::io::Error::other(e.to_string()),
            },
        )?;
        match self.socket.send_to(&bytes, self.px4) {
            Ok(_) => Ok(()),
            // Nobody listens yet (PX4 still booting): ICMP refusals are not errors here.
            Err(e) if e.kind() == ErrorKind::ConnectionRefused => Ok(()),
            Err(source) => Err(Px4Error::Link {
                what: "GCS link: send".into(),
                source,
            }),
        }
    }

    /// A ground station's heartbeat.
    pub fn heartbeat(&mut self) -> Result<(), Px4Error> {
        self.send(&MavMessage::HEARTBEAT(HEARTBEAT_DATA {
            custom_mode: 0,
            mavtype: MavType::MAV_TYPE_GCS,
            autopilot: MavAutopilot::MAV_AUTOPILOT_INVALID,
            base_mode: MavModeFlag::empty(),
            system_status: MavState::MAV_STATE_ACTIVE,
            mavlink_version: 3,
        }))
    }

    /// COMMAND_LONG to PX4 (its system, component 1).
    pub fn command(&mut self, command: MavCmd, params: [f32; 7]) -> Result<(), Px4Error> {
        self.send(&MavMessage::COMMAND_LONG(COMMAND_LONG_DATA {
            target_system: self.system,
            target_component: 1,
            command,
            confirmation: 0,
            param1: params[0],
            param2: params[1],
            param3: params[2],
            param4: params[3],
            param5: params[4],
            param6: params[5],
            param7: params[6],
        }))
    }

    /// COMMAND_INT in the global frame (latitude and longitude in degE7, altitude AMSL), for
    /// positions a float cannot carry to the centimetre.
    pub fn command_global(
        &mut self,
        command: MavCmd,
        params: [f32; 4],
        lat_lon: [i32; 2],
        altitude: f32,
    ) -> Result<(), Px4Error> {
        self.send(&MavMessage::COMMAND_INT(COMMAND_INT_DATA {
            target_system: self.system,
            target_component: 1,
            frame: MavFrame::MAV_FRAME_GLOBAL,
            command,
            current: 0,
            autocontinue: 0,
            param1: params[0],
            param2: params[1],
            param3: params[2],
            param4: params[3],
            x: lat_lon[0],
            y: lat_lon[1],
            z: altitude,
        }))
    }

    /// PARAM_SET of a parameter as PX4 stores it (`integer`: INT32, else REAL32).
    pub fn set_param(&mut self, name: &str, value: f64, integer: bool) -> Result<(), Px4Error> {
        let mut id = [0u8; 16];
        for (d, s) in id.iter_mut().zip(name.bytes()) {
            *d = s;
        }
        // PX4 reads an INT32 parameter's bytes from the float field (MAVLink's bytewise encoding).
        let (param_value, param_type) = if integer {
            (
                f32::from_bits(value as i32 as u32),
                MavParamType::MAV_PARAM_TYPE_INT32,
            )
        } else {
            (value as f32, MavParamType::MAV_PARAM_TYPE_REAL32)
        };
        self.send(&MavMessage::PARAM_SET(PARAM_SET_DATA {
            target_system: self.system,
            target_component: 1,
            param_id: id.into(),
            param_value,
            param_type,
        }))
    }

    /// MANUAL_CONTROL: sticks in `[-1, 1]` (roll, pitch, yaw) and throttle in `[0, 1]`.
    pub fn manual(
        &mut self,
        roll: f64,
        pitch: f64,
        yaw: f64,
        throttle: f64,
    ) -> Result<(), Px4Error> {
        let s = |v: f64| (v.clamp(-1.0, 1.0) * 1000.0).round() as i16;
        self.send(&MavMessage::MANUAL_CONTROL(MANUAL_CONTROL_DATA {
            target: self.system,
            x: s(pitch),
            y: s(roll),
            z: (throttle.clamp(0.0, 1.0) * 1000.0).round() as i16,
            r: s(yaw),
            buttons: 0,
        }))
    }

    /// Every message PX4 has sent since the last call: the state is updated, the kept
    /// messages returned.
    pub fn poll(&mut self) -> Result<Vec<Telemetry>, Px4Error> {
        let mut out = Vec::new();
        loop {
            let n = match self.socket.recv_from(&mut self.buffer) {
                Ok((n, _)) => n,
                Err(e) if e.kind() == ErrorKind::WouldBlock => break,
                Err(e) if e.kind() == ErrorKind::ConnectionRefused => continue,
                Err(source) => {
                    return Err(Px4Error::Link {
                        what: "GCS link: receive".into(),
                        source,
                    })
                }
            };
            let datagram = self.buffer[..n].to_vec();
            let mut reader = MavlinkReader::new(datagram.as_slice());
            while let Ok((header, message)) = reader.read_any_message::<MavMessage>() {
                if header.system_id != u32::from(self.system) {
                    continue;
                }
                if let Some(t) = self.keep(&message, header.component_id) {
                    out.push(t);
                }
            }
        }
        Ok(out)
    }

    fn keep(&mut self, message: &MavMessage, component: u8) -> Option<Telemetry> {
        let ms = |t: u32| f64::from(t) * 1e-3;
        let q = |q: [f32; 4]| q.map(f64::from);
        match message {
            MavMessage::HEARTBEAT(h) if component == 1 => {
                self.state.armed = h
                    .base_mode
                    .contains(MavModeFlag::MAV_MODE_FLAG_SAFETY_ARMED);
                self.state.main_mode = ((h.custom_mode >> 16) & 0xff) as u8;
                self.state.heartbeats += 1;
                None
            }
            MavMessage::EXTENDED_SYS_STATE(s) => {
                self.state.landed_state = s.landed_state as u8;
                None
            }
            MavMessage::LOCAL_POSITION_NED(p) => Some(Telemetry::LocalPosition {
                t: ms(p.time_boot_ms),
                position: [p.x, p.y, p.z].map(f64::from),
            }),
            MavMessage::ATTITUDE_QUATERNION(a) => Some(Telemetry::Attitude {
                t: ms(a.time_boot_ms),
                q: q([a.q1, a.q2, a.q3, a.q4]),
            }),
            MavMessage::ATTITUDE_TARGET(a) => Some(Telemetry::AttitudeTarget {
                t: ms(a.time_boot_ms),
                q: q(a.q),
            }),
            MavMessage::GPS_GLOBAL_ORIGIN(o) => Some(Telemetry::Origin {
                latitude: f64::from(o.latitude) * 1e-7,
                longitude: f64::from(o.longitude) * 1e-7,
                altitude: f64::from(o.altitude) * 1e-3,
            }),
            MavMessage::STATUSTEXT(s) => Some(Telemetry::Text {
                severity: s.severity as u8,
                text: s
                    .text
                    .to_str()
                    .unwrap_or_default()
                    .trim_end_matches('\0')
                    .to_string(),
            }),
            MavMessage::COMMAND_ACK(a) => Some(Telemetry::Ack {
                command: a.command as u16,
                result: a.result as u8,
            }),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_shift_moves_the_timed_messages_only_and_untimed_keeps_the_untimed() {
        let position = Telemetry::LocalPosition {
            t: 1000.5,
            position: [1.0, 2.0, 3.0],
        };
        assert_eq!(
            position.clone().shifted(-1000.0),
            Telemetry::LocalPosition {
                t: 0.5,
                position: [1.0, 2.0, 3.0]
            }
        );
        let q = [1.0, 0.0, 0.0, 0.0];
        assert_eq!(
            Telemetry::Attitude { t: 3.0, q }.shifted(2.0),
            Telemetry::Attitude { t: 5.0, q }
        );
        assert_eq!(
            Telemetry::AttitudeTarget { t: 3.0, q }.shifted(-1.0),
            Telemetry::AttitudeTarget { t: 2.0, q }
        );
        let text = Telemetry::Text {
            severity: 6,
            text: "Takeoff detected".into(),
        };
        assert_eq!(text.clone().shifted(5.0), text);
        assert_eq!(text.clone().untimed(), Some(text));
        assert_eq!(position.untimed(), None);
        assert_eq!(Telemetry::Attitude { t: 3.0, q }.untimed(), None);
    }
}
