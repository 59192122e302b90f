//! MCAP logs: one JSON channel per message kind plus Foxglove 3D messages.
//!
//! Channels (all `message_encoding = "json"`, schemas `encoding = "jsonschema"`):
//!
//! | topic | schema name | content |
//! |---|---|---|
//! | `/state` | `tvmd.State` | true state of the team |
//! | `/reference` | `tvmd.Reference` | reference trajectory |
//! | `/planner` | `tvmd.Planner` | attitude planner diagnostics |
//! | `/control` | `tvmd.Control` | control-law diagnostics (and skipped cycles in `extra`) |
//! | `/allocation` | `tvmd.Allocation` | allocation diagnostics (`e_f`) |
//! | `/actuators` | `tvmd.Actuators` | commanded and actual agent commands, failures |
//! | `/lyapunov` | `tvmd.Lyapunov` | `V_x`, `V_R` |
//! | `/hover` | `tvmd.Hover` | hover classification when the failure mask changes |
//! | `/tf` | `foxglove.FrameTransform` | pose of frame `team` in frame `world` |
//! | `/scene` | `foxglove.SceneUpdate` | one entity per agent (cube at `p_i`, thrust arrow) |
//!
//! A metadata record [`METADATA_SCENARIO`] may hold the scenario of the run.
//!
//! Every message carries the simulation time `t` (s), and its MCAP log/publish time is `t`
//! in nanoseconds. The file is finalised by [`McapLog::finish`] and, if that was not called
//! (an error or a panic unwound the caller), by `Drop`, so it is never left truncated.

use std::collections::BTreeMap;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::Path;

use mcap::records::MessageHeader;
use nalgebra::{Matrix3, UnitQuaternion, Vector3};
use serde::Serialize;
use serde_json::{json, Value};

use crate::actuators::ActuatorCommand;
use crate::physics::TeamBody;
use crate::SimError;

/// Name of the metadata record holding the scenario of a run: keys `name`, `relaxation`,
/// `allocator` and `toml` (the whole scenario as TOML).
pub const METADATA_SCENARIO: &str = "tvmd.scenario";

/// The message kinds of a simulation log (one channel each).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum LogKind {
    /// True state ([`StateMsg`]).
    State,
    /// Reference ([`ReferenceMsg`]).
    Reference,
    /// Planner diagnostics ([`crate::diagnostics::PlannerDiagnostics`]).
    Planner,
    /// Control-law diagnostics ([`crate::diagnostics::ControlDiagnostics`]).
    Control,
    /// Allocation diagnostics ([`crate::diagnostics::AllocationDiagnostics`]).
    Allocation,
    /// Actuators ([`ActuatorsMsg`]).
    Actuators,
    /// Lyapunov candidates ([`crate::diagnostics::LyapunovDiagnostics`]).
    Lyapunov,
    /// Hover classification ([`crate::diagnostics::HoverDiagnostics`]).
    Hover,
}

impl LogKind {
    /// All kinds, in channel order.
    pub const ALL: [LogKind; 8] = [
        LogKind::State,
        LogKind::Reference,
        LogKind::Planner,
        LogKind::Control,
        LogKind::Allocation,
        LogKind::Actuators,
        LogKind::Lyapunov,
        LogKind::Hover,
    ];

