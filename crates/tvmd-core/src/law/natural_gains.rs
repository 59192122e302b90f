//! Gains stated as closed-loop natural frequencies and damping ratios per axis, scaled by the
//! team's mass `m_C` and inertia `J_C` (`docs/method.md#beyond-the-paper-gains-that-fit-any-team`).
//!
//! With the law of eq. (12) near the target (`R ~ R_d`, small errors) each axis is a
//! mass-spring-damper: `m_C e_x_ddot = -K_x e_x - K_v e_v` and `J_C e_R_ddot ~ -K_R e_R -
//! K_Omega e_Omega`. Choosing `K_x = m_C diag(w_x^2)`, `K_v = m_C diag(2 zeta_x w_x)` (and the
//! attitude alike with `J_C`) gives every team the same closed-loop poles, so the same settling
//! time, whatever its mass.

use nalgebra::{Matrix3, Vector3};

use crate::foundation::error::{positive, ConfigError, ConfigField};
use crate::foundation::real::Real;
use crate::law::Gains;

/// Closed-loop natural frequencies `w` (rad/s) and damping ratios `zeta` per axis of position
/// and attitude, validated (each finite and positive). [`NaturalGains::gains`] turns them into
/// the [`Gains`] of eq. (12) for one team.
///
/// ```
/// use tvmd_core::nalgebra::Matrix3;
/// use tvmd_core::NaturalGains;
/// let natural = NaturalGains::<f64>::uniform((1.0, 1.0), (6.0, 0.9))?;
/// let light = natural.gains(2.8, &Matrix3::identity())?;
/// let heavy = natural.gains(5.6, &(Matrix3::identity() * 2.0))?;
/// // Twice the mass, twice the gain: the same poles.
/// assert!((heavy.k_x() - light.k_x() * 2.0).norm() < 1e-12);
/// assert!((light.k_v()[(0, 0)] - 2.0 * 1.0 * 1.0 * 2.8).abs() < 1e-12);
/// # Ok::<(), tvmd_core::ConfigError>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NaturalGains<T: Real> {
    position_frequency: Vector3<T>,
    position_damping: Vector3<T>,
    attitude_frequency: Vector3<T>,
    attitude_damping: Vector3<T>,
}

impl<T: Real> NaturalGains<T> {
    /// Per-axis frequencies (rad/s) and damping ratios: position `(x, y, z)` in `{I}`, attitude
    /// `(roll, pitch, yaw)` in `{C}`.
    ///
    /// Errors: [`ConfigError::NonFinite`] or [`ConfigError::Parameter`] naming
    /// [`ConfigField::NaturalFrequency`] or [`ConfigField::DampingRatio`].
    pub fn new(
        position_frequency: [T; 3],
        position_damping: [T; 3],
        attitude_frequency: [T; 3],
        attitude_damping: [T; 3],
    ) -> Result<Self, ConfigError> {
        let check = |values: [T; 3], field| -> Result<Vector3<T>, ConfigError> {
            let [a, b, c] = values;
            Ok(Vector3::new(
                positive(a, field)?,
                positive(b, field)?,
                positive(c, field)?,
            ))
        };
        Ok(Self {
            position_frequency: check(position_frequency, ConfigField::NaturalFrequency)?,
            position_damping: check(position_damping, ConfigField::DampingRatio)?,
            attitude_frequency: check(attitude_frequency, ConfigField::NaturalFrequency)?,
            attitude_damping: check(attitude_damping, ConfigField::DampingRatio)?,
        })
    }

    /// The same `(w, zeta)` on every position axis and on every attitude axis.
    pub fn uniform(position: (T, T), attitude: (T, T)) -> Result<Self, ConfigError> {
        let (wx, zx) = position;
        let (wr, zr) = attitude;
        Self::new([wx; 3], [zx; 3], [wr; 3], [zr; 3])
    }

    /// Position natural frequencies `w_x` (rad/s).
    pub fn position_frequency(&self) -> Vector3<T> {
        self.position_frequency
    }

    /// Position damping ratios `zeta_x`.
    pub fn position_damping(&self) -> Vector3<T> {
        self.position_damping
    }

    /// Attitude natural frequencies `w_R` (rad/s).
    pub fn attitude_frequency(&self) -> Vector3<T> {
        self.attitude_frequency
    }

    /// Attitude damping ratios `zeta_R`.
    pub fn attitude_damping(&self) -> Vector3<T> {
        self.attitude_damping
    }

