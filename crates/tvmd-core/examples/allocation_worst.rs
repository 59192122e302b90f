//! Per-request cost of the exact-boundary redistribution over the allocation benchmark set
//! (`benches/data/allocation_set.json`): for every team, each request allocated by a reset
//! allocator (as `allocation-eval` and `benches/allocation.rs` do), timed as the minimum over
//! repetitions, then the worst, median and mean request, and the walk's counted work.
//!
//! Run: `cargo run --release -p tvmd-core --example allocation_worst -- [REPS] [f32] [cap=K]`.

#[path = "../tests/common/allocation_set.rs"]
mod allocation_set;

use std::hint::black_box;
use std::time::Instant;

use allocation_set::{teams, SetTeam};
use tvmd_core::RoundCap;
use tvmd_core::{AdmissibleSet, AllocationRequest, Allocator, ExactBoundaryRedistribution, Real};

fn team<T: Real, const N: usize>(t: &SetTeam, reps: usize, cap: Option<u32>) {
    let (config, mask) = t.build::<T, N>();
    let e = config.effectiveness(&mask);
    let sets = [AdmissibleSet::from_limits(config.limits()); N];
    let mut times = Vec::new();
    let mut worst_rounds = 0;
    let (mut exact, mut attainable, mut outside_e_f) = (0, 0, 0.0);
    let mut worst_cost = tvmd_core::WalkCost::default();
    if let Ok(spec) = std::env::var("TVMD_TRACE") {
        // `TEAM:K`: request K of TEAM with the walk capped at 0, 1, ... rounds.
        let (id, k) = spec.split_once(':').unwrap_or((&spec, "0"));
        if id == t.id() {
            let k: usize = k.parse().unwrap_or(0);
            let w = t.requests[k].1.cast::<T>();
            let request = AllocationRequest {
                effectiveness: &e,
                sets: &sets,
                wrench: w,
            };
            for cap in 0..40 {
                let mut a = ExactBoundaryRedistribution::<T, N>::new()
                    .with_round_cap(RoundCap::Rounds(cap));
                let out = a.allocate(&request);
                let r = w - e.wrench(&out.forces);
                println!(
                    "cap {cap:2}: rounds {:2}  e_f {:.6e}  e_tau {:.6e}  {:?}",
                    a.last_cost().rounds,
                    out.e_f.to_subset().unwrap_or(f64::NAN),
                    r.fixed_rows::<3>(0).norm().to_subset().unwrap_or(f64::NAN),
                    a.last_cost()
                );
                if a.last_cost().rounds < cap {
                    break;
                }
            }
        }
        return;
    }
    if let Ok(spec) = std::env::var("TVMD_PROFILE") {
        // `TEAM:K`: allocate request K of TEAM over and over (for `perf record`).
        let (id, k) = spec.split_once(':').unwrap_or((&spec, "0"));
        if id == t.id() {
            let k: usize = k.parse().unwrap_or(0);
            let request = AllocationRequest {
                effectiveness: &e,
                sets: &sets,
                wrench: t.requests[k].1.cast::<T>(),
            };
            for _ in 0..reps {
                let mut a = ExactBoundaryRedistribution::<T, N>::new()
                    .with_round_cap(RoundCap::from_limit(cap));
                black_box(a.allocate(black_box(&request)));
            }
        }
        return;
    }
    for (k, (kind, w)) in t.requests.iter().enumerate() {
        let request = AllocationRequest {
            effectiveness: &e,
            sets: &sets,
            wrench: w.cast::<T>(),
        };
        let mut best = f64::INFINITY;
        let mut rounds = 0;
        for _ in 0..reps {
            let mut a = ExactBoundaryRedistribution::<T, N>::new()
                .with_round_cap(RoundCap::from_limit(cap));
            let t0 = Instant::now();
            let out = black_box(a.allocate(black_box(&request)));
            best = best.min(t0.elapsed().as_secs_f64() * 1e6);
            rounds = out.rounds;
            let c = a.last_cost();
            worst_cost = tvmd_core::WalkCost {
                start_rounds: worst_cost.start_rounds.max(c.start_rounds),
                rounds: worst_cost.rounds.max(c.rounds),
                solves: worst_cost.solves.max(c.solves),
                releases: worst_cost.releases.max(c.releases),
                line_searches: worst_cost.line_searches.max(c.line_searches),
            };
            let rel: f64 = out.e_f.to_subset().unwrap_or(f64::NAN) / w.fixed_rows::<3>(3).norm();
            if SetTeam::attainable(kind) {
                reps_done(&mut attainable, &mut exact, rel);
            } else {
                outside_e_f += rel / reps as f64;
            }
        }
        worst_rounds = worst_rounds.max(rounds);
        times.push((best, k, kind.clone(), rounds));
    }
    let mean = times.iter().map(|x| x.0).sum::<f64>() / times.len() as f64;
    times.sort_by(|a, b| a.0.total_cmp(&b.0));
    let median = times[times.len() / 2].0;
    let (worst, k, kind, rounds) = times.last().cloned().unwrap();
    // The costliest request the team can meet (the outside ones run the walk to its cap).
    let (a_worst, a_k, a_kind, a_rounds) = times
        .iter()
        .rev()
        .find(|x| SetTeam::attainable(&x.2))
        .cloned()
        .unwrap();
    let outside = t.requests.len() - attainable / reps.max(1);
    let outside_e_f = outside_e_f / outside.max(1) as f64;
    println!(
        "{:<12} worst {worst:7.2} us (request {k}, {kind}, {rounds} rounds)  attainable worst {a_worst:6.2} us (request {a_k}, {a_kind}, {a_rounds} rounds)  median {median:6.2}  mean {mean:6.2}  max rounds {worst_rounds}  exact {}/{}  outside mean rel e_f {outside_e_f:.4}  max cost {worst_cost:?}",
        t.id(), exact / reps, attainable / reps
    );
}

/// Counts request `rel` once per request (the last repetition's, all alike).
fn reps_done(attainable: &mut usize, exact: &mut usize, rel: f64) -> bool {
    *attainable += 1;
    *exact += usize::from(rel <= 1e-9);
    true
}

fn run<T: Real>(reps: usize, cap: Option<u32>) {
    for t in teams() {
        match t.size() {
            4 => team::<T, 4>(&t, reps, cap),
            6 => team::<T, 6>(&t, reps, cap),
            8 => team::<T, 8>(&t, reps, cap),
            _ => team::<T, 16>(&t, reps, cap),
        }
    }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let reps = args.iter().find_map(|a| a.parse().ok()).unwrap_or(200usize);
    // `cap=K`: the walk capped at K rounds (`with_round_cap`).
    let cap = args
        .iter()
        .find_map(|a| a.strip_prefix("cap=").and_then(|k| k.parse().ok()));
    if args.iter().any(|a| a == "f32") {
        run::<f32>(reps, cap);
    } else {
        run::<f64>(reps, cap);
    }
}
