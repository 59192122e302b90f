//! The Clarabel allocator (feature `clarabel`): constraints, agreement with the pseudo-inverse,
//! never worse than the redistributed pseudo-inverse on its own feasible set, failures, reuse of
//! the solver between calls, and the fallback.
#![cfg(feature = "clarabel")]

use nalgebra::{Vector3, Vector6};
use proptest::prelude::*;
use tvmd_core::admissible::RateLimits;
use tvmd_core::allocation::{ClarabelAllocator, ClarabelStatus, FallbackReason};
use tvmd_core::error::ConfigField;
use tvmd_core::team::presets;
use tvmd_core::{
    AdmissibleSet, Allocation, AllocationRequest, Allocator, ConfigError, FailureMask,
    GimbalCommand, PseudoInverse, RedistributedPseudoInverse, TeamConfig,
};

const CAP: usize = 10;
type Team = TeamConfig<f64, CAP>;

fn ring(n: usize, inc: bool, radius: f64) -> Team {
    presets::ring(n, radius, inc, presets::paper_limits()).unwrap()
}

fn team_by_index(which: usize, radius: f64) -> Team {
    match which {
        0 => presets::a4_inc().unwrap(),
        1 => presets::a4_con().unwrap(),
        k => ring(3 + k % 8, k % 2 == 0, radius),
    }
}

fn sets_of(team: &Team) -> [AdmissibleSet<f64>; CAP] {
    [AdmissibleSet::from_limits(team.limits()); CAP]
}

/// The convex inner bound of the symmetric set, with tolerance `tol`.
fn assert_in_pyramid(f: &Vector3<f64>, set: &AdmissibleSet<f64>, tol: f64) {
    let (tx, ty) = (set.eta_x().hi.tan(), set.eta_y().hi.tan());
    assert!(f.z >= -tol, "f_z = {} < 0", f.z);
    assert!(
        f.x.abs() <= f.z * ty + tol,
        "|f_x| > f_z tan(sigma_y): {f:?}"
    );
    assert!(
        f.y.abs() <= f.z * tx + tol,
        "|f_y| > f_z tan(sigma_x): {f:?}"
    );
    assert!(f.norm() <= set.thrust().hi + tol, "||f|| > max: {f:?}");
    let cmd = GimbalCommand::from_force(f);
    assert!(
        set.contains(&cmd, 1e-9),
        "outside the admissible set: {cmd:?}"
    );
}

/// `||W (M f - u)||` computed from the returned wrench.
fn weighted_error(a: &Allocation<f64, CAP>, u: &Vector6<f64>, w: &[f64; 6]) -> f64 {
    (u - a.wrench)
        .iter()
        .zip(w)
        .map(|(e, w)| (e * w).powi(2))
        .sum::<f64>()
        .sqrt()
}

/// Whether the force lies in the allocator's inner bound (so the QP could have chosen it).
fn in_pyramid(f: &Vector3<f64>, set: &AdmissibleSet<f64>, tol: f64) -> bool {
    let (tx, ty) = (set.eta_x().hi.tan(), set.eta_y().hi.tan());
    f.z >= -tol
        && f.x.abs() <= f.z * ty + tol
        && f.y.abs() <= f.z * tx + tol
        && f.norm() <= set.thrust().hi + tol
}

#[test]
fn configuration_is_validated() {
    assert!(ClarabelAllocator::<f64, 4>::new(0.0, None).is_ok());
    for bad in [-1e-9, f64::NAN, f64::INFINITY] {
        assert_eq!(
            ClarabelAllocator::<f64, 4>::new(bad, None).unwrap_err(),
            ConfigError::Parameter {
                field: ConfigField::ClarabelLambda
            }
        );
    }
    let e =
        ClarabelAllocator::<f64, 4>::new(1e-6, Some([1.0, 1.0, 0.0, 1.0, 1.0, 1.0])).unwrap_err();
    assert_eq!(
        e,
        ConfigError::Parameter {
            field: ConfigField::ClarabelWeights
        }
    );
    let e = ClarabelAllocator::<f64, 4>::default()
        .with_tolerance(0.0)
        .unwrap_err();
    assert_eq!(
        e,
        ConfigError::Parameter {
            field: ConfigField::ClarabelTolerance
        }
    );
    let a = ClarabelAllocator::<f64, 4>::new(2e-3, Some([2.0; 6])).unwrap();
    assert_eq!(a.lambda(), 2e-3);
    assert_eq!(a.weights(), [2.0; 6]);
    assert_eq!(Allocator::<f64, 4>::name(&a), "clarabel");
    assert!(a.last_report().is_none());
    assert!(format!("{a:?}").contains("ClarabelAllocator"));
}

