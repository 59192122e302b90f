//! The exact-boundary incremental redistribution: admissible and finite on any request, never
//! worse than the redistributed pseudo-inverse it may start from, exact on attainable requests
//! more often than it, warm starts from the previous period, and reset.

use nalgebra::{Vector3, Vector6};
use proptest::prelude::*;
use rand::{rngs::StdRng, Rng, SeedableRng};
use tvmd_core::team::presets;
use tvmd_core::RoundCap;
use tvmd_core::{
    AdmissibleSet, Allocation, AllocationRequest, Allocator, ExactBoundaryRedistribution,
    FailureMask, GimbalCommand, Real, RedistributedPseudoInverse, TeamConfig,
};

const CAP: usize = 10;
type Team = TeamConfig<f64, CAP>;

fn team_by_index<T: Real>(which: usize) -> TeamConfig<T, CAP> {
    match which % 4 {
        0 => presets::a4_inc().unwrap(),
        1 => presets::a4_con().unwrap(),
        2 => presets::ring(6, nalgebra::convert(0.5), true, presets::paper_limits()).unwrap(),
        _ => presets::ring(8, nalgebra::convert(0.6), false, presets::paper_limits()).unwrap(),
    }
}

/// Every set narrowed by the rate window `w` (rad/s over 1 s) around `previous`.
fn narrow<T: Real>(sets: &mut [AdmissibleSet<T>; CAP], previous: &GimbalCommand<T>, w: T) {
    let rates = tvmd_core::admissible::RateLimits::new(w, w).unwrap();
    for s in sets.iter_mut() {
        *s = s.with_rate_limit(previous, &rates, T::one());
    }
}

fn sets_of(team: &Team) -> [AdmissibleSet<f64>; CAP] {
    [AdmissibleSet::from_limits(team.limits()); CAP]
}

/// A command inside `set`; with probability about one half one of its ranges is at a bound.
fn admissible_command(rng: &mut StdRng, set: &AdmissibleSet<f64>) -> GimbalCommand<f64> {
    let pick = |rng: &mut StdRng, lo: f64, hi: f64| match rng.random_range(0..6) {
        0 => lo,
        1 => hi,
        _ => rng.random_range(lo..=hi),
    };
    GimbalCommand {
        eta_x: pick(rng, set.eta_x().lo, set.eta_x().hi),
        eta_y: pick(rng, set.eta_y().lo, set.eta_y().hi),
        thrust: pick(rng, set.thrust().lo, set.thrust().hi),
    }
}

fn assert_admissible(a: &Allocation<f64, CAP>, sets: &[AdmissibleSet<f64>; CAP], team: &Team) {
    for (i, (f, set)) in a.forces.iter().zip(sets).enumerate().take(team.len()) {
        assert!(f.iter().all(|x| x.is_finite()), "agent {i}: {f:?}");
        // Zero thrust is admissible at any gimbal angle: the command stage keeps the angles
        // inside the (rate-narrowed) set.
        if *f == Vector3::zeros() && set.thrust().lo == 0.0 {
            continue;
        }
        let cmd = GimbalCommand::from_force(f);
        assert!(set.contains(&cmd, 1e-9), "agent {i} outside: {cmd:?}");
    }
    assert!(a.e_f.is_finite() && a.wrench_error.is_finite());
}

/// Relative force error of an allocation.
fn relative(a: &Allocation<f64, CAP>, u: &Vector6<f64>) -> f64 {
    a.wrench_error / u.norm().max(1.0)
}

#[test]
fn attainable_requests_are_met_more_often_than_by_the_redistributed_pseudo_inverse() {
    let mut rng = StdRng::seed_from_u64(16);
    for which in 0..4 {
        let team = team_by_index(which);
        let e = team.effectiveness(&FailureMask::none());
        let sets = sets_of(&team);
        let (mut exact, mut exact_rpi, mut total) = (0, 0, 0);
        let mut rounds = 0u32;
        for _ in 0..600 {
            let mut forces = [Vector3::zeros(); CAP];
            for f in forces.iter_mut().take(team.len()) {
                *f = admissible_command(&mut rng, &sets[0]).force();
            }
            let u = e.wrench(&forces);
            let request = AllocationRequest {
                effectiveness: &e,
                sets: &sets,
                wrench: u,
            };
            let rpi = RedistributedPseudoInverse.allocate(&request);
            let a = ExactBoundaryRedistribution::new()
                .with_round_cap(RoundCap::Uncapped)
                .allocate(&request);
            assert_admissible(&a, &sets, &team);
            assert!(torque_first(&a, &u) <= torque_first(&rpi, &u) * (1.0 + 1e-12) + 1e-12);
            total += 1;
            rounds = rounds.max(a.rounds);
            exact += usize::from(relative(&a, &u) <= 1e-9);
            exact_rpi += usize::from(relative(&rpi, &u) <= 1e-9);
        }
        println!("team {which}: exact {exact}/{total}, redistributed pseudo-inverse {exact_rpi}/{total}, max rounds {rounds}");
        assert!(exact >= exact_rpi, "team {which}: {exact} < {exact_rpi}");
        // Measured 567, 577, 600 and 600 of 600 (redistributed pseudo-inverse: 248, 278, 488,
        // 579); the bound leaves room for round-off on another platform, not for a regression.
        assert!(exact * 100 >= total * 90, "team {which}: {exact}/{total}");
    }
}

