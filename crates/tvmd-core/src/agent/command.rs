//! Command inversion: agent forces to gimbal angles and rotor speeds inside `E_f` (eq. 6).

use nalgebra::Vector3;

use crate::agent::admissible::AdmissibleSet;
use crate::agent::gimbal::GimbalCommand;
use crate::agent::limits::AgentLimits;
use crate::foundation::real::{eps, lit, Real};

/// One agent's actuator command.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AgentCommand<T: Real> {
    /// Inner gimbal angle `eta_x` (rad).
    pub eta_x: T,
    /// Outer gimbal angle `eta_y` (rad).
    pub eta_y: T,
    /// Thrust `T` (N).
    pub thrust: T,
    /// Rotor speed `omega` with `T = rho d^4 c_l omega^2` (eq. 5); normalized to 1 at maximum
    /// thrust when the limits were given without rotor constants.
    pub omega: T,
}

impl<T: Real> AgentCommand<T> {
    /// Rotors off, gimbal centred.
    pub fn idle() -> Self {
        Self {
            eta_x: T::zero(),
            eta_y: T::zero(),
            thrust: T::zero(),
            omega: T::zero(),
        }
    }

    /// The gimbal part.
    pub fn gimbal(&self) -> GimbalCommand<T> {
        GimbalCommand {
            thrust: self.thrust,
            eta_x: self.eta_x,
            eta_y: self.eta_y,
        }
    }

    /// The agent-frame force `T a_hat(eta_x, eta_y)`.
    pub fn force(&self) -> Vector3<T> {
        self.gimbal().force()
    }
}

/// The largest clamp [`invert`] may apply to an allocator's output: `1e3 eps` (rad for the
/// angles, relative to the maximum thrust for the thrust). Allocators return admissible
/// forces, so only round-off of the gimbal inverse is ever clamped.
pub fn command_tolerance<T: Real>() -> T {
    eps::<T>() * lit(1e3)
}

/// Inverts an agent-frame force into a command inside `set`. Returns the command and the clamp
/// it needed ([`AdmissibleSet::excess`]: rad for the angles, relative to the largest thrust for
/// the thrust). Non-finite forces give the clamped
/// idle command; a zero force, zero thrust with the gimbal clamped from centre into the set (no
/// clamp counted for the angles, which a zero force does not have).
pub fn invert<T: Real>(
    force: &Vector3<T>,
    set: &AdmissibleSet<T>,
    limits: &AgentLimits<T>,
) -> (AgentCommand<T>, T) {
    let raw = GimbalCommand::from_force(force);
    let g = set.clamp(&raw);
    // A zero force has no direction: every angle produces it at zero thrust, so the angles are
    // taken inside the set (a rate window need not hold the centred gimbal) and only the thrust
    // counts as a clamp.
    let clamp = if raw.thrust == T::zero() {
        set.excess(&GimbalCommand {
            thrust: raw.thrust,
            ..g
        })
    } else {
        set.excess(&raw)
    };
    (
        AgentCommand {
            eta_x: g.eta_x,
            eta_y: g.eta_y,
            thrust: g.thrust,
            omega: limits.speed_for_thrust(g.thrust),
        },
        clamp,
    )
}
