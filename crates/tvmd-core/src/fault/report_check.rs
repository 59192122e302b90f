//! The report check's settings ([`ReportCheck`]: tolerances, the slowest healthy actuator,
//! the envelopes' forgetting, the link timeout, the persistence; recommended values as
//! constants) and their per-period gains at a controller's period ([`ReportGains`]). The check
//! itself is [`crate::fault::reports`].

use crate::foundation::error::{positive, ConfigError, ConfigField};
use crate::foundation::real::{lit, Real};

/// [`ReportCheck::thrust_tolerance`] of [`ReportCheck::recommended`]: a tenth of the maximum
/// thrust (an ESC's speed reading is good to a few percent; the rotor model's `k` to ten).
pub const REPORT_THRUST_TOLERANCE: f64 = 0.1;
/// [`ReportCheck::angle_tolerance`] of [`ReportCheck::recommended`] (rad): about 3 degrees,
/// ten times a servo potentiometer's typical noise.
pub const REPORT_ANGLE_TOLERANCE: f64 = 0.05;
/// [`ReportCheck::servo_rate`] of [`ReportCheck::recommended`] (rad/s): the slowest rate a
/// healthy gimbal servo turns at (the simulator's Monte Carlo servos are rate-limited at 6
/// rad/s; a hobby servo's 60 degrees in 0.1 s is 10 rad/s).
pub const REPORT_SERVO_RATE: f64 = 6.0;
/// [`ReportCheck::servo_lag`] of [`ReportCheck::recommended`] (s): the time constant of the
/// slowest healthy servo below its rate limit (the simulator's Monte Carlo servos, second order
/// at 40 rad/s and damping 0.8, settle like a first-order lag of `2 zeta / w_n` = 0.04 s).
pub const REPORT_SERVO_LAG: f64 = 0.05;
/// [`ReportCheck::thrust_forget`] of [`ReportCheck::recommended`] (share of the maximum thrust
/// per second): over a report's usual 40 ms (20 ms latency, 10 ms of delay, a period) the
/// thrust envelope forgets a tenth of the maximum thrust, as much as its tolerance.
pub const REPORT_THRUST_FORGET: f64 = 2.5;
/// [`ReportCheck::angle_forget`] of [`ReportCheck::recommended`] (rad/s): 0.1 rad over 40 ms.
pub const REPORT_ANGLE_FORGET: f64 = 2.5;
/// [`ReportCheck::command_delay`] of [`ReportCheck::recommended`] (s): the command link's
/// latency and jitter the allowance covers.
pub const REPORT_COMMAND_DELAY: f64 = 0.01;
/// [`ReportCheck::link_timeout`] of [`ReportCheck::recommended`] (s): at 100 reports a second
/// and 20 ms latency, eight reports lost in a row (at 10% loss, once in `10^8` reports).
pub const REPORT_LINK_TIMEOUT: f64 = 0.1;
/// [`ReportCheck::persistence`] of [`ReportCheck::recommended`] (reports in a row).
pub const REPORT_PERSISTENCE: u8 = 2;

/// The report check's settings. Validated: tolerances, servo rate and link timeout finite and
/// positive, the command delay finite and at least 0, the persistence at least 1.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReportCheck<T: Real> {
    thrust_tolerance: T,
    angle_tolerance: T,
    servo_rate: T,
    servo_lag: T,
    command_delay: T,
    link_timeout: T,
    persistence: u8,
    thrust_forget: T,
    angle_forget: T,
}

impl<T: Real> ReportCheck<T> {
    /// `thrust_tolerance` (share of the maximum thrust), `angle_tolerance` (rad), `servo_rate`
    /// (rad/s) and `servo_lag` (s) of the slowest healthy servo, `command_delay` (s),
    /// `link_timeout` (s), `persistence` (reports in a row).
    ///
    /// Errors: [`ConfigError::NonFinite`] or [`ConfigError::Parameter`] naming
    /// [`ConfigField::ReportTolerance`], [`ConfigField::ReportServoRate`] (also for the
    /// servo lag),
    /// [`ConfigField::ReportLinkTimeout`] (also for the command delay) or
    /// [`ConfigField::ReportPersistence`].
    pub fn new(
        thrust_tolerance: T,
        angle_tolerance: T,
        servo_rate: T,
        servo_lag: T,
        command_delay: T,
        link_timeout: T,
        persistence: u8,
    ) -> Result<Self, ConfigError> {
        if persistence == 0 {
            return Err(ConfigError::Parameter {
                field: ConfigField::ReportPersistence,
            });
        }
        let field = ConfigField::ReportLinkTimeout;
        if !command_delay.is_finite() {
            return Err(ConfigError::NonFinite { field });
        }
        if command_delay < T::zero() {
            return Err(ConfigError::Parameter { field });
        }
        // One loop, not five inlined checks: the C interface's flash build counts its bytes.
        for (value, field) in [
            (thrust_tolerance, ConfigField::ReportTolerance),
            (angle_tolerance, ConfigField::ReportTolerance),
            (servo_rate, ConfigField::ReportServoRate),
            (servo_lag, ConfigField::ReportServoRate),
            (link_timeout, field),
        ] {
            positive(value, field)?;
        }
        Ok(Self {
            thrust_tolerance,
            angle_tolerance,
            servo_rate,
            servo_lag,
            command_delay,
            link_timeout,
            persistence,
            thrust_forget: lit(REPORT_THRUST_FORGET),
            angle_forget: lit(REPORT_ANGLE_FORGET),
        })
    }