fn team_sets_request(
    which: usize,
) -> (
    Team,
    tvmd_core::Effectiveness<f64, CAP>,
    [AdmissibleSet<f64>; CAP],
) {
    let team = team_by_index(which);
    let e = team.effectiveness(&FailureMask::none());
    let sets = sets_of(&team);
    (team, e, sets)
}

/// `||[w (u_tau - M_tau f); u_f - M_f f]||`, `w` = `ExactBoundaryRedistribution::TORQUE_PRIORITY`.
fn torque_first<const N: usize>(a: &tvmd_core::Allocation<f64, N>, u: &Vector6<f64>) -> f64 {
    let mut r = u - a.wrench;
    for x in r.iter_mut().take(3) {
        *x *= ExactBoundaryRedistribution::<f64, N>::TORQUE_PRIORITY;
    }
    // Beyond 1e300 the weighted torque overflows; the scaled norm stays finite.
    let m = r.amax();
    if m > 0.0 && m.is_finite() {
        (r / m).norm() * m
    } else {
        r.norm()
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Any request, of any size or sign, with failures and rate-narrowed sets: admissible,
    /// finite forces (zero for failed agents), never worse than the start.
    #[test]
    fn any_request_gives_admissible_forces(
        which in 0usize..4,
        u in proptest::array::uniform6(-1.0f64..1.0),
        scale in prop_oneof![Just(1.0), Just(40.0), Just(1e6), Just(1e300)],
        failed in proptest::option::of(0usize..4),
        window in proptest::option::of(0.01f64..0.3),
        repeat in 1usize..4,
    ) {
        let (team, _, mut sets) = team_sets_request(which);
        let mask = match failed {
            Some(i) => FailureMask::with_failed(&[i]).unwrap(),
            None => FailureMask::none(),
        };
        let e = team.effectiveness(&mask);
        if let Some(w) = window {
            narrow(&mut sets, &GimbalCommand { thrust: 2.0, eta_x: 0.3, eta_y: -0.2 }, w);
        }
        let wrench = Vector6::from(u) * scale;
        let request = AllocationRequest { effectiveness: &e, sets: &sets, wrench };
        let mut allocator = ExactBoundaryRedistribution::new().with_round_cap(RoundCap::Uncapped);
        for _ in 0..repeat {
            let a = allocator.allocate(&request);
            assert_admissible(&a, &sets, &team);
            if let Some(i) = failed {
                prop_assert_eq!(a.forces[i], Vector3::zeros());
            }
            let rpi = RedistributedPseudoInverse.allocate(&request);
            // Never worse than the redistributed pseudo-inverse by the torque-first error the
            // walk chooses its result by.
            let (tf, tf_rpi) = (torque_first(&a, &wrench), torque_first(&rpi, &wrench));
            prop_assert!(tf <= tf_rpi * (1.0 + 1e-12) + 1e-12, "{tf} > {tf_rpi}");
            prop_assert!(a.rounds as usize <= 3 * team.len() + 4);
        }
    }
}

#[test]
fn non_finite_requests_give_admissible_forces() {
    let (team, e, sets) = team_sets_request(0);
    let mut allocator = ExactBoundaryRedistribution::new().with_round_cap(RoundCap::Uncapped);
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        let wrench = Vector6::new(0.0, 0.0, 0.0, 1.0, bad, 20.0);
        let a = allocator.allocate(&AllocationRequest {
            effectiveness: &e,
            sets: &sets,
            wrench,
        });
        for f in a.forces.iter().take(team.len()) {
            assert!(f.iter().all(|x| x.is_finite()));
            assert!(sets[0].contains(&GimbalCommand::from_force(f), 1e-9));
        }
    }
}

