//! [`ControllerSettings`]: everything a [`crate::Controller`] is configured with besides the
//! team and the allocator.

use core::ptr::{addr_of, addr_of_mut};

use crate::afs::Relaxation;
use crate::agent::limits::RateLimits;
use crate::allocation::NullSpaceStage;
use crate::fault::detection::FaultDetection;
use crate::foundation::error::{ConfigError, ConfigField};
use crate::foundation::real::{lit, Real};
use crate::foundation::stored::Stored;
use crate::law::attitude_rate::AttitudeRateFilter;
use crate::law::disturbance::DisturbanceObserver;
use crate::law::gain_schedule::GainSchedule;
use crate::law::natural_gains::NaturalGains;
use crate::law::offset_free::OffsetFree;
use crate::law::Gains;

/// Shortest control period (s) a controller accepts (1 MHz): below it the rates the rate
/// limits, the observer and the planned-rate filter derive would be meaningless.
pub const MIN_PERIOD: f64 = 1e-6;
/// Longest control period (s) a controller accepts (1 Hz).
pub const MAX_PERIOD: f64 = 1.0;

/// Natural frequency (rad/s) of [`ControllerSettings::offset_free_law`]'s position axes.
pub const POSITION_FREQUENCY: f64 = 1.5;
/// Natural frequency (rad/s) of [`ControllerSettings::offset_free_law`]'s attitude axes.
pub const ATTITUDE_FREQUENCY: f64 = 6.0;
/// Damping ratio of [`ControllerSettings::offset_free_law`]'s position axes.
pub const DAMPING_RATIO: f64 = 1.0;
/// Damping ratio of [`ControllerSettings::offset_free_law`]'s attitude axes; 1 until issue 61.
/// The gains scale with the model's inertia, so on a plant lighter than the model the attitude
/// loop's rate gain `2 zeta w J / J_true` grows (twice at half the inertia) towards the gimbal
/// servos' bandwidth; at 0.6 (7.2 rad/s instead of 12 on the model) it stays below it, and every
/// flight of the Monte Carlo families at five times the default model error holds
/// (`docs/monte-carlo.md`).
pub const ATTITUDE_DAMPING: f64 = 0.6;
/// Observer bandwidth `L_f = L_tau` (rad/s) of [`ControllerSettings::offset_free_law`].
pub const OBSERVER_BANDWIDTH: f64 = 10.0;
/// Bound of the offset-free torque (N m) of [`ControllerSettings::offset_free_law`].
pub const OFFSET_FREE_MAX_TORQUE: f64 = 5.0;
/// Bandwidth (rad/s) of [`ControllerSettings::offset_free_law`]'s planned-rate filter.
pub const ATTITUDE_RATE_BANDWIDTH: f64 = 20.0;
/// Rate bound (rad/s) of [`ControllerSettings::offset_free_law`]'s planned-rate filter.
pub const ATTITUDE_RATE_MAX: f64 = 5.0;

/// Settings of a [`crate::Controller`] besides the team and the allocator.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ControllerSettings<T: Real> {
    /// Gains of eq. (12) (used as [`Self::gain_schedule`] says).
    pub gains: Gains<T>,
    /// AFS relaxation `s` of the planner.
    pub relaxation: Relaxation<T>,
    /// `g` (m/s^2).
    pub gravity: T,
    /// Control period `dt` (s), in [[`MIN_PERIOD`], [`MAX_PERIOD`]]; used by the rate limits,
    /// the offset-free state and the planned rates.
    pub period: T,
    /// Optional gimbal rate limits (the rate-constrained allocation).
    pub rate_limits: Option<RateLimits<T>>,
    /// Optional null-space stage run after the allocator ([`NullSpaceStage`]; `None`: the
    /// allocator's forces are used as they are, and [`crate::ControlOutput::null_space`] is
    /// [`crate::NullSpaceReport::off`]).
    pub null_space: Option<NullSpaceStage<T>>,
    /// How [`Self::gains`] become the law's gains for the team: [`GainSchedule::AsGiven`]
    /// (the paper), [`GainSchedule::TeamScaled`] (the authors' MATLAB) or
    /// [`GainSchedule::Natural`] (closed-loop frequencies; `docs/method.md`).
    pub gain_schedule: GainSchedule<T>,
    /// Optional offset-free action ([`OffsetFree`]: a disturbance observer or an integral),
    /// added to the request before the planner; `None`: the paper's law.
    pub offset_free: Option<OffsetFree<T>>,
    /// Optional filter of the planned attitude's rates ([`AttitudeRateFilter`]): when set, the
    /// law's `Omega_d`, `Omega_d_dot` are those of the planner's `R_d` in place of the
    /// reference's; `None`: the reference's (the paper).
    pub attitude_rate: Option<AttitudeRateFilter<T>>,
    /// Optional agent fault detection ([`FaultDetection`]; needs the disturbance observer,
    /// [`OffsetFree::Observer`], whose estimate is its residual): a verdict each period
    /// ([`crate::Controller::fault_report`]) and, with [`crate::FaultResponse::Mask`], the
    /// controller masks a confirmed lost agent itself. `None`: no detection (the paper).
    pub fault_detection: Option<FaultDetection<T>>,
}

