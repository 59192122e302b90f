//! The exact-boundary redistribution's counted work over the allocation benchmark set
//! (`benches/data/allocation_set.json`, issue 46): every allocation, from a reset allocator and
//! warm-started from the previous request, stays within [`WalkCost::bound`]; the bound's rounds
//! are reached (it is tight); a round cap holds, and a capped allocation is admissible, honest
//! about its error and never worse than the redistributed pseudo-inverse by the torque-first
//! error.

#[path = "common/allocation_set.rs"]
mod allocation_set;

use allocation_set::{teams, SetTeam};
use tvmd_core::RoundCap;
use tvmd_core::{
    AdmissibleSet, AllocationRequest, Allocator, ExactBoundaryRedistribution, GimbalCommand,
    RedistributedPseudoInverse, WalkCost,
};

/// The largest counts seen over one team (every allocation checked against the bound), and
/// the attainable requests a reset allocator meets exactly (`e_f <= 1e-9 ||u_fd||`, as
/// `allocation-eval` counts them).
fn check<const N: usize>(t: &SetTeam, cap: Option<u32>) -> (WalkCost, usize) {
    let (config, mask) = t.build::<f64, N>();
    let e = config.effectiveness(&mask);
    let sets = [AdmissibleSet::from_limits(config.limits()); N];
    let bound = WalkCost::bound(e.working_count(), cap.unwrap_or(u32::MAX));
    let cap = RoundCap::from_limit(cap);
    let mut warm = ExactBoundaryRedistribution::<f64, N>::new().with_round_cap(cap);
    let mut seen = WalkCost::default();
    let mut exact = 0;
    for (kind, w) in &t.requests {
        let request = AllocationRequest {
            effectiveness: &e,
            sets: &sets,
            wrench: *w,
        };
        let mut cold = ExactBoundaryRedistribution::<f64, N>::new().with_round_cap(cap);
        for a in [&mut cold, &mut warm] {
            let out = a.allocate(&request);
            let c = a.last_cost();
            assert!(
                c.within(&bound),
                "{} {kind}: {c:?} beyond {bound:?}",
                t.id()
            );
            assert_eq!(out.rounds, c.start_rounds + c.rounds);
            seen = WalkCost {
                start_rounds: seen.start_rounds.max(c.start_rounds),
                rounds: seen.rounds.max(c.rounds),
                solves: seen.solves.max(c.solves),
                releases: seen.releases.max(c.releases),
                line_searches: seen.line_searches.max(c.line_searches),
            };
            // Admissible, and the reported error is the forces' own.
            for (i, (f, s)) in out.forces.iter().zip(&sets).enumerate() {
                if e.block(i).is_some() {
                    assert!(
                        s.contains(&GimbalCommand::from_force(f), 1e-9),
                        "{kind}: {f}"
                    );
                }
            }
            let r = w - e.wrench(&out.forces);
            assert!((r.fixed_rows::<3>(3).norm() - out.e_f).abs() <= 1e-9 * (1.0 + out.e_f));
        }
        let cold_e_f = w - e.wrench(&cold.previous().copied().unwrap_or([Default::default(); N]));
        if SetTeam::attainable(kind)
            && cold_e_f.fixed_rows::<3>(3).norm() <= 1e-9 * w.fixed_rows::<3>(3).norm()
        {
            exact += 1;
        }
        // Never worse than the redistributed pseudo-inverse, capped or not (torque first).
        let rpi = RedistributedPseudoInverse.allocate(&request);
        let walked = cold.previous().copied().unwrap_or(rpi.forces);
        let weigh = |f: &[nalgebra::Vector3<f64>; N]| {
            let r = w - e.wrench(f);
            (r.fixed_rows::<3>(0) * 100.0)
                .norm()
                .hypot(r.fixed_rows::<3>(3).norm())
        };
        assert!(
            weigh(&walked) <= weigh(&rpi.forces) * (1.0 + 1e-9) + 1e-12,
            "{kind}"
        );
    }
    (seen, exact)
}

fn seen(t: &SetTeam, cap: Option<u32>) -> (WalkCost, usize) {
    match t.size() {
        4 => check::<4>(t, cap),
        6 => check::<6>(t, cap),
        8 => check::<8>(t, cap),
        _ => check::<16>(t, cap),
    }
}

#[test]
fn every_allocation_of_the_set_is_within_the_bound_and_the_rounds_bound_is_reached() {
    // Exact on the attainable requests before issue 46 (docs/allocation-benchmark.md).
    let before = [63, 63, 64, 64, 54];
    for (t, before) in teams().iter().zip(before) {
        let n = t.size() - t.failed.len();
        let (seen, exact) = seen(t, None);
        assert!(
            exact >= before,
            "{}: exact on {exact}, before {before}",
            t.id()
        );
        let bound = WalkCost::bound(n, u32::MAX);
        // Measured (issue 46): an outside request runs the walk to its cap on every team.
        assert_eq!(seen.rounds, bound.rounds, "{}: {seen:?}", t.id());
        assert_eq!(
            seen.start_rounds,
            bound.start_rounds,
            "{}: {seen:?}",
            t.id()
        );
    }
}

#[test]
fn a_round_cap_holds_and_keeps_the_allocation_admissible_and_honest() {
    for cap in [0, 1, 3] {
        for t in teams() {
            let (seen, _) = seen(&t, Some(cap));
            assert!(seen.rounds <= cap, "{}: {seen:?}", t.id());
        }
    }
}

#[test]
fn the_bound_is_linear_in_the_agents() {
    assert_eq!(
        WalkCost::bound(4, u32::MAX),
        WalkCost {
            start_rounds: 4,
            rounds: 12,
            solves: 27,
            releases: 13,
            line_searches: 13,
        }
    );
    assert_eq!(WalkCost::bound(16, 5).rounds, 5);
    assert_eq!(WalkCost::bound(16, u32::MAX).solves, 4 * 16 + 11);
    // One agent: at most one release per constraint.
    assert_eq!(WalkCost::bound(1, u32::MAX).releases, 6);
}

#[test]
fn the_cap_is_an_allocator_option_of_the_exact_boundary_redistribution_only() {
    use tvmd_core::allocation::AllocatorOptions;
    use tvmd_core::{AnyAllocator, ConfigError, ConfigField};
    let capped = AllocatorOptions::<f64, 4> {
        max_rounds: Some(RoundCap::Rounds(3)),
        ..AllocatorOptions::default()
    };
    match AnyAllocator::from_name("exact-boundary-redistribution", &capped) {
        Ok(AnyAllocator::ExactBoundaryRedistribution(a)) => {
            assert_eq!(a.round_cap(), RoundCap::Rounds(3))
        }
        other => panic!("{other:?}"),
    }
    assert_eq!(
        AnyAllocator::from_name("redistributed-pseudo-inverse", &capped).unwrap_err(),
        ConfigError::UnusedOption {
            field: ConfigField::AllocatorMaxRounds
        }
    );
}
