//! The control law's settings beyond the paper as words: the gain schedule, the offset-free
//! action and the planned-rate filter of `tvmd_core::ControllerSettings`.

use tvmd_core::{
    AttitudeRateFilter, ConfigError, ConfigField, ControllerSettings, DisturbanceObserver,
    GainSchedule, IntegralAction, NaturalGains, OffsetFree,
};

use crate::{Reader, Writer};

/// Words of a [`LawWords`]: gain schedule 1 + 12, offset-free 1 + 9, planned rates 1 + 2.
pub const LAW_WORDS: usize = 26;

/// [`LawWords::gain_schedule`]: the gains as given (the paper).
pub const GAINS_AS_GIVEN: u32 = 0;
/// [`LawWords::gain_schedule`]: the gains scaled by the team's mass and inertia.
pub const GAINS_TEAM_SCALED: u32 = 1;
/// [`LawWords::gain_schedule`]: natural gains from [`LawWords::natural`].
pub const GAINS_NATURAL: u32 = 2;
/// [`LawWords::offset_free`]: none (the paper).
pub const OFFSET_FREE_OFF: u32 = 0;
/// [`LawWords::offset_free`]: the disturbance observer.
pub const OFFSET_FREE_OBSERVER: u32 = 1;
/// [`LawWords::offset_free`]: integral action.
pub const OFFSET_FREE_INTEGRAL: u32 = 2;

/// The law's settings beyond the paper as plain f32 numbers; [`LawWords::PAPER`] is the
/// paper's law (all off).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LawWords {
    /// [`GAINS_AS_GIVEN`], [`GAINS_TEAM_SCALED`] or [`GAINS_NATURAL`].
    pub gain_schedule: u32,
    /// With [`GAINS_NATURAL`]: position frequencies (3, rad/s), damping ratios (3), attitude
    /// frequencies (3, rad/s), damping ratios (3).
    pub natural: [f32; 12],
    /// [`OFFSET_FREE_OFF`], [`OFFSET_FREE_OBSERVER`] or [`OFFSET_FREE_INTEGRAL`].
    pub offset_free: u32,
    /// Observer `L_f`, `L_tau` (rad/s); integral `K_Ix` (3), `K_IR` (3); the torque bound
    /// (N m). Unused entries are zero.
    pub offset_free_values: [f32; 9],
    /// The planned-rate filter's bandwidth (rad/s) and rate bound (rad/s), if on.
    pub attitude_rate: Option<[f32; 2]>,
}

impl LawWords {
    /// The paper's law: gains as given, no offset-free action, the reference's rates.
    pub const PAPER: Self = Self {
        gain_schedule: GAINS_AS_GIVEN,
        natural: [0.0; 12],
        offset_free: OFFSET_FREE_OFF,
        offset_free_values: [0.0; 9],
        attitude_rate: None,
    };

    /// The law of `settings` (its gain schedule, offset-free action and planned rates).
    pub fn of(settings: &ControllerSettings<f32>) -> Self {
        let mut law = Self::PAPER;
        match &settings.gain_schedule {
            GainSchedule::AsGiven => {}
            GainSchedule::TeamScaled => law.gain_schedule = GAINS_TEAM_SCALED,
            GainSchedule::Natural(n) => {
                law.gain_schedule = GAINS_NATURAL;
                // Element by element: the C interface reaches this, and its link proves no
                // panic path (no slice lengths to check).
                let [a, b, c, d] = [
                    n.position_frequency(),
                    n.position_damping(),
                    n.attitude_frequency(),
                    n.attitude_damping(),
                ];
                law.natural = [a.x, a.y, a.z, b.x, b.y, b.z, c.x, c.y, c.z, d.x, d.y, d.z];
            }
        }
        match &settings.offset_free {
            None => {}
            Some(OffsetFree::Observer(o)) => {
                law.offset_free = OFFSET_FREE_OBSERVER;
                law.offset_free_values[0] = o.force_bandwidth();
                law.offset_free_values[1] = o.torque_bandwidth();
                law.offset_free_values[8] = o.max_torque();
            }
            Some(OffsetFree::Integral(i)) => {
                law.offset_free = OFFSET_FREE_INTEGRAL;
                let (x, r) = (i.k_x(), i.k_r());
                law.offset_free_values = [0.0, 0.0, x.x, x.y, x.z, r.x, r.y, r.z, i.max_torque()];
            }
        }
        law.attitude_rate = settings
            .attitude_rate
            .map(|r| [r.bandwidth(), r.max_rate()]);
        law
    }

    /// Sets the gain schedule, offset-free action and planned rates of `settings` to this law.
    /// Errors: the core constructors' errors for bad values; an unknown kind word is
    /// [`ConfigError::Parameter`] naming [`ConfigField::NaturalFrequency`] (gain schedule) or
    /// [`ConfigField::ObserverBandwidth`] (offset-free action).
    pub fn apply(&self, settings: &mut ControllerSettings<f32>) -> Result<(), ConfigError> {
        let n = &self.natural;
        let three = |k: usize| [n[k], n[k + 1], n[k + 2]];
        settings.gain_schedule = match self.gain_schedule {
            GAINS_AS_GIVEN => GainSchedule::AsGiven,
            GAINS_TEAM_SCALED => GainSchedule::TeamScaled,
            GAINS_NATURAL => {
                GainSchedule::Natural(NaturalGains::new(three(0), three(3), three(6), three(9))?)
            }
            _ => return Err(unknown(ConfigField::NaturalFrequency)),
        };
        let v = &self.offset_free_values;
        settings.offset_free = match self.offset_free {
            OFFSET_FREE_OFF => None,
            OFFSET_FREE_OBSERVER => Some(OffsetFree::Observer(DisturbanceObserver::new(
                v[0], v[1], v[8],
            )?)),
            OFFSET_FREE_INTEGRAL => Some(OffsetFree::Integral(IntegralAction::new(
                [v[2], v[3], v[4]],
                [v[5], v[6], v[7]],
                v[8],
            )?)),
            _ => return Err(unknown(ConfigField::ObserverBandwidth)),
        };
        settings.attitude_rate = match self.attitude_rate {
            None => None,
            Some([bandwidth, max_rate]) => Some(AttitudeRateFilter::new(bandwidth, max_rate)?),
        };
        Ok(())
    }

    /// Appends the [`LAW_WORDS`] words.
    pub fn put(&self, w: &mut Writer<'_>) -> Option<()> {
        w.u32(self.gain_schedule)?;
        w.f32s(&self.natural)?;
        w.u32(self.offset_free)?;
        w.f32s(&self.offset_free_values)?;
        match self.attitude_rate {
            Some(r) => {
                w.u32(1)?;
                w.f32s(&r)
            }
            None => w.f32s(&[0.0; 3]),
        }
    }

    /// Reads the words written by [`LawWords::put`].
    pub fn get(r: &mut Reader<'_>) -> Option<Self> {
        let gain_schedule = r.u32()?;
        let natural = r.array()?;
        let offset_free = r.u32()?;
        let offset_free_values = r.array()?;
        let flag = r.u32()?;
        let rates = r.array::<2>()?;
        Some(Self {
            gain_schedule,
            natural,
            offset_free,
            offset_free_values,
            attitude_rate: (flag == 1).then_some(rates),
        })
    }
}

fn unknown(field: ConfigField) -> ConfigError {
    ConfigError::Parameter { field }
}