    /// The gains of eq. (12) for a team of mass `m_C` and inertia `J_C`:
    /// `K_x = m_C diag(w_x^2)`, `K_v = m_C diag(2 zeta_x w_x)`, `K_R = W J_C W` with
    /// `W = diag(w_R)`, `K_Omega = S J_C S` with `S = diag(sqrt(2 zeta_R w_R))`. For a diagonal
    /// `J_C` these are `J_C diag(w_R^2)` and `J_C diag(2 zeta_R w_R)`, exactly the per-axis
    /// poles; for a `J_C` with products of inertia the congruence keeps them symmetric positive
    /// definite (the poles then hold only approximately).
    ///
    /// Errors: as [`Gains::new`], except that a non-finite product (an overflow: frequencies
    /// or damping ratios too large for the team in this float type) is
    /// [`ConfigError::Overflow`] naming [`ConfigField::NaturalFrequency`], the input, and the
    /// gain in its quantity.
    pub fn gains(&self, mass: T, inertia: &Matrix3<T>) -> Result<Gains<T>, ConfigError> {
        let two = T::one() + T::one();
        let w = &self.position_frequency;
        let k_x = Matrix3::from_diagonal(&w.component_mul(w)) * mass;
        let k_v = Matrix3::from_diagonal(&(w.component_mul(&self.position_damping) * two)) * mass;
        let k_r = congruence(inertia, &self.attitude_frequency);
        let s = (self
            .attitude_frequency
            .component_mul(&self.attitude_damping)
            * two)
            .map(T::sqrt);
        let k_omega = congruence(inertia, &s);
        Gains::new(k_x, k_r, k_omega, k_v).map_err(|e| match e {
            ConfigError::NonFinite { field } => ConfigError::Overflow {
                quantity: match field {
                    ConfigField::GainKx => "gain K_x = m_C w^2",
                    ConfigField::GainKv => "gain K_v = 2 m_C zeta w",
                    ConfigField::GainKr => "gain K_R (J_C and w^2)",
                    _ => "gain K_Omega (J_C, zeta and w)",
                },
                field: ConfigField::NaturalFrequency,
            },
            other => other,
        })
    }
}

/// `D J D` with `D = diag(d)`: symmetric whenever `J` is, definite whenever `J` is and `d > 0`.
pub(crate) fn congruence<T: Real>(inertia: &Matrix3<T>, d: &Vector3<T>) -> Matrix3<T> {
    let d = Matrix3::from_diagonal(d);
    d * inertia * d
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::indexing_slicing)]
    use super::*;

    #[test]
    fn rejects_non_positive_and_non_finite_values() {
        let ok = [1.0f64; 3];
        let bad = [1.0, 0.0, 1.0];
        assert_eq!(
            NaturalGains::new(bad, ok, ok, ok),
            Err(ConfigError::Parameter {
                field: ConfigField::NaturalFrequency
            })
        );
        assert_eq!(
            NaturalGains::new(ok, ok, ok, [1.0, -1.0, 1.0]),
            Err(ConfigError::Parameter {
                field: ConfigField::DampingRatio
            })
        );
        assert_eq!(
            NaturalGains::new(ok, [f64::NAN, 1.0, 1.0], ok, ok),
            Err(ConfigError::NonFinite {
                field: ConfigField::DampingRatio
            })
        );
        // Finite settings whose gain overflows are refused naming the input (issue 57).
        let huge = NaturalGains::<f32>::uniform((1e20, 1.0), (1.0, 1.0)).unwrap();
        let err = huge.gains(1.0, &Matrix3::identity()).unwrap_err();
        assert_eq!(err.field(), Some(ConfigField::NaturalFrequency));
        assert!(
            matches!(err, ConfigError::Overflow { quantity, .. } if quantity.contains("K_x")),
            "{err:?}"
        );
        let huge = NaturalGains::<f64>::uniform((1.0, 1.0), (1e160, 1.0)).unwrap();
        let err = huge.gains(1.0, &Matrix3::identity()).unwrap_err();
        assert_eq!(err.field(), Some(ConfigField::NaturalFrequency));
        assert!(
            matches!(err, ConfigError::Overflow { quantity, .. } if quantity.contains("K_R")),
            "{err:?}"
        );
    }

    #[test]
    fn diagonal_inertia_gives_the_per_axis_poles() {
        let natural = NaturalGains::<f64>::new(
            [1.0, 2.0, 3.0],
            [0.5, 0.7, 1.0],
            [4.0, 5.0, 6.0],
            [0.8, 0.9, 1.0],
        )
        .unwrap();
        let j = Matrix3::from_diagonal(&Vector3::new(0.2, 0.3, 0.5));
        let g = natural.gains(2.0, &j).unwrap();
        for i in 0..3 {
            let (m, w, z): (f64, f64, f64) = (2.0, [1.0, 2.0, 3.0][i], [0.5, 0.7, 1.0][i]);
            assert!((g.k_x()[(i, i)] - m * w * w).abs() < 1e-12);
            assert!((g.k_v()[(i, i)] - 2.0 * z * w * m).abs() < 1e-12);
            let (ji, wr, zr): (f64, f64, f64) =
                ([0.2, 0.3, 0.5][i], [4.0, 5.0, 6.0][i], [0.8, 0.9, 1.0][i]);
            assert!((g.k_r()[(i, i)] - ji * wr * wr).abs() < 1e-12);
            assert!((g.k_omega()[(i, i)] - 2.0 * zr * wr * ji).abs() < 1e-12);
        }
        // Off-diagonal terms stay zero for a diagonal inertia.
        assert_eq!(g.k_r()[(0, 1)], 0.0);
    }

    #[test]
    fn full_inertia_stays_symmetric_positive_definite() {
        let j = Matrix3::new(0.3, 0.05, -0.02, 0.05, 0.4, 0.01, -0.02, 0.01, 0.6);
        let natural = NaturalGains::uniform((1.0f64, 1.0), (6.0, 0.7)).unwrap();
        let g = natural.gains(3.0, &j).unwrap();
        assert!((g.k_r() - g.k_r().transpose()).norm() == 0.0);
        // Uniform frequencies: K_R = w^2 J exactly.
        assert!((g.k_r() - j * 36.0).norm() < 1e-12);
    }
}
