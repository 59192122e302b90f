//! The law beyond the paper in the C configuration ([`TvmdLaw`], the `law` field of
//! [`crate::types::TvmdConfig`]) and its conversion to the core's settings: the gain schedule,
//! the offset-free action and the planned-rate filter (`docs/method.md`, "Beyond the paper").
//!
//! `TvmdLaw` is the C ABI's named-field layout of [`LawWords`], the one flat encoding of the
//! law (crate `tvmd-wire`, also carried by the PIL link and the cycle recordings): both ways
//! go through it, and only the C check of the mode words is this module's.
//!
//! A zero-initialized `TvmdLaw` is the paper's law (gains as given, no offset-free action, the
//! reference's rates). `tvmd_config_default` fills the offset-free law, the library's default.

use tvmd_core::ControllerSettings;
use tvmd_wire::LawWords;

use crate::status::ConvertError;

// The C constants are literals (cbindgen writes them to the header) and the words' own.
const _: () = assert!(
    TVMD_GAINS_AS_GIVEN == tvmd_wire::GAINS_AS_GIVEN
        && TVMD_GAINS_TEAM_SCALED == tvmd_wire::GAINS_TEAM_SCALED
        && TVMD_GAINS_NATURAL == tvmd_wire::GAINS_NATURAL
        && TVMD_OFFSET_FREE_OFF == tvmd_wire::OFFSET_FREE_OFF
        && TVMD_OFFSET_FREE_OBSERVER == tvmd_wire::OFFSET_FREE_OBSERVER
        && TVMD_OFFSET_FREE_INTEGRAL == tvmd_wire::OFFSET_FREE_INTEGRAL
);

/// `law.gain_schedule`: the gains `config.gains` as given (the paper's reading of eq. 12).
pub const TVMD_GAINS_AS_GIVEN: u32 = 0;
/// `law.gain_schedule`: `config.gains` scaled by the team's mass (`K_x`, `K_v`) and inertia
/// (`K_R`, `K_Omega`), the authors' MATLAB reading.
pub const TVMD_GAINS_TEAM_SCALED: u32 = 1;
/// `law.gain_schedule`: gains from the closed-loop natural frequencies and damping ratios of
/// `law.position_*` and `law.attitude_*`, scaled by the team's mass and inertia (`config.gains`
/// is not used).
pub const TVMD_GAINS_NATURAL: u32 = 2;

/// `law.offset_free`: none (the paper's law, no steady-state correction).
pub const TVMD_OFFSET_FREE_OFF: u32 = 0;
/// `law.offset_free`: the disturbance observer (`force_bandwidth`, `torque_bandwidth`,
/// `max_torque`), the one of the library's default law.
pub const TVMD_OFFSET_FREE_OBSERVER: u32 = 1;
/// `law.offset_free`: integral action on the position and attitude errors (`integral_k_x`,
/// `integral_k_r`, `max_torque`).
pub const TVMD_OFFSET_FREE_INTEGRAL: u32 = 2;

/// The law beyond the paper: how the gains are formed, the offset-free action and the filter of
/// the planned attitude's rates. All numbers SI. A mode reads only its own fields; the fields
/// a mode does not use are ignored (any value, even NaN). Every number a mode uses must be
/// finite (`TVMD_ERR_CONFIG_NON_FINITE`) and positive (`TVMD_ERR_CONFIG_PARAMETER`); an unknown
/// mode is `TVMD_ERR_ENUM_VALUE`. All zeros is the paper's law.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TvmdLaw {
    /// One of `TVMD_GAINS_*`.
    pub gain_schedule: u32,
    /// Closed-loop natural frequency `w_x` (rad/s) of the position axes x, y, z (inertial), with
    /// `TVMD_GAINS_NATURAL`: `K_x = m_C diag(w_x^2)`.
    pub position_frequency: [f32; 3],
    /// Damping ratio `zeta_x` (dimensionless) of the position axes, with `TVMD_GAINS_NATURAL`:
    /// `K_v = m_C diag(2 zeta_x w_x)`.
    pub position_damping: [f32; 3],
    /// Closed-loop natural frequency `w_R` (rad/s) of roll, pitch, yaw (body), with
    /// `TVMD_GAINS_NATURAL`: `K_R = W J_C W`, `W = diag(w_R)`.
    pub attitude_frequency: [f32; 3],
    /// Damping ratio `zeta_R` (dimensionless) of roll, pitch, yaw, with `TVMD_GAINS_NATURAL`.
    pub attitude_damping: [f32; 3],
    /// One of `TVMD_OFFSET_FREE_*`.
    pub offset_free: u32,
    /// Observer bandwidth `L_f` (rad/s) of the force estimate, with
    /// `TVMD_OFFSET_FREE_OBSERVER`.
    pub force_bandwidth: f32,
    /// Observer bandwidth `L_tau` (rad/s) of the torque estimate, with
    /// `TVMD_OFFSET_FREE_OBSERVER`.
    pub torque_bandwidth: f32,
    /// Integral gain `K_Ix` (N/(m s)) per inertial axis, with `TVMD_OFFSET_FREE_INTEGRAL`.
    pub integral_k_x: [f32; 3],
    /// Integral gain `K_IR` (N m/(rad s)) per body axis, with `TVMD_OFFSET_FREE_INTEGRAL`.
    pub integral_k_r: [f32; 3],
    /// Bound (N m) on the offset-free torque, with either offset-free action (the force is
    /// bounded by the working agents' capacity `n sigma_Tf`).
    pub max_torque: f32,
    /// Non-zero: the law's `Omega_d`, `Omega_d_dot` are the filtered rates of the planned
    /// attitude `R_d` in place of the reference's (needed whenever the planner tilts away from
    /// the reference); zero: the reference's (the paper).
    pub attitude_rate: u32,
    /// Bandwidth (rad/s) of the planned-rate filter, with `attitude_rate`.
    pub attitude_rate_bandwidth: f32,
    /// Bound (rad/s) on the planned rate, with `attitude_rate`.
    pub attitude_rate_max: f32,
}