    /// The channel's topic.
    pub fn topic(self) -> &'static str {
        match self {
            Self::State => "/state",
            Self::Reference => "/reference",
            Self::Planner => "/planner",
            Self::Control => "/control",
            Self::Allocation => "/allocation",
            Self::Actuators => "/actuators",
            Self::Lyapunov => "/lyapunov",
            Self::Hover => "/hover",
        }
    }

    /// The schema's name.
    pub fn schema_name(self) -> &'static str {
        match self {
            Self::State => "tvmd.State",
            Self::Reference => "tvmd.Reference",
            Self::Planner => "tvmd.Planner",
            Self::Control => "tvmd.Control",
            Self::Allocation => "tvmd.Allocation",
            Self::Actuators => "tvmd.Actuators",
            Self::Lyapunov => "tvmd.Lyapunov",
            Self::Hover => "tvmd.Hover",
        }
    }

    /// The JSON schema of the channel's messages.
    pub fn schema(self) -> Value {
        let num = json!({"type": "number"});
        let v3 =
            json!({"type": "array", "items": {"type": "number"}, "minItems": 3, "maxItems": 3});
        let v6 =
            json!({"type": "array", "items": {"type": "number"}, "minItems": 6, "maxItems": 6});
        let m3 = json!({"type": "array", "items": v3, "minItems": 3, "maxItems": 3,
                        "description": "row-major 3x3 matrix"});
        let cmd = json!({"type": "object", "properties": {
            "eta_x": num, "eta_y": num, "thrust": num}});
        let (props, required): (Value, Vec<&str>) = match self {
            Self::State => (
                json!({"t": num, "position": v3, "velocity": v3, "velocity_body": v3,
                       "orientation": quaternion_schema(), "rotation": m3,
                       "roll_pitch_yaw": v3, "omega": v3}),
                vec!["t", "position", "velocity", "orientation", "omega"],
            ),
            Self::Reference => (
                json!({"t": num, "position": v3, "velocity": v3, "acceleration": v3,
                       "rotation": m3, "omega": v3, "roll": num, "roll_rate": num}),
                vec!["t", "position", "velocity", "acceleration", "rotation"],
            ),
            Self::Planner => (
                json!({"t": num, "r_d": m3, "planned_roll_pitch_yaw": v3, "theta": num,
                       "t_tf": num, "t_eta": num, "reference_feasible": {"type": "boolean"},
                       "planned_roll": num, "status": {"type": "string"},
                       "iterations": {"type": "integer"}}),
                vec!["t"],
            ),
            Self::Control => (
                json!({"t": num, "u_r": v6, "u_d": v6, "e_x": v3, "e_v": v3, "e_r": v3,
                       "e_omega": v3, "t_tf": num, "t_eta": num, "extra": {}}),
                vec!["t"],
            ),
            Self::Allocation => (
                json!({"t": num, "wrench": v6, "e_f": num,
                       "saturated": {"type": "array", "items": {"type": "boolean"}},
                       "wrench_error": num, "rounds": {"type": "integer"},
                       "fallback": {"type": "boolean"},
                       "forces": {"type": "array", "items": v3},
                       "rotor_speeds": {"type": "array", "items": num}}),
                vec!["t", "e_f"],
            ),
            Self::Actuators => (
                json!({"t": num,
                       "commanded": {"type": "array", "items": cmd},
                       "actual": {"type": "array", "items": cmd},
                       "failed": {"type": "array", "items": {"type": "boolean"}},
                       "forces_body": {"type": "array", "items": v3}}),
                vec!["t", "commanded", "actual", "failed"],
            ),
            Self::Lyapunov => (json!({"t": num, "v_x": num, "v_r": num}), vec!["t"]),
            Self::Hover => (
                json!({"t": num, "capable": {"type": "boolean"}, "margin": num,
                       "limiting_agent": {"type": ["integer", "null"]},
                       "limit": {"type": "string"}, "landing": {"type": "boolean"}}),
                vec!["t", "capable", "margin"],
            ),
        };
        json!({"title": self.schema_name(), "type": "object",
               "properties": props, "required": required})
    }
}

fn quaternion_schema() -> Value {
    let num = json!({"type": "number"});
    json!({"title": "foxglove.Quaternion", "type": "object",
           "properties": {"x": num, "y": num, "z": num, "w": num},
           "required": ["x", "y", "z", "w"]})
}

fn vector3_schema() -> Value {
    let num = json!({"type": "number"});
    json!({"title": "foxglove.Vector3", "type": "object",
           "properties": {"x": num, "y": num, "z": num}, "required": ["x", "y", "z"]})
}

fn time_schema() -> Value {
    json!({"type": "object", "title": "time", "properties": {
        "sec": {"type": "integer", "minimum": 0},
        "nsec": {"type": "integer", "minimum": 0, "maximum": 999_999_999}}})
}