#[test]
fn is_send_and_sync() {
    fn check<A: Send + Sync>() {}
    check::<ClarabelAllocator<f64, 4>>();
    check::<ClarabelAllocator<f32, 16>>();
}

#[test]
fn hover_is_exact_and_reports() {
    let team: Team = presets::a4_inc().unwrap();
    let e = team.effectiveness(&FailureMask::none());
    let sets = sets_of(&team);
    let weight = team.mass() * 9.81;
    let request = AllocationRequest {
        effectiveness: &e,
        sets: &sets,
        wrench: Vector6::new(0.0, 0.0, 0.0, 0.0, 0.0, weight),
    };
    // The unconstrained minimiser is admissible: Clarabel is skipped.
    let mut alloc = ClarabelAllocator::<f64, CAP>::new(1e-9, None).unwrap();
    let a = alloc.allocate(&request);
    let report = *alloc.last_report().unwrap();
    assert!(report.unconstrained && report.is_optimal() && !a.fallback);
    assert_eq!(
        (report.status, report.iterations),
        (ClarabelStatus::Unsolved, 0)
    );
    assert!(report.to_string().contains("not called"));
    assert!(a.wrench_error <= 1e-9 * weight, "{}", a.wrench_error);

    // Without the shortcut, the solver finds the same.
    let mut alloc = ClarabelAllocator::<f64, CAP>::new(1e-9, None)
        .unwrap()
        .with_shortcut(false);
    let a = alloc.allocate(&request);
    assert!(!a.fallback);
    assert!(a.wrench_error <= 1e-6 * weight, "{}", a.wrench_error);
    for f in &a.forces[..4] {
        assert!((f - Vector3::new(0.0, 0.0, weight / 4.0)).norm() < 1e-6 * weight);
    }
    assert_eq!(a.saturated_count(), 0);
    let report = *alloc.last_report().unwrap();
    assert_eq!(report.status, ClarabelStatus::Solved);
    assert!(report.iterations > 0 && a.rounds == report.iterations);
    assert!(report.rebuilt && !report.is_fallback() && !report.unconstrained);
    assert!(report.polished, "{report}");
    assert!(report.objective >= 0.0 && report.objective < 1e-6);
    assert!(report.wall_time >= report.solver_time);
    let text = report.to_string();
    assert!(
        text.contains("Solved") && !text.contains("fell back"),
        "{text}"
    );

    // Same structure again: updated in place, not rebuilt.
    let a2 = alloc.allocate(&request);
    assert!(!alloc.last_report().unwrap().rebuilt);
    assert!((a2.wrench - a.wrench).norm() < 1e-9);
}

#[test]
fn failed_agents_get_zero_force_and_rebuild_the_structure() {
    let team = ring(6, true, 0.6);
    let mut alloc = ClarabelAllocator::<f64, CAP>::default().with_shortcut(false);
    let sets = sets_of(&team);
    let wrench = Vector6::new(0.5, -0.3, 0.2, 1.0, -2.0, team.mass() * 9.81);
    for (failed, rebuilt) in [
        (vec![], true),
        (vec![2], true),
        (vec![2], false),
        (vec![2, 5], true),
        (vec![], true),
    ] {
        let e = team.effectiveness(&FailureMask::with_failed(&failed).unwrap());
        let request = AllocationRequest {
            effectiveness: &e,
            sets: &sets,
            wrench,
        };
        let a = alloc.allocate(&request);
        let report = alloc.last_report().unwrap();
        assert_eq!(report.rebuilt, rebuilt, "failed {failed:?}");
        assert!(!a.fallback, "{report}");
        for (i, f) in a.forces.iter().enumerate() {
            if failed.contains(&i) || i >= 6 {
                assert_eq!(*f, Vector3::zeros());
            } else {
                assert_in_pyramid(f, &sets[i], 1e-7);
            }
        }
        // The same call on a fresh allocator gives the same answer.
        let fresh = ClarabelAllocator::<f64, CAP>::default().allocate(&request);
        assert!(!a.saturated.iter().any(|s| *s));
        for (f, g) in a.forces.iter().zip(&fresh.forces) {
            assert!((f - g).norm() < 1e-6, "{f:?} vs {g:?}");
        }
    }
}