impl TvmdLaw {
    /// The law as [`LawWords`], the one flat encoding of the law's settings (the PIL link and
    /// the cycle recordings carry it too), after the check only C needs: a mode word outside
    /// its constants is [`ConvertError::EnumValue`] (`TVMD_ERR_ENUM_VALUE`).
    fn words(&self) -> Result<LawWords, ConvertError> {
        if self.gain_schedule > TVMD_GAINS_NATURAL || self.offset_free > TVMD_OFFSET_FREE_INTEGRAL {
            return Err(ConvertError::EnumValue);
        }
        // Element by element: the link check proves this path panic-free.
        let [a, b, c, d] = [
            self.position_frequency,
            self.position_damping,
            self.attitude_frequency,
            self.attitude_damping,
        ];
        let natural = [
            a[0], a[1], a[2], b[0], b[1], b[2], c[0], c[1], c[2], d[0], d[1], d[2],
        ];
        let (x, r) = (self.integral_k_x, self.integral_k_r);
        let values = [
            self.force_bandwidth,
            self.torque_bandwidth,
            x[0],
            x[1],
            x[2],
            r[0],
            r[1],
            r[2],
            self.max_torque,
        ];
        Ok(LawWords {
            gain_schedule: self.gain_schedule,
            natural,
            offset_free: self.offset_free,
            offset_free_values: values,
            attitude_rate: (self.attitude_rate != 0)
                .then_some([self.attitude_rate_bandwidth, self.attitude_rate_max]),
        })
    }

    /// Sets the gain schedule, offset-free action and planned rates of `settings` to this law;
    /// every value a mode uses is validated by the core's constructor ([`LawWords::apply`]).
    pub(crate) fn apply(&self, settings: &mut ControllerSettings<f32>) -> Result<(), ConvertError> {
        Ok(self.words()?.apply(settings)?)
    }

    /// The law of `settings` (the numbers of a mode that is off stay zero).
    pub(crate) fn from_core(settings: &ControllerSettings<f32>) -> Self {
        let w = LawWords::of(settings);
        let [p0, p1, p2, q0, q1, q2, a0, a1, a2, b0, b1, b2] = w.natural;
        let [f, t, x0, x1, x2, r0, r1, r2, max_torque] = w.offset_free_values;
        let [attitude_rate_bandwidth, attitude_rate_max] = w.attitude_rate.unwrap_or_default();
        Self {
            gain_schedule: w.gain_schedule,
            position_frequency: [p0, p1, p2],
            position_damping: [q0, q1, q2],
            attitude_frequency: [a0, a1, a2],
            attitude_damping: [b0, b1, b2],
            offset_free: w.offset_free,
            force_bandwidth: f,
            torque_bandwidth: t,
            integral_k_x: [x0, x1, x2],
            integral_k_r: [r0, r1, r2],
            max_torque,
            attitude_rate: u32::from(w.attitude_rate.is_some()),
            attitude_rate_bandwidth,
            attitude_rate_max,
        }
    }