fn color_schema() -> Value {
    let num = json!({"type": "number"});
    json!({"title": "foxglove.Color", "type": "object",
           "properties": {"r": num, "g": num, "b": num, "a": num},
           "required": ["r", "g", "b", "a"]})
}

fn pose_schema() -> Value {
    json!({"title": "foxglove.Pose", "type": "object", "properties": {
        "position": vector3_schema(), "orientation": quaternion_schema()},
        "required": ["position", "orientation"]})
}

/// JSON schema for `foxglove.FrameTransform` (the fields this crate writes).
pub fn frame_transform_schema() -> Value {
    json!({
        "title": "foxglove.FrameTransform",
        "description": "A transform between two reference frames in 3D space",
        "type": "object",
        "properties": {
            "timestamp": time_schema(),
            "parent_frame_id": {"type": "string"},
            "child_frame_id": {"type": "string"},
            "translation": vector3_schema(),
            "rotation": quaternion_schema()
        },
        "required": ["timestamp", "parent_frame_id", "child_frame_id", "translation", "rotation"]
    })
}

/// JSON schema for `foxglove.SceneUpdate` (entities with cubes and arrows, deletions).
pub fn scene_update_schema() -> Value {
    let num = json!({"type": "number"});
    let arrow = json!({"title": "foxglove.ArrowPrimitive", "type": "object", "properties": {
        "pose": pose_schema(), "shaft_length": num, "shaft_diameter": num,
        "head_length": num, "head_diameter": num, "color": color_schema()}});
    let cube = json!({"title": "foxglove.CubePrimitive", "type": "object", "properties": {
        "pose": pose_schema(), "size": vector3_schema(), "color": color_schema()}});
    let entity = json!({"title": "foxglove.SceneEntity", "type": "object", "properties": {
        "timestamp": time_schema(),
        "frame_id": {"type": "string"},
        "id": {"type": "string"},
        "lifetime": {"type": "object", "title": "duration", "properties": {
            "sec": {"type": "integer"}, "nsec": {"type": "integer", "minimum": 0}}},
        "frame_locked": {"type": "boolean"},
        "arrows": {"type": "array", "items": arrow},
        "cubes": {"type": "array", "items": cube}}});
    let deletion = json!({"title": "foxglove.SceneEntityDeletion", "type": "object",
        "properties": {"timestamp": time_schema(), "type": {"type": "integer"},
                       "id": {"type": "string"}}});
    json!({
        "title": "foxglove.SceneUpdate",
        "description": "An update to the entities displayed in a 3D scene",
        "type": "object",
        "properties": {
            "deletions": {"type": "array", "items": deletion},
            "entities": {"type": "array", "items": entity}
        }
    })
}

/// True state message (topic `/state`).
#[derive(Clone, Debug, Serialize)]
pub struct StateMsg {
    /// Time (s).
    pub t: f64,
    /// `x` (m).
    pub position: [f64; 3],
    /// `x_dot` (m/s).
    pub velocity: [f64; 3],
    /// `v = R^T x_dot` (m/s).
    pub velocity_body: [f64; 3],
    /// Attitude quaternion `{x, y, z, w}`.
    pub orientation: Quat,
    /// Attitude `R`, row-major.
    pub rotation: [[f64; 3]; 3],
    /// Roll, pitch, yaw (ZYX) (rad).
    pub roll_pitch_yaw: [f64; 3],
    /// Body angular velocity `Omega` (rad/s).
    pub omega: [f64; 3],
}

/// Reference message (topic `/reference`).
#[derive(Clone, Debug, Serialize)]
pub struct ReferenceMsg {
    /// Time (s).
    pub t: f64,
    /// `x_r` (m).
    pub position: [f64; 3],
    /// `x_r_dot` (m/s).
    pub velocity: [f64; 3],
    /// `x_r_ddot` (m/s^2).
    pub acceleration: [f64; 3],
    /// `R_r`, row-major.
    pub rotation: [[f64; 3]; 3],
    /// `Omega_d` (rad/s).
    pub omega: [f64; 3],
    /// `phi_r` (rad).
    pub roll: f64,
    /// `phi_r_dot` (rad/s).
    pub roll_rate: f64,
}

