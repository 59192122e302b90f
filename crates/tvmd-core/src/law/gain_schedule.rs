//! Which gains the law of eq. (12) uses for a team: the settings' gains as given (the paper),
//! the same gains scaled by the team's mass and inertia (the authors' MATLAB), or gains from
//! closed-loop natural frequencies ([`NaturalGains`]). Resolved once per controller
//! (`docs/method.md#beyond-the-paper-gains-that-fit-any-team`).

use nalgebra::Matrix3;

use crate::foundation::error::ConfigError;
use crate::foundation::real::{lit, Real};
use crate::foundation::stored::tag_below;
use crate::law::natural_gains::NaturalGains;
use crate::law::Gains;

/// How the controller turns its settings into the gains of eq. (12). `repr(u8)`: the tag
/// first, checked raw by [`crate::Controller::storage_intact`].
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(u8)]
pub enum GainSchedule<T: Real> {
    /// The settings' gains as they are: the paper's reading (eq. 12 with `K_x`, `K_R`, `K_xi`
    /// unscaled). The default of [`crate::ControllerSettings::paper`].
    AsGiven,
    /// The authors' MATLAB reading: the settings' gains multiplied by the team's mass
    /// (translation: `K_x' = m_C K_x`, `K_v' = m_C K_v`) and inertia (attitude:
    /// `K_R' = J_C K_R`, `K_Omega' = J_C K_Omega`), as if the gains were accelerations per unit
    /// error. For a `J_C` that commutes with the gain (both diagonal, as every preset) the
    /// product is exact; otherwise its symmetric part is used, which must still be positive
    /// definite.
    TeamScaled,
    /// Gains from closed-loop natural frequencies and damping ratios
    /// ([`NaturalGains::gains`]); the settings' gains are not used.
    Natural(NaturalGains<T>),
}

impl<T: Real> GainSchedule<T> {
    /// The gains of eq. (12) for a team of mass `m_C` and inertia `J_C`, given the settings'
    /// gains. [`GainSchedule::AsGiven`] returns `given` unchanged (bit for bit).
    ///
    /// Errors: as [`Gains::new`], naming the gain whose scaled value is not finite or not
    /// symmetric positive definite.
    ///
    /// ```
    /// use tvmd_core::nalgebra::Matrix3;
    /// use tvmd_core::{GainSchedule, Gains};
    /// let paper = Gains::<f64>::paper();
    /// let j = Matrix3::from_diagonal(&tvmd_core::nalgebra::Vector3::new(0.35, 0.35, 0.7));
    /// let scaled = GainSchedule::TeamScaled.resolve(&paper, 2.8, &j)?;
    /// assert!((scaled.k_x()[(0, 0)] - 2.8 * 0.4).abs() < 1e-12);
    /// assert!((scaled.k_r()[(2, 2)] - 0.7 * 1.0).abs() < 1e-12);
    /// assert_eq!(GainSchedule::AsGiven.resolve(&paper, 2.8, &j)?, paper);
    /// # Ok::<(), tvmd_core::ConfigError>(())
    /// ```
    pub fn resolve(
        &self,
        given: &Gains<T>,
        mass: T,
        inertia: &Matrix3<T>,
    ) -> Result<Gains<T>, ConfigError> {
        match self {
            Self::AsGiven => Ok(*given),
            Self::TeamScaled => {
                let product = |k: &Matrix3<T>| {
                    let p = inertia * k;
                    (p + p.transpose()) * lit::<T>(0.5)
                };
                Gains::new(
                    given.k_x() * mass,
                    product(&given.k_r()),
                    product(&given.k_omega()),
                    given.k_v() * mass,
                )
            }
            Self::Natural(natural) => natural.gains(mass, inertia),
        }
    }
}

impl<T: Real> GainSchedule<T> {
    /// Whether the schedule at `this` has one of the three tags (its gains are numbers).
    ///
    /// # Safety
    /// `this` is aligned and points to `size_of::<Self>()` readable bytes.
    pub(crate) unsafe fn storage_intact(this: *const Self) -> bool {
        tag_below(this, 3)
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::indexing_slicing)]
    use super::*;
    use crate::foundation::error::ConfigField;
    use nalgebra::Vector3;

    #[test]
    fn team_scaled_is_the_product_for_a_diagonal_inertia() {
        let paper = Gains::<f64>::paper();
        let j = Matrix3::from_diagonal(&Vector3::new(0.3, 0.4, 0.6));
        let g = GainSchedule::TeamScaled.resolve(&paper, 2.8, &j).unwrap();
        assert_eq!(g.k_x(), paper.k_x() * 2.8);
        assert_eq!(g.k_v(), paper.k_v() * 2.8);
        assert_eq!(g.k_r(), j * paper.k_r());
        assert_eq!(g.k_omega(), j * paper.k_omega());
    }

    #[test]
    fn natural_ignores_the_given_gains_and_errors_are_typed() {
        let paper = Gains::<f64>::paper();
        let natural = NaturalGains::uniform((1.0, 1.0), (5.0, 1.0)).unwrap();
        let j = Matrix3::identity();
        let g = GainSchedule::Natural(natural)
            .resolve(&paper, 2.0, &j)
            .unwrap();
        assert_eq!(g.k_x()[(0, 0)], 2.0);
        assert_eq!(g.k_r()[(1, 1)], 25.0);
        // A huge mass overflows the scaled K_v (0.8 m, 2 m): a typed error, not an infinite
        // gain.
        let err = GainSchedule::TeamScaled.resolve(&paper, 1e308, &j);
        assert_eq!(
            err,
            Err(ConfigError::NonFinite {
                field: ConfigField::GainKv
            })
        );
    }
}

#[cfg(test)]
mod storage_tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use crate::foundation::stored::{accepts, refuses};

    #[test]
    fn an_invalid_schedule_tag_is_refused() {
        let check = GainSchedule::<f32>::storage_intact;
        for s in [GainSchedule::AsGiven, GainSchedule::TeamScaled] {
            assert!(accepts(&s, check));
            assert!(refuses(&s, 3, |p| p.cast(), check));
        }
    }
}