    /// The paper's law (every mode off) carrying the numbers of the library's default law, so
    /// that switching a mode on in `tvmd_config_paper`'s result starts from the default's
    /// values (the integral gains, which the default does not use, stay zero).
    pub(crate) fn paper() -> Self {
        Self {
            gain_schedule: TVMD_GAINS_AS_GIVEN,
            offset_free: TVMD_OFFSET_FREE_OFF,
            attitude_rate: 0,
            ..Self::from_core(&ControllerSettings::offset_free_law())
        }
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::panic)]
    use super::*;

    use tvmd_core::{GainSchedule, OffsetFree};

    /// The core's settings of `law` (on the paper's), or its error.
    fn to_core(law: &TvmdLaw) -> Result<ControllerSettings<f32>, ConvertError> {
        let mut settings = ControllerSettings::paper();
        law.apply(&mut settings).map(|()| settings)
    }

    fn status(law: &TvmdLaw) -> crate::status::TvmdStatus {
        match to_core(law) {
            Ok(_) => crate::status::TVMD_OK,
            Err(e) => e.status(),
        }
    }

    #[test]
    fn the_default_round_trips_and_zeros_are_the_paper() {
        let default = ControllerSettings::<f32>::offset_free_law();
        let law = to_core(&TvmdLaw::from_core(&default)).unwrap();
        assert_eq!(law.gain_schedule, default.gain_schedule);
        assert_eq!(law.offset_free, default.offset_free);
        assert_eq!(law.attitude_rate, default.attitude_rate);
        let paper = ControllerSettings::<f32>::paper();
        for zero_or_paper in [TvmdLaw::default(), TvmdLaw::paper()] {
            let law = to_core(&zero_or_paper).unwrap();
            assert_eq!(law.gain_schedule, paper.gain_schedule);
            assert_eq!((law.offset_free, law.attitude_rate), (None, None));
        }
        assert_eq!(TvmdLaw::from_core(&paper), TvmdLaw::default());
    }

    #[test]
    fn the_integral_round_trips_and_unused_fields_are_ignored() {
        let mut law = TvmdLaw::paper();
        law.offset_free = TVMD_OFFSET_FREE_INTEGRAL;
        law.integral_k_x = [1.0, 2.0, 3.0];
        law.integral_k_r = [0.5; 3];
        law.force_bandwidth = f32::NAN; // the observer's, unused here
        law.gain_schedule = TVMD_GAINS_TEAM_SCALED;
        law.position_frequency = [-1.0; 3]; // the natural gains', unused here
        let core = to_core(&law).unwrap();
        let Some(OffsetFree::Integral(i)) = core.offset_free else {
            panic!("integral expected");
        };
        assert_eq!(<[f32; 3]>::from(i.k_x()), [1.0, 2.0, 3.0]);
        assert_eq!(core.gain_schedule, GainSchedule::TeamScaled);
        let settings = ControllerSettings {
            gain_schedule: core.gain_schedule,
            offset_free: core.offset_free,
            ..ControllerSettings::paper()
        };
        let back = TvmdLaw::from_core(&settings);
        assert_eq!(back.integral_k_x, [1.0, 2.0, 3.0]);
        assert_eq!(back.gain_schedule, TVMD_GAINS_TEAM_SCALED);
    }

    #[test]
    fn bad_values_are_typed_statuses() {
        use crate::status::*;
        let default = TvmdLaw::from_core(&ControllerSettings::offset_free_law());
        /// An edit of the law and the status it must give.
        type Case = (fn(&mut TvmdLaw), TvmdStatus);
        let cases: [Case; 9] = [
            (|l| l.gain_schedule = 3, TVMD_ERR_ENUM_VALUE),
            (|l| l.offset_free = 7, TVMD_ERR_ENUM_VALUE),
            (|l| l.position_frequency[1] = 0.0, TVMD_ERR_CONFIG_PARAMETER),
            (
                |l| l.attitude_damping[2] = f32::NAN,
                TVMD_ERR_CONFIG_NON_FINITE,
            ),
            (|l| l.force_bandwidth = -1.0, TVMD_ERR_CONFIG_PARAMETER),
            (|l| l.max_torque = f32::INFINITY, TVMD_ERR_CONFIG_NON_FINITE),
            (|l| l.attitude_rate_max = 0.0, TVMD_ERR_CONFIG_PARAMETER),
            (
                |l| {
                    l.offset_free = TVMD_OFFSET_FREE_INTEGRAL;
                    l.integral_k_r = [1.0, 0.0, 1.0];
                },
                TVMD_ERR_CONFIG_PARAMETER,
            ),
            (
                |l| l.attitude_rate_bandwidth = f32::NAN,
                TVMD_ERR_CONFIG_NON_FINITE,
            ),
        ];
        for (i, (edit, expected)) in cases.iter().enumerate() {
            let mut law = default;
            edit(&mut law);
            assert_eq!(status(&law), *expected, "case {i}");
        }
        // A mode that is off ignores its numbers.
        let mut off = default;
        off.attitude_rate = 0;
        off.attitude_rate_bandwidth = f32::NAN;
        assert_eq!(status(&off), TVMD_OK);
    }
}