/// Actuator message (topic `/actuators`).
#[derive(Clone, Debug, Serialize)]
pub struct ActuatorsMsg {
    /// Time (s).
    pub t: f64,
    /// Commands from the controller (held).
    pub commanded: Vec<ActuatorCommand>,
    /// Actual actuator outputs.
    pub actual: Vec<ActuatorCommand>,
    /// Failure flags (true failure state, whether or not the controller is told).
    pub failed: Vec<bool>,
    /// Actual agent forces in the body frame (N).
    pub forces_body: Vec<[f64; 3]>,
}

/// A quaternion as Foxglove writes it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Quat {
    /// x.
    pub x: f64,
    /// y.
    pub y: f64,
    /// z.
    pub z: f64,
    /// w.
    pub w: f64,
}

impl Quat {
    /// From a rotation matrix.
    pub fn from_matrix(r: &Matrix3<f64>) -> Self {
        Self::from(UnitQuaternion::from_matrix(r))
    }
}

impl From<UnitQuaternion<f64>> for Quat {
    fn from(q: UnitQuaternion<f64>) -> Self {
        Self {
            x: q.i,
            y: q.j,
            z: q.k,
            w: q.w,
        }
    }
}

/// Adds `"t": t` in front of a serialized JSON object unless it starts with a `t` field (the
/// message types of this module do); wraps anything else as `{"t": t, "value": ...}`.
fn stamp(t: f64, body: Vec<u8>) -> Result<Vec<u8>, SimError> {
    if body.starts_with(b"{\"t\":") {
        return Ok(body);
    }
    let t_json = serde_json::to_vec(&t)?;
    let mut out = Vec::with_capacity(body.len() + t_json.len() + 16);
    match body.strip_prefix(b"{") {
        Some(rest) => {
            out.extend_from_slice(b"{\"t\":");
            out.extend_from_slice(&t_json);
            if rest != b"}" {
                out.push(b',');
            }
            out.extend_from_slice(rest);
        }
        None => {
            out.extend_from_slice(b"{\"t\":");
            out.extend_from_slice(&t_json);
            out.extend_from_slice(b",\"value\":");
            out.extend_from_slice(&body);
            out.push(b'}');
        }
    }
    Ok(out)
}

fn nanos(t: f64) -> u64 {
    if t.is_finite() && t > 0.0 {
        (t * 1e9).round() as u64
    } else {
        0
    }
}

fn time_json(t: f64) -> Value {
    let ns = nanos(t);
    json!({"sec": ns / 1_000_000_000, "nsec": ns % 1_000_000_000})
}

fn v3_json(v: &Vector3<f64>) -> Value {
    json!({"x": v.x, "y": v.y, "z": v.z})
}

fn q_json(q: &UnitQuaternion<f64>) -> Value {
    json!({"x": q.i, "y": q.j, "z": q.k, "w": q.w})
}

type McapWriter = mcap::Writer<BufWriter<File>>;

/// An MCAP log file with all channels registered up front.
pub struct McapLog {
    writer: Option<McapWriter>,
    channels: BTreeMap<LogKind, u16>,
    tf_channel: u16,
    scene_channel: u16,
    sequence: u32,
    messages: u64,
}