    /// The same check whose envelopes forget at `thrust` (share of the maximum thrust per
    /// second) and `angle` (rad/s) ([`REPORT_THRUST_FORGET`], [`REPORT_ANGLE_FORGET`] unless
    /// set). Errors: [`ConfigError::NonFinite`] or [`ConfigError::Parameter`] naming
    /// [`ConfigField::ReportTolerance`] unless both are finite and positive.
    pub fn with_forgetting(self, thrust: T, angle: T) -> Result<Self, ConfigError> {
        Ok(Self {
            thrust_forget: positive(thrust, ConfigField::ReportTolerance)?,
            angle_forget: positive(angle, ConfigField::ReportTolerance)?,
            ..self
        })
    }

    /// The thrust envelope's forgetting rate (share of the maximum thrust per second).
    pub fn thrust_forget(&self) -> T {
        self.thrust_forget
    }

    /// The angle envelopes' forgetting rate (rad/s).
    pub fn angle_forget(&self) -> T {
        self.angle_forget
    }

    /// The recommended values ([`REPORT_THRUST_TOLERANCE`], [`REPORT_ANGLE_TOLERANCE`],
    /// [`REPORT_SERVO_RATE`], [`REPORT_SERVO_LAG`], [`REPORT_COMMAND_DELAY`],
    /// [`REPORT_LINK_TIMEOUT`], [`REPORT_PERSISTENCE`]).
    pub fn recommended() -> Self {
        Self {
            thrust_tolerance: lit(REPORT_THRUST_TOLERANCE),
            angle_tolerance: lit(REPORT_ANGLE_TOLERANCE),
            servo_rate: lit(REPORT_SERVO_RATE),
            servo_lag: lit(REPORT_SERVO_LAG),
            command_delay: lit(REPORT_COMMAND_DELAY),
            link_timeout: lit(REPORT_LINK_TIMEOUT),
            persistence: REPORT_PERSISTENCE,
            thrust_forget: lit(REPORT_THRUST_FORGET),
            angle_forget: lit(REPORT_ANGLE_FORGET),
        }
    }

    /// The thrust tolerance (share of the maximum thrust).
    pub fn thrust_tolerance(&self) -> T {
        self.thrust_tolerance
    }

    /// The angle tolerance (rad).
    pub fn angle_tolerance(&self) -> T {
        self.angle_tolerance
    }

    /// The slowest healthy servo rate (rad/s) the model turns at.
    pub fn servo_rate(&self) -> T {
        self.servo_rate
    }

    /// The slowest healthy servo's time constant (s) below its rate limit.
    pub fn servo_lag(&self) -> T {
        self.servo_lag
    }

    /// The command link's stated delay (s).
    pub fn command_delay(&self) -> T {
        self.command_delay
    }

    /// The age (s) past which an agent's link is taken as gone.
    pub fn link_timeout(&self) -> T {
        self.link_timeout
    }

    /// Reports in a row that confirm a fault.
    pub fn persistence(&self) -> u8 {
        self.persistence
    }
}

/// What one period of `period` s does to the models: computed once per controller
/// ([`ReportCheck::gains`]), so that no period pays an `exp`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReportGains<T: Real> {
    pub(super) period: T,
    /// The share of the gap the rotor and the servo models close in a period.
    pub(super) rotor: T,
    pub(super) servo: T,
    /// The servo model's largest step (rad).
    pub(super) step: T,
    /// What the envelopes forget in a period (N, rad).
    pub(super) forget_thrust: T,
    pub(super) forget_angle: T,
    /// The allowances of a report of age `a`: `base + rate a` (N, rad): the tolerance and
    /// what the envelope forgets over the report's age, the command's delay and a period.
    pub(super) thrust_base: T,
    pub(super) thrust_rate: T,
    pub(super) angle_base: T,
    pub(super) angle_rate: T,
}

impl<T: Real> ReportCheck<T> {
    /// The per-period gains of this check at the control period `period` (s), the rotor lag
    /// `rotor_lag` (s, the controller's stated actuator lag) and the team's `max_thrust` (N);
    /// all positive.
    pub fn gains(&self, period: T, rotor_lag: T, max_thrust: T) -> ReportGains<T> {
        let closed = |tau: T| T::one() - (-(period / tau)).exp();
        let thrust_rate = self.thrust_forget * max_thrust;
        let since = self.command_delay + period;
        ReportGains {
            period,
            rotor: closed(rotor_lag),
            servo: closed(self.servo_lag),
            step: self.servo_rate * period,
            forget_thrust: thrust_rate * period,
            forget_angle: self.angle_forget * period,
            thrust_base: self.thrust_tolerance * max_thrust + thrust_rate * since,
            thrust_rate,
            angle_base: self.angle_tolerance + self.angle_forget * since,
            angle_rate: self.angle_forget,
        }
    }
}
