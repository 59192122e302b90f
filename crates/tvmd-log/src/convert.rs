//! Conversions to the Foxglove SDK's message types and times.

use foxglove::messages::{FrameTransform, Quaternion, Vector3 as FgVector3};
use nalgebra::{Matrix3, UnitQuaternion, Vector3};

/// The pose of frame `team` in frame `world` at `t` as `foxglove.FrameTransform`.
pub fn frame_transform(t: f64, position: &Vector3<f64>, rotation: &Matrix3<f64>) -> FrameTransform {
    FrameTransform {
        timestamp: Some(timestamp(t)),
        parent_frame_id: "world".into(),
        child_frame_id: "team".into(),
        translation: Some(fg_vector(position)),
        rotation: Some(fg_quaternion(&tvmd_plant::math::rotation_quaternion(
            rotation,
        ))),
    }
}

/// `t` (s) as non-negative nanoseconds (0 for negative or non-finite times).
pub fn nanos(t: f64) -> u64 {
    if t.is_finite() && t > 0.0 {
        (t * 1e9).round() as u64
    } else {
        0
    }
}

/// `t` (s) as a Foxglove timestamp.
pub fn timestamp(t: f64) -> foxglove::messages::Timestamp {
    let ns = nanos(t);
    foxglove::messages::Timestamp::new(
        u32::try_from(ns / 1_000_000_000).unwrap_or(u32::MAX),
        (ns % 1_000_000_000) as u32,
    )
}

/// A nalgebra vector as `foxglove.Vector3`.
pub fn fg_vector(v: &Vector3<f64>) -> FgVector3 {
    FgVector3 {
        x: v.x,
        y: v.y,
        z: v.z,
    }
}

/// A unit quaternion as `foxglove.Quaternion`.
pub fn fg_quaternion(q: &UnitQuaternion<f64>) -> Quaternion {
    Quaternion {
        x: q.i,
        y: q.j,
        z: q.k,
        w: q.w,
    }
}