#[test]
fn no_working_agent_falls_back_to_zero() {
    let team: Team = presets::a4_inc().unwrap();
    let e = team.effectiveness(&FailureMask::with_failed(&[0, 1, 2, 3]).unwrap());
    let sets = sets_of(&team);
    let request = AllocationRequest {
        effectiveness: &e,
        sets: &sets,
        wrench: Vector6::new(0.0, 0.0, 0.0, 0.0, 0.0, 10.0),
    };
    let mut alloc = ClarabelAllocator::<f64, CAP>::default();
    let a = alloc.allocate(&request);
    assert!(a.fallback);
    assert!(a.forces.iter().all(|f| *f == Vector3::zeros()));
    assert_eq!(
        alloc.last_report().unwrap().fallback,
        Some(FallbackReason::NoAgents)
    );
}

#[test]
fn solver_failure_falls_back_to_the_redistributed_pseudo_inverse() {
    let team: Team = presets::a4_inc().unwrap();
    let e = team.effectiveness(&FailureMask::none());
    let sets = sets_of(&team);
    let request = AllocationRequest {
        effectiveness: &e,
        sets: &sets,
        wrench: Vector6::new(3.0, -2.0, 1.0, 15.0, -10.0, 40.0),
    };
    let mut alloc = ClarabelAllocator::<f64, CAP>::default().with_max_iterations(1);
    let a = alloc.allocate(&request);
    let report = *alloc.last_report().unwrap();
    assert!(a.fallback);
    assert_eq!(report.status, ClarabelStatus::MaxIterations);
    assert_eq!(report.fallback, Some(FallbackReason::Status));
    assert!(report
        .to_string()
        .contains("fell back to the redistributed pseudo-inverse"));
    let mut rpi = RedistributedPseudoInverse.allocate(&request);
    rpi.fallback = true;
    assert_eq!(a, rpi);
    for (f, set) in a.forces.iter().zip(&sets).take(4) {
        assert!(set.contains(&GimbalCommand::from_force(f), 1e-9));
    }

    // Non-finite input never reaches the solver.
    let request = AllocationRequest {
        wrench: Vector6::new(f64::NAN, 0.0, 0.0, 0.0, 0.0, 10.0),
        ..request
    };
    let mut alloc = ClarabelAllocator::<f64, CAP>::default();
    let a = alloc.allocate(&request);
    assert!(a.fallback);
    let report = alloc.last_report().unwrap();
    assert_eq!(report.fallback, Some(FallbackReason::NonFiniteInput));
    assert_eq!(report.status, ClarabelStatus::Unsolved);
}

#[test]
fn minimum_thrust_is_kept() {
    let limits = presets::paper_limits::<f64>().with_min_thrust(2.0).unwrap();
    let team: Team = presets::square([1, 1, 0, 0], limits).unwrap();
    let e = team.effectiveness(&FailureMask::none());
    let sets = [AdmissibleSet::from_limits(team.limits()); CAP];
    let mut alloc = ClarabelAllocator::<f64, CAP>::default();
    // A strong roll torque would want some agents below idle.
    let request = AllocationRequest {
        effectiveness: &e,
        sets: &sets,
        wrench: Vector6::new(6.0, 0.0, 0.0, 0.0, 0.0, 12.0),
    };
    let a = alloc.allocate(&request);
    assert!(!a.fallback);
    for f in &a.forces[..4] {
        assert!(f.z >= 2.0 - 1e-7, "{f:?}");
        assert!(sets[0].contains(&GimbalCommand::from_force(f), 1e-9));
    }
    assert!(a.saturated_count() > 0);
}

#[test]
fn runs_in_f32() {
    let team = presets::a4_inc::<f32, 4>().unwrap();
    let e = team.effectiveness(&FailureMask::none());
    let sets = [AdmissibleSet::from_limits(team.limits()); 4];
    let request = AllocationRequest {
        effectiveness: &e,
        sets: &sets,
        wrench: Vector6::new(0.1, -0.1, 0.05, 1.0, 0.5, team.mass() * 9.81),
    };
    let mut alloc = ClarabelAllocator::<f32, 4>::new(1e-9, None).unwrap();
    let a = alloc.allocate(&request);
    let pi = PseudoInverse.allocate(&request);
    assert!(!a.fallback);
    for (f, g) in a.forces.iter().zip(&pi.forces) {
        assert!((f - g).norm() < 1e-4, "{f:?} vs {g:?}");
    }
}

