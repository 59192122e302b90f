//! The cases of issue 13 ("safe on any input"): overflow- and underflow-safe norms and gimbal
//! inverse, the AFS's height sign, the projection of downward and huge requests, the
//! planner's rotation check, admissible allocations with honest `e_f`, and the controller's
//! input bound and zero-thrust rule, in `f32` and `f64`.

use std::f64::consts::{FRAC_PI_4, FRAC_PI_6};

use nalgebra::{Matrix3, Vector3, Vector6};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use tvmd_core::command::command_tolerance;
use tvmd_core::team::presets;
use tvmd_core::{
    project_force, AdmissibleSet, AgentLimits, AllocationRequest, Allocator, AttainableForceSpace,
    AttitudePlanner, Controller, ControllerSettings, FailureMask, GimbalCommand, InputError,
    PseudoInverse, Real, RedistributedPseudoInverse, Reference, Relaxation, RigidState, TeamConfig,
    WeightedPseudoInverse,
};

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs())
}

#[test]
fn gimbal_inverse_is_exact_at_any_magnitude() {
    // (Subnormal forces are not exact even forward: their components round absolutely.)
    for scale in [1e155, 1e-160, 1e300, 1e-300, f64::MAX / 2.0] {
        let f = GimbalCommand {
            thrust: scale,
            eta_x: 0.2,
            eta_y: -0.3,
        }
        .force();
        let g = GimbalCommand::from_force(&f);
        assert!(
            close(g.thrust, scale, 1e-12) || scale < 1e-300,
            "{scale}: {g:?}"
        );
        assert!((g.eta_x - 0.2).abs() < 1e-12, "{scale}: {g:?}");
        assert!((g.eta_y + 0.3).abs() < 1e-12, "{scale}: {g:?}");
    }
    // The exact calls.
    let g = GimbalCommand::from_force(
        &GimbalCommand {
            thrust: 1e155,
            eta_x: 0.2,
            eta_y: -0.3,
        }
        .force(),
    );
    assert!(close(g.thrust, 1e155, 1e-14) && (g.eta_x - 0.2).abs() < 1e-15);
    for scale in [1e19_f32, 1e-20, 1e38, 1e-38] {
        let f = GimbalCommand {
            thrust: scale,
            eta_x: 0.2_f32,
            eta_y: -0.3,
        }
        .force();
        let g = GimbalCommand::from_force(&f);
        assert!(
            (g.eta_x - 0.2).abs() < 1e-6 && (g.eta_y + 0.3).abs() < 1e-6,
            "{g:?}"
        );
        assert!(((g.thrust - scale) / scale).abs() < 1e-6, "{g:?}");
    }
}

fn paper_afs<T: Real>() -> AttainableForceSpace<T> {
    presets::a4_inc::<T, 4>()
        .unwrap()
        .afs(&FailureMask::none())
        .unwrap()
}

#[test]
fn projection_of_huge_tiny_and_downward_requests() {
    let afs = paper_afs::<f64>();
    let v = Vector3::new(0.3, -0.2, 1.0);
    let big = project_force(&afs, &(v * 1e155));
    assert!(big.force.z > 0.0, "{big:?}");
    assert!(afs.contains(&big.force, Relaxation::none()), "{big:?}");
    let unit = project_force(&afs, &(v * 100.0));
    assert!((big.force - unit.force).norm() < 1e-9 * unit.force.norm());
    // Tiny: inside, unchanged.
    let tiny = project_force(&afs, &(v * 1e-160));
    assert_eq!(tiny.force, v * 1e-160);
    // Downward: no K_f of this structure reaches the AFS but the apex.
    let down = project_force(&afs, &Vector3::new(0.1, 0.0, -1.0));
    assert_eq!(down.force, Vector3::zeros());
    assert_eq!((down.t_tf, down.t_eta), (0.0, 0.0));
    assert!(afs.contains(&down.force, Relaxation::none()));
}