impl McapLog {
    /// Creates (truncates) `path`, its parent directories first, and registers every channel
    /// with its schema. I/O errors name the path ([`SimError::File`]).
    pub fn create(path: impl AsRef<Path>) -> Result<Self, SimError> {
        let path = path.as_ref();
        const ACTION: &str = "write the MCAP log";
        crate::paths::create_parent(path, ACTION)?;
        let file = BufWriter::new(File::create(path).map_err(SimError::file(ACTION, path))?);
        let mut w = mcap::WriteOptions::new()
            .profile("")
            .library(concat!("tvmd-sim ", env!("CARGO_PKG_VERSION")))
            .create(file)?;
        let meta = BTreeMap::new();
        let mut channels = BTreeMap::new();
        for kind in LogKind::ALL {
            let schema = serde_json::to_vec(&kind.schema())?;
            let sid = w.add_schema(kind.schema_name(), "jsonschema", &schema)?;
            channels.insert(kind, w.add_channel(sid, kind.topic(), "json", &meta)?);
        }
        let sid = w.add_schema(
            "foxglove.FrameTransform",
            "jsonschema",
            &serde_json::to_vec(&frame_transform_schema())?,
        )?;
        let tf_channel = w.add_channel(sid, "/tf", "json", &meta)?;
        let sid = w.add_schema(
            "foxglove.SceneUpdate",
            "jsonschema",
            &serde_json::to_vec(&scene_update_schema())?,
        )?;
        let scene_channel = w.add_channel(sid, "/scene", "json", &meta)?;
        Ok(Self {
            writer: Some(w),
            channels,
            tf_channel,
            scene_channel,
            sequence: 0,
            messages: 0,
        })
    }

    /// Writes an MCAP metadata record `name` with string key/value pairs (for example the
    /// scenario, see [`METADATA_SCENARIO`]).
    pub fn write_metadata(
        &mut self,
        name: &str,
        values: BTreeMap<String, String>,
    ) -> Result<(), SimError> {
        let w = self.writer.as_mut().ok_or(SimError::LogFinished)?;
        w.write_metadata(&mcap::records::Metadata {
            name: name.to_string(),
            metadata: values,
        })?;
        Ok(())
    }

    /// Number of messages written so far.
    pub fn message_count(&self) -> u64 {
        self.messages
    }

    fn write_raw(&mut self, channel: u16, t: f64, data: &[u8]) -> Result<(), SimError> {
        let w = self.writer.as_mut().ok_or(SimError::LogFinished)?;
        let time = nanos(t);
        w.write_to_known_channel(
            &MessageHeader {
                channel_id: channel,
                sequence: self.sequence,
                log_time: time,
                publish_time: time,
            },
            data,
        )?;
        self.sequence = self.sequence.wrapping_add(1);
        self.messages += 1;
        Ok(())
    }

    /// Writes `msg` (any serde type; a field `t` is added unless it has one) on the channel of
    /// `kind`.
    pub fn write<T: Serialize>(&mut self, kind: LogKind, t: f64, msg: &T) -> Result<(), SimError> {
        let data = stamp(t, serde_json::to_vec(msg)?)?;
        let channel = self.channels[&kind];
        self.write_raw(channel, t, &data)
    }

    /// Writes the pose of frame `team` in frame `world` (`foxglove.FrameTransform`).
    pub fn write_frame_transform(
        &mut self,
        t: f64,
        position: &Vector3<f64>,
        rotation: &Matrix3<f64>,
    ) -> Result<(), SimError> {
        let q = UnitQuaternion::from_matrix(rotation);
        let msg = json!({
            "timestamp": time_json(t),
            "parent_frame_id": "world",
            "child_frame_id": "team",
            "translation": v3_json(position),
            "rotation": q_json(&q),
        });
        let data = serde_json::to_vec(&msg)?;
        self.write_raw(self.tf_channel, t, &data)
    }

