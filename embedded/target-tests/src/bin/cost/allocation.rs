//! On-target cost of the default allocator (`ExactBoundaryRedistribution`, f32) over the
//! allocation benchmark set (`benches/data/allocation_set.json`, as f32 statics written by
//! `build_allocation_set.rs`): per team, the instructions of each request's allocation by a
//! reset allocator (as `allocation-eval` runs them), their worst and median, the walk's most
//! rounds, the peak stack, and the forces against the host's f32 forces of the same requests
//! (bit-identical count, worst difference relative to the largest thrust).

// The generated table holds measured numbers, some of which happen to be close to `pi`.
#![allow(clippy::approx_constant)]

use core::hint::black_box;

use cortex_m_semihosting::hprintln;
use tvmd_core::nalgebra::{Vector3, Vector6};
use tvmd_core::team::presets;
use tvmd_core::RoundCap;
use tvmd_core::{
    AdmissibleSet, AllocationRequest, Allocator, ExactBoundaryRedistribution, FailureMask,
    RedistributedPseudoInverse, TeamConfig,
};

use crate::{clock, stack};

/// One request of the set with the host's f32 result.
pub struct SetRequest<const N: usize> {
    /// `u = [u_tau; u_f]`, f32.
    pub wrench: [f32; 6],
    /// The host's f32 forces (std's libm).
    pub host: [[f32; 3]; N],
    /// The host's `Allocation::rounds`.
    pub host_rounds: u32,
}

/// One team of the set.
pub struct SetTeam<const N: usize> {
    /// `a4_inc`, `a4_inc_f1`, ...
    pub name: &'static str,
    /// Failed agents.
    pub failed: &'static [usize],
    /// Its requests in the set's order.
    pub requests: &'static [SetRequest<N>],
}

include!(concat!(env!("OUT_DIR"), "/allocation_set.rs"));

/// Allocations per request measured: each count is within `4 * 40 / REPS` instructions.
const REPS: u32 = 4;

/// The measured unit: one allocation by a reset allocator behind a call.
#[inline(never)]
fn allocate<const N: usize>(
    a: &mut ExactBoundaryRedistribution<f32, N>,
    r: &AllocationRequest<'_, f32, N>,
) -> f32 {
    a.reset();
    a.allocate(r).e_f
}

/// The paper's allocator on the same request, for comparison.
#[inline(never)]
fn allocate_rpi<const N: usize>(
    _a: &mut ExactBoundaryRedistribution<f32, N>,
    r: &AllocationRequest<'_, f32, N>,
) -> f32 {
    RedistributedPseudoInverse.allocate(r).e_f
}

/// The same call shape with no work.
#[inline(never)]
fn empty<const N: usize>(
    _a: &mut ExactBoundaryRedistribution<f32, N>,
    r: &AllocationRequest<'_, f32, N>,
) -> f32 {
    r.wrench.x
}

pub fn team<const N: usize>(name: &str) -> Option<TeamConfig<f32, N>> {
    match name {
        "a4_inc" | "a4_inc_f1" => presets::a4_inc().ok(),
        "a6_inc" => presets::a6_inc().ok(),
        "a8_inc" => presets::a8_inc().ok(),
        _ => presets::ring(16, 1.8, true, presets::paper_limits()).ok(),
    }
}