impl<T: Real> Default for ControllerSettings<T> {
    /// The library's default: [`ControllerSettings::offset_free_law`], the law that holds its
    /// setpoint under model error and disturbances (the paper's law leaves a steady error under
    /// any unmodelled force). Reproduce the paper with [`ControllerSettings::paper`].
    fn default() -> Self {
        Self::offset_free_law()
    }
}

impl<T: Real> ControllerSettings<T> {
    /// The paper's settings: its gains as given, `s = 0.5`, `g = 9.81`, `dt = 0.01` s, no rate
    /// limits, no null-space stage, no offset-free action, the reference's `Omega_d`.
    pub fn paper() -> Self {
        Self {
            gains: Gains::paper(),
            relaxation: Relaxation::new(lit(0.5)).unwrap_or(Relaxation::none()),
            gravity: lit(crate::team::presets::GRAVITY),
            period: lit(0.01),
            rate_limits: None,
            null_space: None,
            gain_schedule: GainSchedule::AsGiven,
            offset_free: None,
            attitude_rate: None,
            fault_detection: None,
        }
    }

    /// The law that flies outside a perfect model (`law = "offset-free"` in scenarios): the
    /// paper's settings with natural gains ([`GainSchedule::Natural`], [`POSITION_FREQUENCY`],
    /// [`DAMPING_RATIO`], [`ATTITUDE_FREQUENCY`], [`ATTITUDE_DAMPING`], scaled by the team's mass and
    /// inertia), the disturbance observer ([`OBSERVER_BANDWIDTH`], [`OFFSET_FREE_MAX_TORQUE`])
    /// and the planned attitude's rates ([`ATTITUDE_RATE_BANDWIDTH`], [`ATTITUDE_RATE_MAX`]).
    /// `docs/method.md`, "Beyond the paper", states what is proven about it and what is measured.
    ///
    /// ```
    /// use tvmd_core::{ControllerSettings, GainSchedule};
    /// let s = ControllerSettings::<f32>::offset_free_law();
    /// assert!(matches!(s.gain_schedule, GainSchedule::Natural(_)));
    /// assert!(s.offset_free.is_some() && s.attitude_rate.is_some());
    /// assert_eq!(s.relaxation, ControllerSettings::<f32>::paper().relaxation);
    /// ```
    pub fn offset_free_law() -> Self {
        let natural = NaturalGains::uniform(
            (lit(POSITION_FREQUENCY), lit(DAMPING_RATIO)),
            (lit(ATTITUDE_FREQUENCY), lit(ATTITUDE_DAMPING)),
        );
        let observer = DisturbanceObserver::new(
            lit(OBSERVER_BANDWIDTH),
            lit(OBSERVER_BANDWIDTH),
            lit(OFFSET_FREE_MAX_TORQUE),
        );
        let rates = AttitudeRateFilter::new(lit(ATTITUDE_RATE_BANDWIDTH), lit(ATTITUDE_RATE_MAX));
        let paper = Self::paper();
        // The constants are positive and finite, so every constructor succeeds; the fallbacks
        // only keep this function panic-free.
        Self {
            gain_schedule: natural.map_or(GainSchedule::AsGiven, GainSchedule::Natural),
            offset_free: observer.ok().map(OffsetFree::Observer),
            attitude_rate: rates.ok(),
            ..paper
        }
    }

