//! tvmd's frames against PX4's.
//!
//! tvmd's world frame `{I}` is z up and its body frame `{C}` is x forward, y left, z up (FLU;
//! docs/method.md, "Frames and state"). PX4 works in NED (world) and FRD (body). The bridge
//! reads tvmd's world as **x north, y west, z up**, so that one matrix maps both:
//! `T = diag(1, -1, -1)` takes a world vector to NED and a body vector to FRD, and a rotation
//! `R` (body to world) becomes `T R T` (FRD to NED). A team at rest with the identity attitude
//! faces north in PX4.

use nalgebra::{Matrix3, Rotation3, UnitQuaternion, Vector3};

/// `T v`: a tvmd world vector (x north, y west, z up) in NED, or a tvmd body vector (FLU) in
/// FRD. `T` is its own inverse, so the same map goes back.
pub fn flip(v: &Vector3<f64>) -> Vector3<f64> {
    Vector3::new(v.x, -v.y, -v.z)
}

/// The attitude `R` (tvmd body to tvmd world) as PX4's FRD-to-NED rotation `T R T`.
pub fn rotation_ned_frd(r: &Matrix3<f64>) -> Matrix3<f64> {
    let t = Matrix3::from_diagonal(&Vector3::new(1.0, -1.0, -1.0));
    t * r * t
}

/// PX4's attitude quaternion `[w, x, y, z]` (FRD to NED, Hamilton, as HIL_STATE_QUATERNION and
/// `vehicle_attitude.q`) of the tvmd attitude `R`. Re-orthonormalised first: rapier's
/// rotation drifts from orthonormal by round-off only.
pub fn quaternion_ned_frd(r: &Matrix3<f64>) -> [f64; 4] {
    let rotation = Rotation3::from_matrix(&rotation_ned_frd(r));
    let q = UnitQuaternion::from_rotation_matrix(&rotation);
    // One sign: w >= 0 (q and -q are the same attitude).
    let s = if q.w < 0.0 { -1.0 } else { 1.0 };
    [s * q.w, s * q.i, s * q.j, s * q.k]
}

/// The tvmd attitude `R` of PX4's quaternion `[w, x, y, z]` (FRD to NED).
pub fn rotation_of_px4_quaternion(q: [f64; 4]) -> Matrix3<f64> {
    let q = UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(q[0], q[1], q[2], q[3]));
    rotation_ned_frd(q.to_rotation_matrix().matrix())
}

/// Roll, pitch, yaw (rad, ZYX) of PX4's FRD-to-NED rotation of the tvmd attitude `R`: the
/// Euler angles a PX4 user reads (yaw from north, clockwise seen from above).
pub fn euler_ned(r: &Matrix3<f64>) -> [f64; 3] {
    let (roll, pitch, yaw) = Rotation3::from_matrix(&rotation_ned_frd(r)).euler_angles();
    [roll, pitch, yaw]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: &[f64], b: &[f64]) -> bool {
        a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-12)
    }

    #[test]
    fn level_attitude_is_px4_identity() {
        assert!(close(
            &quaternion_ned_frd(&Matrix3::identity()),
            &[1.0, 0.0, 0.0, 0.0]
        ));
    }

    #[test]
    fn gravity_and_up_map_to_ned_down() {
        // Up in tvmd is -D in NED; north stays north; west is -east.
        assert!(close(flip(&Vector3::z()).as_slice(), &[0.0, 0.0, -1.0]));
        assert!(close(flip(&Vector3::y()).as_slice(), &[0.0, -1.0, 0.0]));
        assert!(close(flip(&Vector3::x()).as_slice(), &[1.0, 0.0, 0.0]));
    }

    #[test]
    fn positive_roll_keeps_its_sign_and_yaw_flips() {
        // A roll about tvmd's body x (forward) by +a: right wing ... in FLU the left side goes
        // up, in FRD the right side goes down: the same physical motion, the same +a roll.
        let a = 0.3;
        let roll = Rotation3::from_axis_angle(&Vector3::x_axis(), a);
        let e = euler_ned(roll.matrix());
        assert!(close(&e, &[a, 0.0, 0.0]), "{e:?}");
        // A positive pitch in FLU (nose down about +y left) is a positive pitch in FRD (nose
        // up about +y right)? No: about +y (left) the nose goes down, PX4 pitch -a.
        let pitch = Rotation3::from_axis_angle(&Vector3::y_axis(), a);
        assert!(close(&euler_ned(pitch.matrix()), &[0.0, -a, 0.0]));
        // A yaw to the left (counter-clockwise from above, about +z up) is a negative PX4 yaw.
        let yaw = Rotation3::from_axis_angle(&Vector3::z_axis(), a);
        assert!(close(&euler_ned(yaw.matrix()), &[0.0, 0.0, -a]));
    }

    #[test]
    fn quaternion_round_trips_and_rotates_like_the_matrix() {
        let r = Rotation3::from_euler_angles(0.2, -0.4, 1.1);
        let q = quaternion_ned_frd(r.matrix());
        assert!((rotation_of_px4_quaternion(q) - r.matrix()).norm() < 1e-12);
        // A body vector rotated in tvmd, then flipped, equals the flipped vector rotated by
        // PX4's quaternion.
        let v = Vector3::new(0.3, -1.2, 2.0);
        let px4 =
            UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(q[0], q[1], q[2], q[3]));
        assert!((flip(&(r * v)) - px4 * flip(&v)).norm() < 1e-12);
    }
}