/// Every projected force is a member of the AFS at `s = 1`, for requests of every size and
/// direction, in both precisions and on teams with and without the `sigma >= pi/2` branch.
fn projection_is_always_a_member<T: Real>() {
    let mut rng = StdRng::seed_from_u64(3);
    let half_pi = std::f64::consts::FRAC_PI_2;
    let max = T::max_value()
        .map(|m| m.to_subset().unwrap_or(f64::MAX))
        .unwrap();
    for (sx, sy) in [
        (FRAC_PI_6, FRAC_PI_4),
        (half_pi, 0.4),
        (0.3, half_pi),
        (half_pi, half_pi),
    ] {
        for (n, n_x) in [(4, 2), (4, 4), (6, 3), (3, 0)] {
            let afs = AttainableForceSpace::<T>::new(
                n,
                n_x,
                nalgebra::convert(sx),
                nalgebra::convert(sy),
                nalgebra::convert(13.734),
            )
            .unwrap();
            for _ in 0..2000 {
                let e: f64 = rng.random_range(-300.0..300.0);
                let scale = 10f64.powf(e).min(max / 4.0);
                let u = Vector3::from_fn(|_, _| rng.random_range(-1.0..1.0) * scale)
                    .map(nalgebra::convert::<f64, T>);
                let p = project_force(&afs, &u);
                assert!(p.force.iter().all(|x| x.is_finite()), "{u:?}");
                assert!(p.force.z >= T::zero(), "{u:?} -> {p:?}");
                assert!(
                    afs.contains(&p.force, Relaxation::none()),
                    "{u:?} -> {p:?} outside the AFS"
                );
            }
        }
    }
}

#[test]
fn projection_is_always_a_member_f32() {
    projection_is_always_a_member::<f32>();
}

#[test]
fn projection_is_always_a_member_f64() {
    projection_is_always_a_member::<f64>();
}

#[test]
fn afs_never_admits_a_downward_force() {
    let half_pi = std::f64::consts::FRAC_PI_2;
    // sigma_y = pi/2 gives the branch with an offset; s = 1.
    let afs = AttainableForceSpace::<f64>::new(4, 2, FRAC_PI_6, half_pi, 13.734).unwrap();
    let s = Relaxation::none();
    assert!(afs.semi_axes(1.0, s).unbounded_branch);
    assert!(!afs.contains(&Vector3::new(0.0, 0.0, -1.0), s));
    assert!(!afs.contains(&Vector3::new(0.0, 0.0, -1e-300), s));
    assert!(!afs.contains(&Vector3::new(0.1, 0.1, -1.0), s));
    // z = 0: admitted in that branch only.
    assert!(afs.contains(&Vector3::new(1.0, 0.0, 0.0), s));
    let narrow = paper_afs::<f64>();
    assert!(!narrow.contains(&Vector3::new(1.0, 0.0, 0.0), s));
    assert!(!narrow.contains(&Vector3::new(0.0, 0.0, -1.0), s));
    // The apex (all thrusts zero) is a member of both.
    assert!(narrow.contains(&Vector3::zeros(), s) && afs.contains(&Vector3::zeros(), s));
    // The planner never takes a downward force as feasible.
    let planner = AttitudePlanner::new(s);
    let out = planner
        .plan(&afs, &Matrix3::identity(), &Vector3::new(0.0, 0.0, -1.0))
        .unwrap();
    assert_ne!(out.status, tvmd_core::PlannerStatus::AlreadyFeasible);
    assert!((out.r_d.transpose() * Vector3::new(0.0, 0.0, -1.0)).z >= 0.0);
}

#[test]
fn planner_refuses_a_non_rotation() {
    let afs = paper_afs::<f64>();
    let planner = AttitudePlanner::new(Relaxation::new(0.5).unwrap());
    let f = Vector3::new(0.0, 0.0, 27.0);
    for r in [Matrix3::zeros(), Matrix3::identity() * 2.0] {
        assert_eq!(
            planner.plan(&afs, &r, &f),
            Err(InputError::NotRotation {
                field: "planner.r_r"
            })
        );
    }
    let mut r = Matrix3::identity();
    r[(0, 1)] = f64::NAN;
    assert_eq!(
        planner.plan(&afs, &r, &f),
        Err(InputError::NonFinite {
            field: "planner.r_r"
        })
    );
    // Huge and tiny requests plan without NaN.
    for scale in [1e155, 1e-160] {
        let out = planner
            .plan(
                &afs,
                &tvmd_core::rotation::roll(1.0),
                &(Vector3::new(0.0, 0.0, 1.0) * scale),
            )
            .unwrap();
        assert!(
            out.r_d.iter().all(|x| x.is_finite()) && out.theta.is_finite(),
            "{out:?}"
        );
    }
}

