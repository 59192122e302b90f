//! Small math helpers shared by the simulator (nalgebra types).

use nalgebra::{Matrix3, Rotation3, UnitQuaternion, Vector3};

/// The skew-symmetric cross-product matrix `[v]x`, such that `[v]x w = v x w`.
pub fn skew(v: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -v.z, v.y, v.z, 0.0, -v.x, -v.y, v.x, 0.0)
}

/// `R_z(m pi/2)`, exact for whole quarter turns (the core's, shared by plant and controller).
pub fn quarter_turn(m: i32) -> Matrix3<f64> {
    tvmd_core::effectiveness::quarter_turn(m)
}

/// Rotation about the world x axis by `angle` (roll).
pub fn rot_x(angle: f64) -> Matrix3<f64> {
    let (s, c) = angle.sin_cos();
    Matrix3::new(1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c)
}

/// The rotation `R = R_z(yaw) R_y(pitch) R_x(roll)` of roll, pitch and yaw (ZYX).
pub fn from_roll_pitch_yaw([roll, pitch, yaw]: [f64; 3]) -> Matrix3<f64> {
    Rotation3::from_euler_angles(roll, pitch, yaw).into_inner()
}

/// Roll, pitch, yaw (ZYX) of `r`, the inverse of [`from_roll_pitch_yaw`] away from gimbal lock.
pub fn roll_pitch_yaw(r: &Matrix3<f64>) -> [f64; 3] {
    let (roll, pitch, yaw) = Rotation3::from_matrix_unchecked(*r).euler_angles();
    [roll, pitch, yaw]
}

/// Unit quaternion of a rotation matrix (the matrix is re-orthonormalised first).
pub fn quaternion_of(r: &Matrix3<f64>) -> UnitQuaternion<f64> {
    UnitQuaternion::from_matrix(r)
}

/// Unit quaternion of a rotation matrix by Shepperd's closed form, for matrices that are
/// rotations to rounding (the plant's, built from rapier's unit quaternion): it skips the
/// iterative re-orthonormalisation of [`quaternion_of`], the dearer part of a logged tick.
pub fn rotation_quaternion(r: &Matrix3<f64>) -> UnitQuaternion<f64> {
    UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(*r))
}

/// Converts a nalgebra matrix to a row-major array.
pub fn to_rows(m: &Matrix3<f64>) -> [[f64; 3]; 3] {
    [
        [m[(0, 0)], m[(0, 1)], m[(0, 2)]],
        [m[(1, 0)], m[(1, 1)], m[(1, 2)]],
        [m[(2, 0)], m[(2, 1)], m[(2, 2)]],
    ]
}

/// Converts a row-major array to a nalgebra matrix.
pub fn from_rows(rows: &[[f64; 3]; 3]) -> Matrix3<f64> {
    Matrix3::new(
        rows[0][0], rows[0][1], rows[0][2], rows[1][0], rows[1][1], rows[1][2], rows[2][0],
        rows[2][1], rows[2][2],
    )
}

/// The planned roll `phi_d = atan2(R_d[2,1], R_d[2,2])` (rad): the core's
/// [`tvmd_core::rotation::roll_angle`].
pub fn planned_roll(r_d: &Matrix3<f64>) -> f64 {
    tvmd_core::rotation::roll_angle(r_d)
}

/// Tilt of a rotation: angle between body z and world z (rad).
pub fn tilt_angle(r: &Matrix3<f64>) -> f64 {
    r[(2, 2)].clamp(-1.0, 1.0).acos()
}

/// Angle of the rotation `R_a^T R_b` (geodesic distance on SO(3)), in radians.
pub fn rotation_distance(a: &Matrix3<f64>, b: &Matrix3<f64>) -> f64 {
    let c = ((a.transpose() * b).trace() - 1.0) / 2.0;
    c.clamp(-1.0, 1.0).acos()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quarter_turns_match_trigonometry() {
        for m in -5..=5 {
            let a = m as f64 * std::f64::consts::FRAC_PI_2;
            let r = Rotation3::from_axis_angle(&Vector3::z_axis(), a);
            assert!(
                (quarter_turn(m) - r.matrix()).abs().max() < 1e-15,
                "m = {m}"
            );
        }
    }

    #[test]
    fn skew_is_cross_product() {
        let v = Vector3::new(0.3, -1.2, 2.0);
        let w = Vector3::new(-0.7, 0.4, 1.1);
        assert!((skew(&v) * w - v.cross(&w)).norm() < 1e-15);
    }

    #[test]
    fn roll_pitch_yaw_of_roll() {
        let rpy = roll_pitch_yaw(&rot_x(0.4));
        assert!((rpy[0] - 0.4).abs() < 1e-12 && rpy[1].abs() < 1e-12 && rpy[2].abs() < 1e-12);
    }
}