#[test]
fn a_slowly_moving_request_starts_from_the_previous_forces() {
    let (team, e, sets) = team_sets_request(0);
    let mut rng = StdRng::seed_from_u64(5);
    let (mut warm_exact, mut fresh_exact) = (0, 0);
    let (mut warm_rounds, mut fresh_rounds) = (0, 0);
    for _ in 0..20 {
        let mut allocator = ExactBoundaryRedistribution::new().with_round_cap(RoundCap::Uncapped);
        let base: Vec<GimbalCommand<f64>> = (0..4)
            .map(|_| admissible_command(&mut rng, &sets[0]))
            .collect();
        // Attainable requests whose forces move slowly (the thrust shrinks by 0.2% a period).
        for k in 0..10 {
            let mut forces = [Vector3::zeros(); CAP];
            for (f, c) in forces.iter_mut().zip(&base) {
                let mut c = *c;
                c.thrust *= 1.0 - 0.002 * k as f64;
                *f = c.force();
            }
            let wrench = e.wrench(&forces);
            let request = AllocationRequest {
                effectiveness: &e,
                sets: &sets,
                wrench,
            };
            let warm = allocator.allocate(&request);
            let fresh = ExactBoundaryRedistribution::new()
                .with_round_cap(RoundCap::Uncapped)
                .allocate(&request);
            assert_admissible(&warm, &sets, &team);
            assert_eq!(allocator.previous(), Some(&warm.forces));
            if k > 0 {
                warm_exact += usize::from(relative(&warm, &wrench) <= 1e-9);
                fresh_exact += usize::from(relative(&fresh, &wrench) <= 1e-9);
                warm_rounds += warm.rounds;
                fresh_rounds += fresh.rounds;
            }
        }
    }
    // Measured: 180 and 180 of 180 exact, 944 and 940 rounds: the warm start keeps the
    // forces continuous between periods but buys neither exactness nor rounds here.
    println!(
        "warm: {warm_exact} exact, {warm_rounds} rounds; fresh: {fresh_exact}, {fresh_rounds}"
    );
    assert!(
        warm_exact * 100 >= fresh_exact * 95,
        "{warm_exact} vs {fresh_exact}"
    );
    assert!(
        warm_rounds * 100 <= fresh_rounds * 110,
        "{warm_rounds} > {fresh_rounds}"
    );
}

#[test]
fn a_repeated_request_met_last_period_keeps_its_forces() {
    let (team, e, sets) = team_sets_request(0);
    let mut rng = StdRng::seed_from_u64(9);
    let mut kept = 0;
    for _ in 0..100 {
        let mut forces = [Vector3::zeros(); CAP];
        for f in forces.iter_mut().take(4) {
            *f = admissible_command(&mut rng, &sets[0]).force();
        }
        let wrench = e.wrench(&forces);
        let request = AllocationRequest {
            effectiveness: &e,
            sets: &sets,
            wrench,
        };
        let mut allocator = ExactBoundaryRedistribution::new().with_round_cap(RoundCap::Uncapped);
        let first = allocator.allocate(&request);
        let rpi = RedistributedPseudoInverse.allocate(&request);
        // Met to the walk's own stopping tolerance (`64 eps` of the request's largest entry).
        let met = first.wrench_error <= 1e-14 * wrench.amax().max(1.0);
        if met && first.wrench_error < rpi.wrench_error {
            let second = allocator.allocate(&request);
            assert_admissible(&second, &sets, &team);
            // The previous forces are the start (re-saturated: a force on the boundary may move
            // by an ulp); the walk has at most a round-off residual left.
            for (a, b) in second.forces.iter().zip(&first.forces) {
                assert!((a - b).norm() <= 1e-12 * b.norm().max(1.0), "{a:?} {b:?}");
            }
            assert!(second.rounds <= rpi.rounds + 1);
            kept += 1;
        }
    }
    assert!(kept > 30, "{kept}");
}

#[test]
fn reset_and_configure_forget_the_previous_forces() {
    let (_, e, sets) = team_sets_request(0);
    let wrench = Vector6::new(0.1, 0.0, 0.0, 3.0, 0.0, 20.0);
    let request = AllocationRequest {
        effectiveness: &e,
        sets: &sets,
        wrench,
    };
    let mut a = ExactBoundaryRedistribution::new().with_round_cap(RoundCap::Uncapped);
    a.allocate(&request);
    assert!(a.previous().is_some());
    Allocator::<f64, CAP>::reset(&mut a);
    assert!(a.previous().is_none());
    a.allocate(&request);
    a.configure(&e);
    assert!(a.previous().is_none());
}

