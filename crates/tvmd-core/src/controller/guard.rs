//! The cycle's guards: the bound on every input ([`crate::Controller::input_limit`]), its check, and
//! the safety net on non-finite outputs.

use nalgebra::Vector3;

use super::ControlOutput;
use crate::afs::planner::PlannerOutput;
use crate::afs::projection::ForceProjection;
use crate::agent::command::AgentCommand;
use crate::allocation::Allocation;
use crate::foundation::error::InputError;
use crate::foundation::real::{count, lit, sqrt, to_f64, Real};
use crate::law::{Gains, LawOutput, Reference, RigidState};
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
    (max / linear).min(sqrt(max / quadratic)) / lit(64.0)
}

/// The first output field with a non-finite number (the cycle's safety net). Cheap: each part
/// sums `x * 0`, which is NaN exactly when some `x` is not finite (one multiply-add per number).
pub(super) fn first_non_finite<T: Real, const N: usize>(
    out: &ControlOutput<T, N>,
) -> Option<&'static str> {
    if let Some(field) = first_non_finite_allocation(&out.commands, &out.allocation) {
        return Some(field);
    }
    first_non_finite_law(&out.planner, &out.projection, &out.f_r, &out.law)
}

/// As [`first_non_finite`] for the law stage's part: the planner, the projection, the law.
pub(super) fn first_non_finite_law<T: Real>(
    planner: &PlannerOutput<T>,
    projection: &ForceProjection<T>,
    f_r: &Vector3<T>,
    law: &LawOutput<T>,
) -> Option<&'static str> {
    if !probe(planner.r_d.as_slice()) || !probe(&[planner.theta]) {
        return Some("output.planner");
    }
    if !probe(projection.force.as_slice()) || !probe(f_r.as_slice()) {
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

/// As [`first_non_finite`] for the allocation stage's part: the commands, then the allocation.
pub(super) fn first_non_finite_allocation<T: Real, const N: usize>(
    commands: &[AgentCommand<T>; N],
    allocation: &Allocation<T, N>,
) -> Option<&'static str> {
    let zero = T::zero();
    let commands = commands.iter().fold(zero, |acc, c| {
        acc + (c.eta_x + c.eta_y + c.thrust + c.omega) * zero
    }) == zero;
    let forces = allocation
        .forces
        .iter()
        .fold(zero, |acc, f| acc + (f.x + f.y + f.z) * zero)
        == zero;
    if !commands {
        return Some("output.commands");
    }
    if !forces
        || !probe(allocation.wrench.as_slice())
        || !probe(&[allocation.e_f, allocation.wrench_error])
    {
        return Some("output.allocation");
    }
    None
}

/// Whether every value is finite (`sum x * 0 == 0`).
fn probe<T: Real>(values: &[T]) -> bool {
    let zero = T::zero();
    values.iter().fold(zero, |acc, x| acc + *x * zero) == zero
}