fn allocate<A: Allocator<f64, 4>>(
    a: &mut A,
    wrench: Vector6<f64>,
) -> tvmd_core::Allocation<f64, 4> {
    let team = presets::a4_inc::<f64, 4>().unwrap();
    let effectiveness = team.effectiveness(&FailureMask::none());
    let sets = [AdmissibleSet::from_limits(team.limits()); 4];
    a.configure(&effectiveness);
    let out = a.allocate(&AllocationRequest {
        effectiveness: &effectiveness,
        sets: &sets,
        wrench,
    });
    // Inside E_f, and e_f is what the forces produce.
    for (f, set) in out.forces.iter().zip(&sets) {
        let g = GimbalCommand::from_force(f);
        assert!(set.contains(&g, command_tolerance()), "{f:?} outside E_f");
        assert!(
            f.norm() <= team.limits().max_thrust() * (1.0 + 1e-12),
            "{f:?}"
        );
    }
    let produced = effectiveness.wrench(&out.forces);
    assert_eq!(produced, out.wrench);
    // The test's own scaled norm of the force residual.
    let d = wrench.fixed_rows::<3>(3) - produced.fixed_rows::<3>(3);
    let m = d.amax();
    let e_f = if m == 0.0 { 0.0 } else { (d / m).norm() * m };
    assert!(close(out.e_f, e_f, 1e-12), "{out:?}: {e_f}");
    out
}

#[test]
fn allocators_stay_admissible_and_honest_on_extreme_requests() {
    let weights = WeightedPseudoInverse::new([1.0, 2.0, 1.0, 0.5]).unwrap();
    for wrench in [
        Vector6::new(0.0, 0.0, 0.0, 0.0, 0.0, 1e155),
        Vector6::new(0.0, 0.0, 0.0, 0.0, 0.0, -1.0),
        Vector6::new(1e300, -1e300, 1e300, 1e300, 1e300, 1e300),
        Vector6::new(0.0, 0.0, 0.0, 0.0, 0.0, f64::MAX),
        Vector6::new(1e-300, 0.0, 0.0, 0.0, 1e-310, 1e-300),
    ] {
        let outs = [
            allocate(&mut PseudoInverse, wrench),
            allocate(&mut weights.clone(), wrench),
            allocate(&mut RedistributedPseudoInverse, wrench),
        ];
        for out in outs {
            assert!(
                out.e_f.is_finite() && out.wrench_error.is_finite(),
                "{out:?}"
            );
            if wrench[5] == 1e155 {
                // Every agent saturated at its maximum thrust, straight up.
                assert_eq!(out.saturated_count(), 4, "{out:?}");
                assert!(
                    out.forces.iter().all(|f| close(f.z, 13.734, 1e-9)),
                    "{out:?}"
                );
                assert!(close(out.e_f, 1e155, 1e-12));
            }
            if wrench[5] == -1.0 {
                // Nobody pushes down: the honest answer is no force, e_f = the request.
                assert!(out.e_f <= 1.0 + 1e-12, "{out:?}");
            }
        }
    }
}

#[cfg(feature = "clarabel")]
#[test]
fn clarabel_falls_back_on_a_request_out_of_its_range() {
    use tvmd_core::allocation::{ClarabelAllocator, FallbackReason};
    let mut a = ClarabelAllocator::<f64, 4>::default();
    let out = allocate(&mut a, Vector6::new(0.0, 0.0, 0.0, 0.0, 0.0, 1e155));
    assert!(out.fallback && out.e_f.is_finite());
    assert_eq!(
        a.last_report().unwrap().fallback,
        Some(FallbackReason::OutOfRange)
    );
    let out = allocate(&mut a, Vector6::new(0.0, 0.0, 0.0, 0.0, 0.0, -1.0));
    assert!(out.e_f <= 1.0 + 1e-6, "{out:?}");
}

fn controller<T: Real>() -> Controller<T, 4, RedistributedPseudoInverse> {
    Controller::new(
        presets::a4_inc().unwrap(),
        ControllerSettings::paper(),
        RedistributedPseudoInverse,
    )
    .unwrap()
}

fn hover_reference<T: Real>() -> Reference<T> {
    Reference::hover(Vector3::new(T::zero(), T::zero(), nalgebra::convert(1.5)))
}

#[test]
fn input_bound_of_the_paper_team() {
    let b32 = controller::<f32>().input_limit();
    let b64 = controller::<f64>().input_limit();
    // The values stated in Controller::input_limit's rustdoc and docs/method.md.
    assert!(close(f64::from(b32), 5.9e16, 0.01), "{b32:e}");
    assert!(close(b64, 4.3e151, 0.01), "{b64:e}");
}

