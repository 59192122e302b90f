//! Allocation benchmarks over the committed allocation set (`benches/data/allocation_set.json`,
//! `tvmd-sim allocation-set`): one entry `allocation/<team>/<allocator>` per team and allocator
//! of `AnyAllocator::NAMES` (every allocator of the build, so new ones are picked up), each
//! iteration allocating the team's next request (attainable and outside ones in the set's
//! order, from a reset allocator as in `tvmd-sim allocation-eval`): the median is the mean
//! time of one allocation over the team's set. f64, capacity `N` = the team's size.
//!
//! Also `allocation-worst/<team>/exact-boundary-redistribution` (issue 46): the default
//! allocator on the team's costliest request (found by a timing pre-pass: the minimum of 20
//! allocations per request), each iteration from a reset allocator: the worst case per request
//! on the set (`cargo run --release -p tvmd-core --example allocation_worst` lists every team's).
//!
//! Run: `cargo bench --bench allocation --features clarabel -- --warm-up-time 0.5
//! --measurement-time 1`, then `python3 benches/allocation_table.py` for the table.

use std::hint::black_box;
use std::time::Instant;

use criterion::{criterion_group, criterion_main, Criterion};
use tvmd::core::allocation::AllocatorOptions;
use tvmd::core::nalgebra::Vector6;
use tvmd::core::{
    AdmissibleSet, AllocationRequest, Allocator, AnyAllocator, ExactBoundaryRedistribution,
};
use tvmd_studies::allocation_bench::{failure_mask, team, team_size, AllocationSet, TeamRequests};

const SET: &str = include_str!("data/allocation_set.json");

/// `a4_inc`, or `a4_inc-f1` with agent 1 failed.
fn team_id(t: &TeamRequests) -> String {
    let failed: Vec<String> = t.failed.iter().map(|i| format!("-f{i}")).collect();
    format!("{}{}", t.team, failed.concat())
}

fn bench_team<const N: usize>(c: &mut Criterion, t: &TeamRequests) {
    let config = team::<N>(&t.team).unwrap_or_else(|e| panic!("{e}"));
    let mask = failure_mask(&config, &t.failed).unwrap_or_else(|e| panic!("{e}"));
    let effectiveness = config.effectiveness(&mask);
    let sets = [AdmissibleSet::from_limits(config.limits()); N];
    let wrenches: Vec<Vector6<f64>> = t
        .requests
        .iter()
        .map(|r| Vector6::from_column_slice(&r.wrench))
        .collect();
    let mut group = c.benchmark_group(format!("allocation/{}", team_id(t)));
    for name in AnyAllocator::<f64, N>::NAMES {
        let mut allocator = AnyAllocator::<f64, N>::from_name(name, &AllocatorOptions::default())
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        allocator.configure(&effectiveness);
        let mut next = wrenches.iter().cycle();
        group.bench_function(*name, |b| {
            b.iter(|| {
                let wrench = *next.next().unwrap_or(&Vector6::zeros());
                allocator.reset();
                black_box(allocator.allocate(&AllocationRequest {
                    effectiveness: &effectiveness,
                    sets: &sets,
                    wrench: black_box(wrench),
                }))
            })
        });
    }
    group.finish();
    // The default allocator's costliest request of the team (its walk capped at
    // DEFAULT_MAX_ROUNDS).
    let costliest = wrenches
        .iter()
        .map(|w| {
            let request = AllocationRequest {
                effectiveness: &effectiveness,
                sets: &sets,
                wrench: *w,
            };
            let best = (0..20)
                .map(|_| {
                    let t0 = Instant::now();
                    black_box(ExactBoundaryRedistribution::<f64, N>::new().allocate(&request));
                    t0.elapsed()
                })
                .min()
                .unwrap_or_default();
            (best, *w)
        })
        .max_by_key(|(t, _)| *t)
        .map(|(_, w)| w)
        .unwrap_or_else(Vector6::zeros);
    let mut group = c.benchmark_group(format!("allocation-worst/{}", team_id(t)));
    group.bench_function("exact-boundary-redistribution", |b| {
        let request = AllocationRequest {
            effectiveness: &effectiveness,
            sets: &sets,
            wrench: costliest,
        };
        b.iter(|| ExactBoundaryRedistribution::<f64, N>::new().allocate(black_box(&request)))
    });
    group.finish();
}

fn allocation(c: &mut Criterion) {
    let set = AllocationSet::from_json(SET).unwrap_or_else(|e| panic!("allocation set: {e}"));
    for t in &set.teams {
        match team_size(&t.team).unwrap_or_else(|e| panic!("{e}")) {
            0..=4 => bench_team::<4>(c, t),
            5..=6 => bench_team::<6>(c, t),
            7..=8 => bench_team::<8>(c, t),
            _ => bench_team::<16>(c, t),
        }
    }
}

criterion_group!(benches, allocation);
criterion_main!(benches);
