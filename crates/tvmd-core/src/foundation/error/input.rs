//! [`InputError`]: a control-cycle input that cannot be used.

use core::fmt;

/// A control-cycle input that cannot be used. The cycle still returns a safe output with it.
///
/// Not `Eq`: [`InputError::OutOfRange`] carries the bound as an `f64`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum InputError {
    /// A NaN or infinite number in the named input.
    NonFinite {
        /// The input, e.g. `"state.position"`.
        field: &'static str,
    },
    /// A rotation matrix input is not a rotation (`R^T R != I` or `det R != 1` beyond tolerance).
    NotRotation {
        /// The input, e.g. `"state.attitude"`.
        field: &'static str,
    },
    /// A finite input too large for the float type to carry through the control cycle: a
    /// component beyond the controller's bound ([`crate::Controller::input_limit`]).
    OutOfRange {
        /// The input, e.g. `"state.angular_velocity"`.
        field: &'static str,
        /// The bound on `|component|` (the input's unit).
        limit: f64,
    },
    /// The force request `u_fr` is finite and non-zero, but the only admissible answer the
    /// cycle finds is every thrust zero (a downward request with no torque, a request at the
    /// cone's apex, or one that underflows): refused rather than commanding a free fall.
    Unattainable {
        /// The input, `"force_request"`.
        field: &'static str,
    },
    /// A safety net: an output of the cycle was not finite although every input was within
    /// its bound (should not happen; a bug report).
    Overflow {
        /// The output, e.g. `"output.commands"`.
        field: &'static str,
    },
}

impl InputError {
    /// The input (or output, for [`InputError::Overflow`]) the error names.
    pub const fn field(&self) -> &'static str {
        match *self {
            Self::NonFinite { field }
            | Self::NotRotation { field }
            | Self::OutOfRange { field, .. }
            | Self::Unattainable { field }
            | Self::Overflow { field } => field,
        }
    }
}

impl fmt::Display for InputError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Self::NonFinite { field } => {
                write!(f, "input `{field}` is not finite (NaN or infinite)")
            }
            Self::NotRotation { field } => write!(f, "input `{field}` is not a rotation matrix"),
            Self::OutOfRange { field, limit } => write!(
                f,
                "input `{field}` has a component beyond {limit:e}, too large for the control cycle's float type"
            ),
            Self::Unattainable { field } => write!(
                f,
                "`{field}` is non-zero but no admissible command other than zero thrust answers it"
            ),
            Self::Overflow { field } => write!(
                f,
                "`{field}` overflowed although every input was within bounds (a bug)"
            ),
        }
    }
}

#[cfg(feature = "std")]
impl std::error::Error for InputError {}