/// The worst and median instructions of one allocation over `set`'s requests (`None` if the
/// team was refused), printed with the stack peak and the comparison with the host (the default
/// cap only: the host's forces are the default's); `cap` is the walk's round cap
/// (`ExactBoundaryRedistribution::with_round_cap`), `None` the default.
pub fn report<const N: usize>(
    set: &SetTeam<N>,
    cap: Option<RoundCap>,
    per_tick: u32,
) -> Option<(u32, u32)> {
    let config = team::<N>(set.name)?;
    let mask = FailureMask::with_failed(set.failed).ok()?;
    let e = config.effectiveness(&mask);
    let sets = [AdmissibleSet::from_limits(config.limits()); N];
    let mut a =
        ExactBoundaryRedistribution::<f32, N>::new().with_round_cap(cap.unwrap_or_default());
    let mut counts = [0u32; 128];
    let mut paper = [0u32; 128];
    let (mut stack_peak, mut identical, mut worst_diff, mut max_rounds) = (0, 0, 0.0f32, 0);
    let (mut rounds_differ, mut worst_at, mut worst_so_far) = (0, 0, 0);
    let thrust = config.limits().max_thrust();
    for (k, ((r, slot), paper_slot)) in set
        .requests
        .iter()
        .zip(counts.iter_mut())
        .zip(paper.iter_mut())
        .enumerate()
    {
        let request = AllocationRequest {
            effectiveness: &e,
            sets: &sets,
            wrench: Vector6::from_column_slice(&r.wrench),
        };
        let work = clock::ticks(REPS, &mut || {
            black_box(allocate(black_box(&mut a), black_box(&request)));
        });
        let overhead = clock::ticks(REPS, &mut || {
            black_box(empty(black_box(&mut a), black_box(&request)));
        });
        let per_call = |work: u32| clock::per_call(work, overhead, per_tick, REPS);
        *slot = per_call(work);
        *paper_slot = per_call(clock::ticks(REPS, &mut || {
            black_box(allocate_rpi(black_box(&mut a), black_box(&request)));
        }));
        if *slot >= worst_so_far {
            (worst_so_far, worst_at) = (*slot, k);
        }
        stack_peak = stack_peak.max(stack::peak(&mut || {
            black_box(allocate(black_box(&mut a), black_box(&request)));
        }));
        a.reset();
        let out = a.allocate(&request);
        max_rounds = max_rounds.max(out.rounds);
        rounds_differ += usize::from(out.rounds != r.host_rounds);
        let mut same = true;
        for (f, h) in out.forces.iter().zip(&r.host) {
            let h = Vector3::new(h[0], h[1], h[2]);
            same &= f
                .iter()
                .zip(h.iter())
                .all(|(x, y)| x.to_bits() == y.to_bits());
            worst_diff = worst_diff.max((f - h).amax() / thrust);
        }
        identical += usize::from(same);
    }
    let n = set.requests.len().min(counts.len());
    let sorted = sort(&mut counts[..n]);
    let (worst, median) = (sorted.last().copied()?, *sorted.get(n / 2)?);
    let sorted = sort(&mut paper[..n]);
    let (paper_worst, paper_median) = (sorted.last().copied()?, *sorted.get(n / 2)?);
    if cap.is_some() {
        hprintln!(
            "cost: allocation {:10} (n = {:2}, {} requests), walk {:?}: {:6} instructions worst (request {}), {:6} median, {:2} rounds at most",
            set.name, N, n, cap.unwrap_or_default(), worst, worst_at, median, max_rounds
        );
        return Some((worst, median));
    }
    hprintln!(
        "cost: allocation {:10} (n = {:2}, {} requests): exact-boundary-redistribution {:6} instructions worst (request {}), {:6} median, {:2} rounds at most, peak stack {:5} B; host f32 forces: {}/{} bit-identical, worst difference {:.2e} of sigma_Tf, rounds differ on {}; redistributed-pseudo-inverse {} worst, {} median",
        set.name,
        N,
        n,
        worst,
        worst_at,
        median,
        max_rounds,
        stack_peak,
        identical,
        n,
        worst_diff,
        rounds_differ,
        paper_worst,
        paper_median
    );
    Some((worst, median))
}

/// Insertion sort (no allocation; at most 128 counts).
fn sort(c: &mut [u32]) -> &[u32] {
    for i in 1..c.len() {
        let mut j = i;
        while j > 0 && c.get(j - 1) > c.get(j) {
            c.swap(j - 1, j);
            j -= 1;
        }
    }
    c
}