#[test]
fn huge_inputs_are_refused_with_the_held_commands() {
    let mut c = controller::<f64>();
    let ok = c
        .step(
            &RigidState::at_rest(Vector3::new(0.0, 0.0, 1.5)),
            &hover_reference(),
        )
        .unwrap();
    // The first call: Omega = 1e154, Omega_d = e_y.
    let mut state = RigidState::at_rest(Vector3::new(0.0, 0.0, 1.5));
    state.angular_velocity.x = 1e154;
    let mut reference = hover_reference();
    reference.angular_velocity.y = 1.0;
    let e = c.step(&state, &reference).unwrap_err();
    assert_eq!(e.commands, ok.commands);
    assert!(matches!(
        e.error,
        InputError::OutOfRange {
            field: "state.angular_velocity",
            ..
        }
    ));
    // The second: position 1e200.
    let e = c
        .step(
            &RigidState::at_rest(Vector3::new(1e200, 0.0, 1.5)),
            &hover_reference(),
        )
        .unwrap_err();
    assert_eq!(e.error.field(), "state.position");
    assert!(e.to_string().contains("beyond"));
}

/// A finite input is refused or answered with admissible, non-zero commands.
fn refused_or_admissible<T: Real>(
    c: &mut Controller<T, 4, RedistributedPseudoInverse>,
    state: &RigidState<T>,
    reference: &Reference<T>,
) -> bool {
    let sets = c.admissible_sets();
    match c.step(state, reference) {
        Ok(out) => {
            for (cmd, set) in out.commands.iter().zip(&sets) {
                assert!(set.contains(&cmd.gimbal(), command_tolerance()), "{cmd:?}");
            }
            assert!(out.commands.iter().any(|c| c.thrust > T::zero()));
            assert!(out.allocation.e_f.is_finite());
            true
        }
        Err(e) => {
            assert!(
                matches!(
                    e.error,
                    InputError::OutOfRange { .. } | InputError::Unattainable { .. }
                ),
                "{e}"
            );
            false
        }
    }
}

#[test]
fn f32_cycle_on_large_inputs() {
    let mut c = controller::<f32>();
    // Omega and Omega_d both 1e10: inside the f32 bound, answered (saturated, non-zero).
    let mut state = RigidState::at_rest(Vector3::new(0.0, 0.0, 1.5));
    state.angular_velocity.x = 1e10;
    let mut reference = hover_reference();
    reference.angular_velocity.y = 1e10;
    assert!(refused_or_admissible(&mut c, &state, &reference));
    // 1e19 in one field: beyond the bound, refused.
    for field in 0..3 {
        let mut state = RigidState::at_rest(Vector3::new(0.0, 0.0, 1.5));
        match field {
            0 => state.position.x = 1e19,
            1 => state.velocity.y = 1e19,
            _ => state.angular_velocity.z = 1e19,
        }
        assert!(!refused_or_admissible(&mut c, &state, &hover_reference()));
    }
    // Just inside the bound, in every field at once: still finite and admissible or refused.
    let b = c.input_limit() * 0.99;
    let v = Vector3::new(b, -b, b);
    let state = RigidState {
        position: v,
        attitude: Matrix3::identity(),
        angular_velocity: v,
        velocity: -v,
    };
    let reference = Reference {
        position: -v,
        velocity: v,
        acceleration: v,
        attitude: Matrix3::identity(),
        angular_velocity: -v,
        angular_acceleration: v,
    };
    refused_or_admissible(&mut c, &state, &reference);
}

#[test]
fn zero_thrust_for_a_non_zero_request_is_refused() {
    let mut c = controller::<f64>();
    let held = c
        .step(
            &RigidState::at_rest(Vector3::new(0.0, 0.0, 1.5)),
            &hover_reference(),
        )
        .unwrap()
        .commands;
    // Far above the reference, at rest: u_fr points down, no torque is asked.
    let e = c
        .step(
            &RigidState::at_rest(Vector3::new(0.0, 0.0, 200.0)),
            &hover_reference(),
        )
        .unwrap_err();
    assert_eq!(
        e.error,
        InputError::Unattainable {
            field: "force_request"
        }
    );
    assert_eq!(e.commands, held);
}

#[test]
fn idle_thrust_keeps_the_commands_non_zero() {
    // With an idle thrust the downward request is answered at idle, never zero.
    let limits = AgentLimits::new(FRAC_PI_6, FRAC_PI_4, 13.734)
        .unwrap()
        .with_min_thrust(0.5)
        .unwrap();
    let team = TeamConfig::<f64, 4>::new(
        presets::a4_inc::<f64, 4>().unwrap().agents(),
        limits,
        tvmd_core::Navigator::default(),
    )
    .unwrap();
    let mut c = Controller::new(
        team,
        ControllerSettings::paper(),
        RedistributedPseudoInverse,
    )
    .unwrap();
    let out = c
        .step(
            &RigidState::at_rest(Vector3::new(0.0, 0.0, 200.0)),
            &hover_reference(),
        )
        .unwrap();
    assert!(
        out.commands.iter().all(|c| (c.thrust - 0.5).abs() < 1e-12),
        "{out:?}"
    );
}