#[test]
fn f32_agrees_with_f64_on_attainable_requests() {
    let team64: Team = team_by_index(0);
    let team32 = team_by_index::<f32>(0);
    let (e64, e32) = (
        team64.effectiveness(&FailureMask::none()),
        team32.effectiveness(&FailureMask::none()),
    );
    let (s64, s32) = (
        sets_of(&team64),
        [AdmissibleSet::from_limits(team32.limits()); CAP],
    );
    let mut rng = StdRng::seed_from_u64(32);
    let mut exact = 0;
    for _ in 0..200 {
        let mut forces = [Vector3::zeros(); CAP];
        for f in forces.iter_mut().take(4) {
            *f = admissible_command(&mut rng, &s64[0]).force();
        }
        let u = e64.wrench(&forces);
        let a32 = ExactBoundaryRedistribution::new()
            .with_round_cap(RoundCap::Uncapped)
            .allocate(&AllocationRequest {
                effectiveness: &e32,
                sets: &s32,
                wrench: u.cast::<f32>(),
            });
        for f in a32.forces.iter().take(4) {
            assert!(f.iter().all(|x| x.is_finite()));
            assert!(s32[0].contains(&GimbalCommand::from_force(f), 1e-5));
        }
        exact += usize::from(a32.wrench_error as f64 / u.norm().max(1.0) <= 1e-5);
    }
    // f64 meets 95% of such requests to 1e-9; f32 to its own resolution about as often.
    assert!(exact >= 170, "{exact}/200");
}

/// A rate window of zero width (the previous command beyond the gimbal limit, so the window is
/// the limit itself): one ulp of the inverse's round-off is a clamp of one ulp, in the units of
/// `contains`, not half the window (CI's case of `f32_forces_invert_without_clamping`).
#[test]
fn a_zero_width_window_clamps_round_off_only() {
    let team = team_by_index::<f32>(1);
    let e = team.effectiveness(&FailureMask::none());
    let mut sets = [AdmissibleSet::from_limits(team.limits()); CAP];
    let previous = GimbalCommand {
        thrust: 2.0,
        eta_x: 0.0,
        eta_y: 0.997_158_35 * 0.8,
    };
    narrow(&mut sets, &previous, 0.001);
    let eta_y = sets[0].eta_y();
    assert_eq!(eta_y.lo, eta_y.hi, "the window is a point");
    let wrench = Vector6::new(0.353_033_07, 0.0, 0.0, 0.0, 0.0, -0.917_253_85);
    let a = ExactBoundaryRedistribution::new()
        .with_round_cap(RoundCap::Uncapped)
        .allocate(&AllocationRequest {
            effectiveness: &e,
            sets: &sets,
            wrench,
        });
    let tol = tvmd_core::command::command_tolerance::<f32>();
    for (f, set) in a.forces.iter().zip(&sets).take(team.len()) {
        let (_, clamp) = tvmd_core::command::invert(f, set, team.limits());
        let raw = GimbalCommand::from_force(f);
        assert!(clamp <= tol, "clamp {clamp} of {f:?}");
        assert_eq!(set.contains(&raw, tol), set.excess(&raw) <= tol);
    }
    // One ulp past the point: an excess of that ulp, where the width-relative violation reads
    // half the (floored) width.
    let past = GimbalCommand {
        thrust: 1.0,
        eta_x: 0.0,
        eta_y: f32::from_bits(eta_y.hi.to_bits() + 1),
    };
    let ulp = past.eta_y - eta_y.hi;
    assert_eq!(sets[0].excess(&past), ulp);
    assert!(sets[0].violation(&past) > 0.4);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// f32, any request with rate-narrowed sets: the command inversion clamps round-off only.
    #[test]
    fn f32_forces_invert_without_clamping(
        which in 0usize..4,
        u in proptest::array::uniform6(-1.0f32..1.0),
        scale in prop_oneof![Just(1.0f32), Just(40.0), Just(1e6)],
        centre in proptest::array::uniform3(-1.0f32..1.0),
        window in proptest::option::of(0.001f32..0.3),
        repeat in 1usize..5,
    ) {
        let team = team_by_index::<f32>(which);
        let e = team.effectiveness(&FailureMask::none());
        let mut sets = [AdmissibleSet::from_limits(team.limits()); CAP];
        if let Some(w) = window {
            let previous = GimbalCommand { thrust: 2.0, eta_x: centre[0] * 0.5, eta_y: centre[1] * 0.8 };
            narrow(&mut sets, &previous, w);
        }
        let wrench = Vector6::from(u) * scale;
        let request = AllocationRequest { effectiveness: &e, sets: &sets, wrench };
        let mut allocator = ExactBoundaryRedistribution::new().with_round_cap(RoundCap::Uncapped);
        for _ in 0..repeat {
            let a = allocator.allocate(&request);
            for (i, (f, set)) in a.forces.iter().zip(&sets).enumerate().take(team.len()) {
                let (_, clamp) = tvmd_core::command::invert(f, set, team.limits());
                prop_assert!(
                    clamp <= tvmd_core::command::command_tolerance::<f32>(),
                    "agent {} force {:?} clamp {} set {:?}", i, f, clamp, set
                );
            }
        }
    }
}