#[test]
fn clones_rebuild_their_solver() {
    let team: Team = presets::a4_con().unwrap();
    let e = team.effectiveness(&FailureMask::none());
    let sets = sets_of(&team);
    let request = AllocationRequest {
        effectiveness: &e,
        sets: &sets,
        wrench: Vector6::new(0.0, 0.0, 0.0, 1.0, 0.0, 20.0),
    };
    let mut a = ClarabelAllocator::<f64, CAP>::default().with_shortcut(false);
    let first = a.allocate(&request);
    let mut b = a.clone();
    assert_eq!(b.last_report(), a.last_report());
    let second = b.allocate(&request);
    assert!(b.last_report().unwrap().rebuilt);
    assert!((first.wrench - second.wrench).norm() < 1e-9);
}

fn random_wrench(u: [f64; 6], scale: f64, weight: f64) -> Vector6<f64> {
    Vector6::new(
        u[0] * scale,
        u[1] * scale,
        u[2] * scale,
        u[3] * scale * 4.0,
        u[4] * scale * 4.0,
        weight + u[5] * scale * 4.0,
    )
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    /// Every returned force satisfies the pyramid, the cone and `f_z >= 0` to `1e-7`, whatever
    /// the request (feasible or not, with or without a failure).
    #[test]
    fn constraints_hold(
        which in 0usize..10, radius in 0.3f64..1.2,
        u in prop::array::uniform6(-1.0f64..1.0), scale in 0.0f64..30.0,
        fail in prop::option::of(0usize..10), weighted in any::<bool>(),
    ) {
        let team = team_by_index(which, radius);
        let n = team.len();
        let failures = match fail.filter(|i| *i < n && n >= 4) {
            Some(i) => FailureMask::with_failed(&[i]).unwrap(),
            None => FailureMask::none(),
        };
        let e = team.effectiveness(&failures);
        let sets = sets_of(&team);
        let wrench = random_wrench(u, scale, team.mass() * 9.81);
        let request = AllocationRequest { effectiveness: &e, sets: &sets, wrench };
        let w = if weighted { Some([3.0, 3.0, 1.0, 1.0, 1.0, 2.0]) } else { None };
        let mut alloc = ClarabelAllocator::<f64, CAP>::new(1e-6, w).unwrap();
        let a = alloc.allocate(&request);
        prop_assert!(!a.fallback, "{}", alloc.last_report().unwrap());
        for (i, (f, set)) in a.forces.iter().zip(&sets).enumerate() {
            if i >= n || failures.is_failed(i) {
                prop_assert_eq!(*f, Vector3::zeros());
            } else {
                assert_in_pyramid(f, set, 1e-7);
            }
        }
    }

    /// Near hover the pseudo-inverse is admissible, and the QP with a tiny `lambda` finds it.
    #[test]
    fn matches_the_pseudo_inverse_when_it_is_admissible(
        which in 0usize..10, radius in 0.3f64..1.2,
        torque in prop::array::uniform3(-0.5f64..0.5), lateral in prop::array::uniform2(-1.0f64..1.0),
        weighted in any::<bool>(),
    ) {
        let team = team_by_index(which, radius);
        let e = team.effectiveness(&FailureMask::none());
        let sets = sets_of(&team);
        let weight = team.mass() * 9.81;
        let wrench = Vector6::new(torque[0], torque[1], torque[2], lateral[0], lateral[1], weight);
        let request = AllocationRequest { effectiveness: &e, sets: &sets, wrench };
        let pi = PseudoInverse.allocate(&request);
        prop_assume!(pi.saturated_count() == 0);
        prop_assume!(pi.forces.iter().zip(&sets).all(|(f, s)| in_pyramid(f, s, 0.0)));
        // Exact wrench for any W, so W does not change the minimum-norm answer.
        let w = if weighted { Some([3.0, 3.0, 1.0, 1.0, 1.0, 2.0]) } else { None };
        let mut alloc = ClarabelAllocator::<f64, CAP>::new(1e-9, w).unwrap();
        let a = alloc.allocate(&request);
        prop_assert!(!a.fallback);
        for (f, g) in a.forces.iter().zip(&pi.forces) {
            prop_assert!((f - g).norm() <= 1e-6 * weight, "{:?} vs {:?}", f, g);
        }
        prop_assert!(a.wrench_error <= 1e-6 * weight);
    }

    /// Over infeasible requests the QP's weighted wrench error is never above the redistributed
    /// pseudo-inverse's when that answer lies in the QP's feasible set (then it is a candidate
    /// of the QP); it may be when the redistribution uses the corners of the exact gimbal set
    /// outside the pyramid, which the QP's inner bound excludes.
    #[test]
    fn never_worse_than_the_redistributed_pseudo_inverse(
        which in 0usize..10, radius in 0.3f64..1.2,
        u in prop::array::uniform6(-1.0f64..1.0), scale in 8.0f64..40.0,
        weighted in any::<bool>(),
    ) {
        let team = team_by_index(which, radius);
        let e = team.effectiveness(&FailureMask::none());
        let sets = sets_of(&team);
        let wrench = random_wrench(u, scale, team.mass() * 9.81);
        let request = AllocationRequest { effectiveness: &e, sets: &sets, wrench };
        let rpi = RedistributedPseudoInverse.allocate(&request);
        prop_assume!(rpi.saturated_count() > 0);
        let w = if weighted { [3.0, 3.0, 1.0, 1.0, 1.0, 2.0] } else { [1.0; 6] };
        let mut alloc = ClarabelAllocator::<f64, CAP>::new(1e-9, Some(w)).unwrap();
        let a = alloc.allocate(&request);
        prop_assert!(!a.fallback);
        let (mine, theirs) = (weighted_error(&a, &wrench, &w), weighted_error(&rpi, &wrench, &w));
        let rpi_in_qp_set = rpi.forces.iter().zip(&sets).take(team.len()).all(|(f, s)| in_pyramid(f, s, 1e-12));
        if rpi_in_qp_set {
            prop_assert!(mine <= theirs + 1e-6 * (1.0 + theirs), "clarabel {} > rpi {}", mine, theirs);
        }
    }

    /// Rate-limited windows (which may exclude zero, where the `eta_x` side becomes a cone):
    /// still admissible, and a reused solver answers as a fresh one.
    #[test]
    fn rate_limited_sets_and_reuse(
        which in 0usize..10, radius in 0.3f64..1.2,
        steps in prop::collection::vec((prop::array::uniform6(-1.0f64..1.0), 0.0f64..30.0), 1..6),
        previous in prop::collection::vec((-0.5f64..0.5, -0.75f64..0.75), CAP),
        rate in 0.5f64..10.0,
    ) {
        let team = team_by_index(which, radius);
        let e = team.effectiveness(&FailureMask::none());
        let base = AdmissibleSet::from_limits(team.limits());
        let rates = RateLimits::new(rate, rate).unwrap();
        let mut sets = [base; CAP];
        for (set, (ex, ey)) in sets.iter_mut().zip(&previous) {
            let prev = GimbalCommand { thrust: 5.0, eta_x: *ex, eta_y: *ey };
            *set = base.with_rate_limit(&prev, &rates, 0.01);
        }
        let mut alloc = ClarabelAllocator::<f64, CAP>::default();
        for (u, scale) in steps {
            let wrench = random_wrench(u, scale, team.mass() * 9.81);
            let request = AllocationRequest { effectiveness: &e, sets: &sets, wrench };
            let a = alloc.allocate(&request);
            prop_assert!(!a.fallback, "{}", alloc.last_report().unwrap());
            for (f, set) in a.forces.iter().zip(&sets).take(team.len()) {
                // A zero force has no direction (`from_force` centres the gimbal), so only its
                // thrust is checked.
                let mut cmd = GimbalCommand::from_force(f);
                if cmd.thrust == 0.0 {
                    cmd = set.clamp(&cmd);
                }
                prop_assert!(set.contains(&cmd, 1e-9), "{:?} outside {:?}", cmd, set);
            }
            // A reused solver reaches the optimum as a new one does. (With a small `lambda` the
            // optimum is nearly flat along the null space of `W M`, so forces are compared
            // through the objective, to the solver's gap tolerance on the scale `||W u||^2`, or
            // to Clarabel's reduced tolerance when either run stopped `AlmostSolved`.)
            let mine = alloc.last_report().unwrap().objective;
            let mut fresh = ClarabelAllocator::<f64, CAP>::default();
            fresh.allocate(&request);
            let theirs = fresh.last_report().unwrap().objective;
            let almost = [alloc.last_report().unwrap(), fresh.last_report().unwrap()]
                .iter()
                .any(|r| r.status == ClarabelStatus::AlmostSolved);
            let tol = if almost { 1e-4 * (1.0 + theirs) } else { 1e-8 * (1.0 + wrench.norm_squared()) };
            prop_assert!((mine - theirs).abs() <= tol, "{} vs {}: {} / {}", mine, theirs, alloc.last_report().unwrap(), fresh.last_report().unwrap());
        }
    }
}