    /// Gains, relaxation, rate limits, the offset-free action and the rate filter are valid by
    /// construction (private fields); checked here: gravity finite and positive, the period in
    /// [[`MIN_PERIOD`], [`MAX_PERIOD`]], and a null-space stage only in a build that links it
    /// (cargo feature `null-space`).
    pub(crate) fn validate(&self) -> Result<(), ConfigError> {
        if cfg!(not(feature = "null-space")) && self.null_space.is_some() {
            return Err(ConfigError::StageUnavailable {
                name: "null-space",
                feature: "null-space",
            });
        }
        if !self.gravity.is_finite() || self.gravity <= T::zero() {
            return Err(ConfigError::Parameter {
                field: ConfigField::Gravity,
            });
        }
        let (min, max): (T, T) = (lit(MIN_PERIOD), lit(MAX_PERIOD));
        // `!(a <= b)` also refuses NaN.
        if !(self.period >= min && self.period <= max) {
            return Err(ConfigError::Parameter {
                field: ConfigField::Period,
            });
        }
        Ok(())
    }
}

/// [`ControllerSettings`] as a controller keeps them: the optional parts in [`Stored`]s, whose
/// tags, unlike `Option`'s, have a defined place and values, so that
/// [`crate::Controller::storage_intact`] can check them raw.
#[derive(Clone, Copy, Debug)]
pub(super) struct StoredSettings<T: Real> {
    pub(super) gains: Gains<T>,
    pub(super) relaxation: Relaxation<T>,
    pub(super) gravity: T,
    pub(super) period: T,
    pub(super) rate_limits: Stored<RateLimits<T>>,
    pub(super) null_space: Stored<NullSpaceStage<T>>,
    pub(super) gain_schedule: GainSchedule<T>,
    pub(super) offset_free: Stored<OffsetFree<T>>,
    pub(super) attitude_rate: Stored<AttitudeRateFilter<T>>,
    pub(super) fault_detection: Stored<FaultDetection<T>>,
}

impl<T: Real> From<StoredSettings<T>> for ControllerSettings<T> {
    fn from(s: StoredSettings<T>) -> Self {
        Self {
            gains: s.gains,
            relaxation: s.relaxation,
            gravity: s.gravity,
            period: s.period,
            rate_limits: s.rate_limits.get(),
            null_space: s.null_space.get(),
            gain_schedule: s.gain_schedule,
            offset_free: s.offset_free.get(),
            attitude_rate: s.attitude_rate.get(),
            fault_detection: s.fault_detection.get(),
        }
    }
}

impl<T: Real> StoredSettings<T> {
    /// Writes `s` at `this` field by field, each optional part's tag and value in place (what
    /// `ControllerSettings::from` reads back as `s`), without a converted copy on the stack
    /// (about 370 B less of the C interface's flash build).
    ///
    /// # Safety
    /// `this` is aligned and points to `size_of::<Self>()` writable bytes.
    pub(super) unsafe fn write_from(this: *mut Self, s: &ControllerSettings<T>) {
        addr_of_mut!((*this).gains).write(s.gains);
        addr_of_mut!((*this).relaxation).write(s.relaxation);
        addr_of_mut!((*this).gravity).write(s.gravity);
        addr_of_mut!((*this).period).write(s.period);
        Stored::write_from(addr_of_mut!((*this).rate_limits), &s.rate_limits);
        Stored::write_from(addr_of_mut!((*this).null_space), &s.null_space);
        addr_of_mut!((*this).gain_schedule).write(s.gain_schedule);
        Stored::write_from(addr_of_mut!((*this).offset_free), &s.offset_free);
        Stored::write_from(addr_of_mut!((*this).attitude_rate), &s.attitude_rate);
        Stored::write_from(addr_of_mut!((*this).fault_detection), &s.fault_detection);
    }

    /// Whether the settings at `this` hold valid tags: the five optional parts', the gain
    /// schedule's, and those inside (the null-space objective, the offset-free action, the
    /// fault response). Reads only.
    ///
    /// # Safety
    /// `this` is aligned and points to `size_of::<Self>()` readable bytes.
    pub(super) unsafe fn storage_intact(this: *const Self) -> bool {
        Stored::tag_intact(addr_of!((*this).rate_limits))
            && Stored::storage_intact(addr_of!((*this).null_space), |p| {
                NullSpaceStage::storage_intact(p)
            })
            && GainSchedule::storage_intact(addr_of!((*this).gain_schedule))
            && Stored::storage_intact(addr_of!((*this).offset_free), |p| {
                OffsetFree::storage_intact(p)
            })
            && Stored::tag_intact(addr_of!((*this).attitude_rate))
            && Stored::storage_intact(addr_of!((*this).fault_detection), |p| {
                FaultDetection::storage_intact(p)
            })
    }
}