    /// Writes a `foxglove.SceneUpdate` with one entity per agent in frame `team`: a cube at
    /// `p_i` turned by `psi_i` (blue if `m_i` is even, orange if odd, red if failed) and an
    /// arrow along its body-frame force, `0.5 m` long at `max_thrust`; plus a grey navigator
    /// cube at the centre.
    pub fn write_scene(
        &mut self,
        t: f64,
        team: &TeamBody,
        forces_body: &[Vector3<f64>],
        failed: &[bool],
        max_thrust: f64,
    ) -> Result<(), SimError> {
        let stamp = time_json(t);
        let color = |r: f64, g: f64, b: f64| json!({"r": r, "g": g, "b": b, "a": 1.0});
        let mut entities = Vec::with_capacity(team.len() + 1);
        for (i, a) in team.agents.iter().enumerate() {
            let p = a.position_vector();
            let yaw = a.quarter_turns as f64 * std::f64::consts::FRAC_PI_2;
            let q_agent = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), yaw);
            let c = if failed.get(i).copied().unwrap_or(false) {
                color(0.9, 0.1, 0.1)
            } else if a.quarter_turns.rem_euclid(2) == 0 {
                color(0.2, 0.4, 0.9)
            } else {
                color(0.95, 0.55, 0.1)
            };
            let mut arrows = Vec::new();
            if let Some(f) = forces_body.get(i) {
                let n = f.norm();
                if n > 1e-9 && max_thrust > 0.0 {
                    let q =
                        UnitQuaternion::rotation_between(&Vector3::x(), f).unwrap_or_else(|| {
                            UnitQuaternion::from_axis_angle(
                                &Vector3::z_axis(),
                                std::f64::consts::PI,
                            )
                        });
                    let len = 0.5 * n / max_thrust;
                    arrows.push(json!({
                        "pose": {"position": v3_json(&p), "orientation": q_json(&q)},
                        "shaft_length": 0.8 * len, "shaft_diameter": 0.02,
                        "head_length": 0.2 * len, "head_diameter": 0.05,
                        "color": color(0.1, 0.8, 0.2)
                    }));
                }
            }
            entities.push(json!({
                "timestamp": stamp, "frame_id": "team", "id": format!("agent-{i}"),
                "lifetime": {"sec": 0, "nsec": 0}, "frame_locked": true,
                "cubes": [{"pose": {"position": v3_json(&p), "orientation": q_json(&q_agent)},
                           "size": {"x": 0.16, "y": 0.12, "z": 0.04}, "color": c}],
                "arrows": arrows,
            }));
        }
        entities.push(json!({
            "timestamp": stamp, "frame_id": "team", "id": "navigator",
            "lifetime": {"sec": 0, "nsec": 0}, "frame_locked": true,
            "cubes": [{"pose": {"position": {"x": 0.0, "y": 0.0, "z": 0.0},
                                "orientation": {"x": 0.0, "y": 0.0, "z": 0.0, "w": 1.0}},
                       "size": {"x": 0.1, "y": 0.1, "z": 0.05}, "color": color(0.5, 0.5, 0.5)}],
            "arrows": [],
        }));
        let data = serde_json::to_vec(&json!({"deletions": [], "entities": entities}))?;
        self.write_raw(self.scene_channel, t, &data)
    }

    /// Writes the summary and footer and flushes the file. Further writes fail with
    /// [`SimError::LogFinished`]; calling `finish` again is a no-op.
    pub fn finish(&mut self) -> Result<(), SimError> {
        if let Some(mut w) = self.writer.take() {
            w.finish()?;
            let mut file = w.into_inner();
            file.flush()?;
        }
        Ok(())
    }
}

impl Drop for McapLog {
    fn drop(&mut self) {
        // Best effort: finalise so the file stays a valid MCAP even on an error path.
        let _ = self.finish();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn messages_carry_one_t() {
        let parse = |b: Vec<u8>| serde_json::from_slice::<Value>(&b).unwrap();
        assert_eq!(
            parse(stamp(0.5, br#"{"a":1}"#.to_vec()).unwrap()),
            json!({"t": 0.5, "a": 1})
        );
        assert_eq!(
            parse(stamp(0.5, b"{}".to_vec()).unwrap()),
            json!({"t": 0.5})
        );
        let own = br#"{"t":0.25,"a":1}"#.to_vec();
        assert_eq!(stamp(0.5, own.clone()).unwrap(), own);
        assert_eq!(
            parse(stamp(0.5, b"[1,2]".to_vec()).unwrap()),
            json!({"t": 0.5, "value": [1, 2]})
        );
    }

    #[test]
    fn schemas_are_objects_with_titles() {
        for k in LogKind::ALL {
            assert_eq!(k.schema()["title"], k.schema_name());
        }
        assert_eq!(frame_transform_schema()["title"], "foxglove.FrameTransform");
        assert_eq!(scene_update_schema()["title"], "foxglove.SceneUpdate");
    }
}
