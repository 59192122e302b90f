//! The cycle's stages (`Controller::plan`, `law`, `allocate`) against the full `step`: the law
//! then the allocation is the step bit for bit (paper's and offset-free law, over a closed
//! loop with a disturbance), the planner alone plans what the step plans, and the allocation
//! stage refuses bad wrenches with the held commands.

mod flight;

use flight::{rk4, Body, Truth};
use tvmd_core::nalgebra::{Matrix3, Vector3, Vector6};
use tvmd_core::rotation::roll;
use tvmd_core::team::presets;
use tvmd_core::{
    Controller, ControllerSettings, ExactBoundaryRedistribution, InputError,
    RedistributedPseudoInverse, Reference, RoundCap,
};

fn truth() -> Truth {
    let team = presets::a4_inc::<f64, 4>().unwrap();
    Truth {
        mass: team.mass() * 1.05,
        inertia: team.inertia(),
        gravity: 9.81,
        force: Vector3::new(0.4, -0.3, -0.5),
        torque: Vector3::new(0.02, 0.0, 0.03),
    }
}

/// Two identical controllers, one stepped, one driven by `law` then `allocate`, flown in the
/// same closed loop through the tilt: every output equal, every period.
#[test]
fn law_then_allocate_is_the_step_bit_for_bit() {
    for settings in [
        ControllerSettings::<f64>::paper(),
        ControllerSettings::offset_free_law(),
    ] {
        let team = presets::a4_inc::<f64, 4>().unwrap();
        let mut whole =
            Controller::new(team, settings, ExactBoundaryRedistribution::new()).unwrap();
        let mut staged = whole.clone();
        let truth = truth();
        let mut body = Body::at(Vector3::new(0.2, -0.1, 1.5));
        for k in 0..300 {
            let t = k as f64 * 0.01;
            let mut reference = Reference::hover(Vector3::new(0.0, 0.0, 1.5));
            reference.attitude = roll((t * 0.5).min(1.0));
            let state = body.state();
            let out = whole.step(&state, &reference).unwrap();
            let law = staged.law(&state, &reference).unwrap();
            // The attitude stage alone gives the law stage's torque for its planned attitude.
            let attitude = staged
                .attitude(&state, &law.planner.r_d, &reference)
                .unwrap();
            assert_eq!(attitude.u_tau.as_slice(), &law.law.u_d.as_slice()[..3]);
            assert_eq!(attitude.e_r, law.law.e_r);
            let alloc = staged.allocate(&law.law.u_d).unwrap();
            assert_eq!(law.planner, out.planner, "period {k}");
            assert_eq!(law.projection, out.projection);
            assert_eq!(law.law, out.law);
            assert_eq!(alloc.allocation, out.allocation);
            assert_eq!(alloc.commands, out.commands);
            assert_eq!(
                staged.offset_free_compensation(),
                whole.offset_free_compensation()
            );
            let torque =
                (out.law.u_d.fixed_rows::<3>(0) - out.allocation.wrench.fixed_rows::<3>(0)).norm();
            assert!((alloc.torque_error - torque).abs() <= 1e-12 * (1.0 + torque));
            for _ in 0..10 {
                body = rk4(&body, &truth, &out.allocation.wrench, 0.001);
            }
        }
        assert_eq!(staged.previous_commands(), whole.previous_commands());
    }
}

/// The planner alone plans what the step planned, for the step's `f_r`.
#[test]
fn plan_is_the_steps_planner() {
    let team = presets::a4_inc::<f64, 4>().unwrap();
    let mut c = Controller::new(
        team,
        ControllerSettings::paper(),
        RedistributedPseudoInverse,
    )
    .unwrap();
    let mut reference = Reference::hover(Vector3::new(0.0, 0.0, 1.5));
    reference.attitude = roll(1.0);
    let state = Body::at(Vector3::new(0.2, 0.0, 1.5)).state();
    let out = c.step(&state, &reference).unwrap();
    let planned = c.plan(&reference.attitude, &out.f_r).unwrap();
    assert_eq!(planned, out.planner);
    assert!(planned.theta > 0.0);
    assert!(matches!(
        c.plan(&(Matrix3::identity() * 2.0), &out.f_r),
        Err(InputError::NotRotation { .. })
    ));
    assert!(matches!(
        c.plan(&reference.attitude, &Vector3::new(f64::NAN, 0.0, 1.0)),
        Err(InputError::NonFinite { .. })
    ));
}

/// The allocation stage alone (a flight stack's allocator): the hover wrench is met, a NaN
/// wrench is refused with the held commands, and a force no thrust can give is reported as
/// missed.
#[test]
fn allocate_meets_a_wrench_and_refuses_a_bad_one() {
    let team = presets::a4_inc::<f64, 4>().unwrap();
    let weight = team.mass() * 9.81;
    let mut c = Controller::new(
        team,
        ControllerSettings::paper(),
        ExactBoundaryRedistribution::new(),
    )
    .unwrap();
    let hover = Vector6::new(0.0, 0.0, 0.0, 0.0, 0.0, weight);
    let out = c.allocate(&hover).unwrap();
    assert!(out.allocation.e_f < 1e-9 && out.torque_error < 1e-9);
    assert_eq!(c.previous_commands(), &out.commands);
    let total: f64 = out.commands.iter().map(|x| x.thrust).sum();
    assert!((total - weight).abs() < 1e-6, "{total}");
    let bad = Vector6::new(0.0, f64::NAN, 0.0, 0.0, 0.0, weight);
    let held = c.allocate(&bad).unwrap_err();
    assert_eq!(held.error, InputError::NonFinite { field: "wrench" });
    assert_eq!(held.commands, out.commands);
    // Straight down: no thrust can push the team down, and the answer says so, never as a
    // silent success. The default walk (capped at 2 rounds) ends with every agent idle: the
    // request is refused as unattainable and the last commands are held.
    let down = Vector6::new(0.0, 0.0, 0.0, 0.0, 0.0, -weight);
    let refused = c.allocate(&down).unwrap_err();
    assert_eq!(refused.error, InputError::Unattainable { field: "wrench" });
    assert_eq!(refused.commands, out.commands);
    // Uncapped, the walk ends on some thrust and reports the whole request missed in `e_f`.
    let mut uncapped = Controller::new(
        presets::a4_inc::<f64, 4>().unwrap(),
        ControllerSettings::paper(),
        ExactBoundaryRedistribution::new().with_round_cap(RoundCap::Uncapped),
    )
    .unwrap();
    let missed = uncapped.allocate(&down).unwrap();
    assert!((missed.allocation.e_f - weight).abs() < 1e-3, "{missed:?}");
}
