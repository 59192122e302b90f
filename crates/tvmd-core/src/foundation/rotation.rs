//! Rotations used across the stages: roll `R_x(phi)` and its angle, exact quarter turns
//! `R_z(m pi/2)`, and the hat / vee maps between `R^3` and skew-symmetric matrices.

use nalgebra::{Matrix3, Vector3};

use crate::foundation::error::InputError;
use crate::foundation::real::{lit, Real};

/// Checks that `r` is a rotation: finite ([`InputError::NonFinite`]), `R^T R = I` and
/// `det R = 1` within `1e-3` ([`InputError::NotRotation`]), both naming `field`. The one
/// rotation check of the crate (states, references, the planner's `R_r`): state estimators
/// renormalize, but not every period.
///
/// ```
/// use tvmd_core::nalgebra::Matrix3;
/// use tvmd_core::rotation::{roll, validate_rotation};
/// assert!(validate_rotation(&roll(0.3_f64), "r").is_ok());
/// assert!(validate_rotation(&(Matrix3::<f64>::identity() * 2.0), "r").is_err());
/// ```
pub fn validate_rotation<T: Real>(r: &Matrix3<T>, field: &'static str) -> Result<(), InputError> {
    if !r.iter().all(|x| x.is_finite()) {
        return Err(InputError::NonFinite { field });
    }
    let tol: T = lit(1e-3);
    let orthonormal = (r.transpose() * r - Matrix3::identity()).amax() <= tol;
    if orthonormal && (r.determinant() - T::one()).abs() <= tol {
        Ok(())
    } else {
        Err(InputError::NotRotation { field })
    }
}

/// `R_x(phi)`, a roll about the body `x` axis (the paper's stage-B reference).
///
/// ```
/// use tvmd_core::rotation::{roll, roll_angle};
/// let r = roll(0.4_f64);
/// assert!((roll_angle(&r) - 0.4).abs() < 1e-15);
/// ```
pub fn roll<T: Real>(phi: T) -> Matrix3<T> {
    let (s, c) = phi.sin_cos();
    let (o, i) = (T::zero(), T::one());
    Matrix3::new(i, o, o, o, c, -s, o, s, c)
}

/// The roll angle `phi = atan2(R[2,1], R[2,2])` of an attitude (rad), e.g. the planned roll of
/// `R_d` that the simulator logs and the hover saturation law is stated in.
pub fn roll_angle<T: Real>(r: &Matrix3<T>) -> T {
    r.m32.atan2(r.m33)
}

/// `R_z(m pi/2)`, exact for whole quarter turns (the agent yaw `psi_i = m_i pi/2`).
///
/// ```
/// use tvmd_core::rotation::quarter_turn;
/// use tvmd_core::nalgebra::Vector3;
/// assert_eq!(quarter_turn::<f64>(1) * Vector3::x(), Vector3::y());
/// assert_eq!(quarter_turn::<f64>(-3), quarter_turn::<f64>(1));
/// ```
pub fn quarter_turn<T: Real>(quarter_turns: i32) -> Matrix3<T> {
    let (o, i) = (T::zero(), T::one());
    match quarter_turns.rem_euclid(4) {
        0 => Matrix3::identity(),
        1 => Matrix3::new(o, -i, o, i, o, o, o, o, i),
        2 => Matrix3::new(-i, o, o, o, -i, o, o, o, i),
        _ => Matrix3::new(o, i, o, -i, o, o, o, o, i),
    }
}

/// `[v]x`, the skew-symmetric matrix with `[v]x w = v x w`.
pub fn hat<T: Real>(v: &Vector3<T>) -> Matrix3<T> {
    v.cross_matrix()
}

/// `(A)^vee` of a skew-symmetric matrix, the inverse of [`hat`] (reads `A[2,1]`, `A[0,2]`,
/// `A[1,0]`).
pub fn vee<T: Real>(a: &Matrix3<T>) -> Vector3<T> {
    Vector3::new(a.m32, a.m13, a.m21)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vee_inverts_hat() {
        let v = Vector3::new(0.3, -1.2, 2.0);
        assert_eq!(vee(&hat(&v)), v);
    }

    #[test]
    fn quarter_turns_compose() {
        for m in -6..6 {
            let composed = quarter_turn::<f64>(m) * quarter_turn::<f64>(1);
            assert_eq!(composed, quarter_turn(m + 1), "m = {m}");
        }
    }

    #[test]
    fn roll_angle_of_a_roll() {
        for phi in [-3.0_f64, -1.0, 0.0, 0.5, 3.0] {
            assert!((roll_angle(&roll(phi)) - phi).abs() < 1e-15);
        }
    }
}
