//! The cycle's guards: the bound on every input ([`crate::Controller::input_limit`]), its check, and
//! the safety net on non-finite outputs.

use nalgebra::Vector3;

use super::ControlOutput;
use crate::error::InputError;
use crate::law::{Gains, Reference, RigidState};
use crate::real::{count, lit, to_f64, Real};
use crate::team::TeamConfig;

/// [`InputError::OutOfRange`] for the first vector input with a component beyond `limit`
/// ([`crate::Controller::input_limit`]).
pub(super) fn check_range<T: Real>(
    limit: T,
    state: &RigidState<T>,
    reference: &Reference<T>,
) -> Result<(), InputError> {
    let vectors: [(&Vector3<T>, &'static str); 8] = [
        (&state.position, "state.position"),
        (&state.angular_velocity, "state.angular_velocity"),
        (&state.velocity, "state.velocity"),
        (&reference.position, "reference.position"),
        (&reference.velocity, "reference.velocity"),
        (&reference.acceleration, "reference.acceleration"),
        (&reference.angular_velocity, "reference.angular_velocity"),
        (
            &reference.angular_acceleration,
            "reference.angular_acceleration",
        ),
    ];
    for (v, field) in vectors {
        if v.iter().any(|x| x.abs() > limit) {
            return Err(InputError::OutOfRange {
                field,
                limit: to_f64(limit),
            });
        }
    }
    Ok(())
}

/// `B` of [`crate::Controller::input_limit`].
pub(super) fn input_limit<T: Real, const N: usize>(
    team: &TeamConfig<T, N>,
    gains: &Gains<T>,
    gravity: T,
) -> T {
    let row = |k: &nalgebra::Matrix3<T>| k.amax() * lit(3.0);
    let mass = team.mass();
    let quadratic = [
        row(&team.inertia()),
        row(&gains.k_x()),
        row(&gains.k_omega()),
        row(&gains.k_v()),
        mass,
    ]
    .iter()
    .fold(T::one(), |m, x| m.max(*x));
    let linear = [
        quadratic,
        row(&gains.k_r()),
        mass * gravity,
        count::<T>(team.len()) * team.limits().max_thrust(),
    ]
    .iter()
    .fold(T::one(), |m, x| m.max(*x));
    let max = T::max_value().unwrap_or_else(T::one);
    (max / linear).min((max / quadratic).sqrt()) / lit(64.0)
}

/// The first output field with a non-finite number (the cycle's safety net). Cheap: each part
/// sums `x * 0`, which is NaN exactly when some `x` is not finite (one multiply-add per number).
pub(super) fn first_non_finite<T: Real, const N: usize>(
    out: &ControlOutput<T, N>,
) -> Option<&'static str> {
    let zero = T::zero();
    let probe = |values: &[T]| values.iter().fold(zero, |acc, x| acc + *x * zero) == zero;
    let commands = out.commands.iter().fold(zero, |acc, c| {
        acc + (c.eta_x + c.eta_y + c.thrust + c.omega) * zero
    }) == zero;
    let forces = out
        .allocation
        .forces
        .iter()
        .fold(zero, |acc, f| acc + (f.x + f.y + f.z) * zero)
        == zero;
    let law = &out.law;
    if !commands {
        return Some("output.commands");
    }
    if !forces
        || !probe(out.allocation.wrench.as_slice())
        || !probe(&[out.allocation.e_f, out.allocation.wrench_error])
    {
        return Some("output.allocation");
    }
    if !probe(out.planner.r_d.as_slice()) || !probe(&[out.planner.theta]) {
        return Some("output.planner");
    }
    if !probe(out.projection.force.as_slice()) || !probe(out.f_r.as_slice()) {
        return Some("output.projection");
    }
    if !probe(law.u_r.as_slice())
        || !probe(law.u_d.as_slice())
        || !probe(law.e_xi.as_slice())
        || !probe(law.e_r.as_slice())
        || !probe(law.e_x.as_slice())
        || !probe(&[law.v_r, law.v_x])
    {
        return Some("output.law");
    }
    None
}
