//! Worst-case certificates (issue 59): for each allocator the target build ships and a team of
//! `N` agents, the most Cortex-M4F instructions one allocation can take, as the code's loop
//! limits times per-unit maxima measured here on a calibration family of requests generated on
//! the target, from hover to ten times the team's thrust. They are then checked against what
//! is measured apart from the family: the allocation benchmark set (`allocation.rs`'s teams and
//! requests) and the control cycles of `main.rs` (`cycle_certificate.rs`).
//!
//! The units, each the largest over the family (a count's quantization is 4 * 40 / REPS):
//! - pseudo-inverse, weighted pseudo-inverse: no loop depends on the request: one solve;
//! - redistributed pseudo-inverse (at most `n` rounds, `redistributed.rs`): a one-round
//!   allocation's cost, and per further round the largest mean over a request's further
//!   rounds (a round fixes one agent, so a later round has fewer free agents and costs less:
//!   `n - 1` times the largest mean is at least the full-saturation request's further rounds,
//!   which are at least any request's first ones);
//! - capped redistribution: a one-round allocation, plus per further round the largest
//!   difference of the same request capped at `k` and `k - 1` rounds (its first rounds are its
//!   costliest, so a mean would not do);
//! - exact-boundary redistribution: its start the same way (`Rounds(0)`, the start alone, with
//!   its set-up), and a walk round's cost as the difference of the same request capped at `k`
//!   and `k - 1` rounds (every marginal the family reaches, the last direction that finds
//!   nothing to do included), times `WalkCost::bound(n, cap).rounds + 1`: the `+ 1` is the
//!   shedding of a previous period's internal forces (one solve and one line search, less than
//!   a round) that a reset allocator never runs.

use core::hint::black_box;

use cortex_m_semihosting::hprintln;
use tvmd_core::nalgebra::{Vector3, Vector6};
use tvmd_core::{
    AdmissibleSet, AllocationRequest, Allocator, CappedRedistribution, ExactBoundaryRedistribution,
    FailureMask, PseudoInverse, RedistributedPseudoInverse, RoundCap, TeamConfig, WalkCost,
    WeightedPseudoInverse,
};

use crate::allocation::SetTeam;
use crate::clock;

/// Allocations per measured request: each count within `4 * 40 / REPS` instructions.
const REPS: u32 = 2;

/// Requests of the calibration family (every pair of [`SCALES`] once).
const FAMILY: usize = 64;

/// Force and torque scales of the family, as fractions of the team's total thrust.
const SCALES: [f32; 8] = [0.0, 0.05, 0.2, 0.5, 1.0, 1.5, 3.0, 10.0];

/// The per-unit maxima of one team size (instructions).
#[derive(Clone, Copy, Debug, Default)]
pub struct Units {
    pseudo_inverse: u32,
    weighted: u32,
    rpi_base: u32,
    rpi_round: u32,
    start_base: u32,
    start_round: u32,
    walk_round: u32,
    capped_base: u32,
    capped_round: u32,
}

/// The certificates of a team of `N` agents (instructions per allocation).
#[derive(Clone, Copy, Debug, Default)]
pub struct Certificates {
    /// Agents.
    pub n: usize,
    /// The measured units.
    pub units: Units,
}

impl Certificates {
    /// The most instructions one allocation of `allocator` takes.
    pub fn allocation(&self, allocator: Certified) -> u32 {
        let u = &self.units;
        let further = self.n.saturating_sub(1) as u32;
        match allocator {
            Certified::PseudoInverse => u.pseudo_inverse,
            Certified::Weighted => u.weighted,
            Certified::Redistributed => u.rpi_base + further * u.rpi_round,
            Certified::Capped(k) => {
                u.capped_base + (k.min(self.n as u32).saturating_sub(1)) * u.capped_round
            }
            Certified::ExactBoundary(cap) => {
                let walk = WalkCost::bound(self.n, cap_limit(cap)).rounds + 1;
                u.start_base + further * u.start_round + walk * u.walk_round
            }
        }
    }
}

/// The allocators certified here (the target build's; Clarabel's need `std`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Certified {
    /// `PseudoInverse`.
    PseudoInverse,
    /// `WeightedPseudoInverse` (weights 1).
    Weighted,
    /// `RedistributedPseudoInverse`, the paper's.
    Redistributed,
    /// `CappedRedistribution` at this many rounds (its default: 2).
    Capped(u32),
    /// `ExactBoundaryRedistribution` with its walk capped (the default: `Rounds(2)`).
    ExactBoundary(RoundCap),
}

impl Certified {
    /// Every certified allocator and cap.
    pub const ALL: [Self; 6] = [
        Self::PseudoInverse,
        Self::Weighted,
        Self::Redistributed,
        Self::Capped(CappedRedistribution::DEFAULT_MAX_ROUNDS),
        Self::ExactBoundary(RoundCap::Rounds(tvmd_core::allocation::DEFAULT_MAX_ROUNDS)),
        Self::ExactBoundary(RoundCap::Uncapped),
    ];

    /// Its name in the printed table.
    pub fn name(&self) -> &'static str {
        match self {
            Self::PseudoInverse => "pseudo-inverse",
            Self::Weighted => "weighted-pseudo-inverse",
            Self::Redistributed => "redistributed-pseudo-inverse",
            Self::Capped(_) => "capped-redistribution",
            Self::ExactBoundary(RoundCap::Uncapped) => "exact-boundary, uncapped",
            Self::ExactBoundary(_) => "exact-boundary (default)",
        }
    }
}

fn cap_limit(cap: RoundCap) -> u32 {
    match cap {
        RoundCap::Rounds(k) => k,
        RoundCap::Uncapped => u32::MAX,
    }
}

/// The measured unit: one allocation by a reset allocator behind a call.
#[inline(never)]
fn allocate<A: Allocator<f32, N>, const N: usize>(
    a: &mut A,
    r: &AllocationRequest<'_, f32, N>,
) -> f32 {
    a.reset();
    a.allocate(r).e_f
}

/// The same call shape with no work.
#[inline(never)]
fn empty<A: Allocator<f32, N>, const N: usize>(
    _a: &mut A,
    r: &AllocationRequest<'_, f32, N>,
) -> f32 {
    r.wrench.x
}

/// Instructions of one allocation of `r` by `a` (reset before each).
pub fn cost<A: Allocator<f32, N>, const N: usize>(
    a: &mut A,
    r: &AllocationRequest<'_, f32, N>,
    per_tick: u32,
) -> u32 {
    let work = clock::ticks(REPS, &mut || {
        black_box(allocate(black_box(&mut *a), black_box(r)));
    });
    let overhead = clock::ticks(REPS, &mut || {
        black_box(empty(black_box(&mut *a), black_box(r)));
    });
    clock::per_call(work, overhead, per_tick, REPS)
}

/// A deterministic generator of the family (Numerical Recipes' LCG).
struct Lcg(u32);

impl Lcg {
    fn uniform(&mut self) -> f32 {
        self.0 = self.0.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        (self.0 >> 8) as f32 / (1u32 << 24) as f32
    }

    /// A unit vector (the axis `z` when the draw is too short to normalize).
    fn direction(&mut self) -> Vector3<f32> {
        let v = Vector3::new(
            2.0 * self.uniform() - 1.0,
            2.0 * self.uniform() - 1.0,
            2.0 * self.uniform() - 1.0,
        );
        v.try_normalize(1e-3).unwrap_or_else(Vector3::z)
    }
}

/// Ceiling of `a / b` (`b > 0`).
fn ceil_div(a: u32, b: u32) -> u32 {
    a.div_ceil(b.max(1))
}

/// Measures the units on `team` (every agent working) over the calibration family.
pub fn calibrate<const N: usize>(team: &TeamConfig<f32, N>, per_tick: u32) -> Certificates {
    let e = team.effectiveness(&FailureMask::none());
    let sets = [AdmissibleSet::from_limits(team.limits()); N];
    let total = N as f32 * team.limits().max_thrust();
    let weight = team.mass() * 9.81;
    let mut weighted = WeightedPseudoInverse::new([1.0f32; N]).ok();
    let mut eb = ExactBoundaryRedistribution::<f32, N>::new();
    let mut units = Units::default();
    // (cost, rounds beyond the first) of the rounds' means, taken once every base is known.
    let mut rpi = [(0u32, 0u32); FAMILY];
    let mut start = [(0u32, 0u32); FAMILY];
    let mut lcg = Lcg(0x5eed_0059);
    for (k, (rpi_slot, start_slot)) in rpi.iter_mut().zip(start.iter_mut()).enumerate() {
        let (fs, ts) = (
            SCALES[k % SCALES.len()],
            SCALES[(k / SCALES.len()) % SCALES.len()],
        );
        let torque = lcg.direction() * (ts * total * 0.25);
        let force = Vector3::new(0.0, 0.0, weight) + lcg.direction() * (fs * total);
        let mut wrench = Vector6::zeros();
        wrench.fixed_rows_mut::<3>(0).copy_from(&torque);
        wrench.fixed_rows_mut::<3>(3).copy_from(&force);
        let r = AllocationRequest {
            effectiveness: &e,
            sets: &sets,
            wrench,
        };
        units.pseudo_inverse = units
            .pseudo_inverse
            .max(cost(&mut PseudoInverse, &r, per_tick));
        if let Some(w) = weighted.as_mut() {
            units.weighted = units.weighted.max(cost(w, &r, per_tick));
        }
        let rounds = RedistributedPseudoInverse.allocate(&r).rounds;
        *rpi_slot = (
            cost(&mut RedistributedPseudoInverse, &r, per_tick),
            rounds.saturating_sub(1),
        );
        // The capped redistribution: one round, then each further round's own cost (its
        // first rounds are its most expensive: a mean would not bound a cap of 2).
        let mut previous = match CappedRedistribution::new(1) {
            Ok(mut c) => cost(&mut c, &r, per_tick),
            Err(_) => 0,
        };
        units.capped_base = units.capped_base.max(previous);
        let needed = CappedRedistribution::new(u32::MAX)
            .map(|mut c| c.allocate(&r).rounds)
            .unwrap_or(0);
        for k in 2..=needed.min(N as u32) {
            if let Ok(mut c) = CappedRedistribution::new(k) {
                let now = cost(&mut c, &r, per_tick);
                units.capped_round = units.capped_round.max(now.saturating_sub(previous));
                previous = now;
            }
        }
        // The start alone, then every walk round the uncapped walk takes, and the next.
        let mut capped = eb.with_round_cap(RoundCap::Rounds(0));
        let c0 = cost(&mut capped, &r, per_tick);
        capped.reset();
        capped.allocate(&r);
        *start_slot = (c0, capped.last_cost().start_rounds.saturating_sub(1));
        eb = eb.with_round_cap(RoundCap::Uncapped);
        eb.reset();
        eb.allocate(&r);
        let limit = WalkCost::bound(N, u32::MAX).rounds;
        let (mut previous, mut round) = (c0, 1);
        while round <= limit && round <= eb.last_cost().rounds + 1 {
            let mut capped = eb.with_round_cap(RoundCap::Rounds(round));
            let c = cost(&mut capped, &r, per_tick);
            units.walk_round = units.walk_round.max(c.saturating_sub(previous));
            previous = c;
            round += 1;
        }
    }
    let (rpi_base, rpi_round) = bases(&rpi);
    let (start_base, start_round) = bases(&start);
    units.rpi_base = rpi_base;
    units.rpi_round = rpi_round;
    units.start_base = start_base;
    units.start_round = start_round;
    Certificates { n: N, units }
}

/// From (cost, further rounds) pairs: the largest one-round cost, and the largest mean cost
/// of a further round over it.
fn bases(samples: &[(u32, u32)]) -> (u32, u32) {
    let base = samples
        .iter()
        .filter(|(_, further)| *further == 0)
        .map(|(c, _)| *c)
        .max()
        .unwrap_or(0);
    let round = samples
        .iter()
        .filter(|(_, further)| *further > 0)
        .map(|(c, further)| ceil_div(c.saturating_sub(base), *further))
        .max()
        .unwrap_or(0);
    (base, round)
}

/// Prints the certificates and checks each allocator's worst over `set` (its own team, built
/// by `allocation::team`) against them; `false` when a count exceeds its certificate.
pub fn check_set<const N: usize>(
    certificates: &Certificates,
    set: &SetTeam<N>,
    per_tick: u32,
) -> bool {
    let Some(team) = crate::allocation::team::<N>(set.name) else {
        hprintln!("certificate: FAIL: team {} refused", set.name);
        return false;
    };
    let Ok(mask) = FailureMask::with_failed(set.failed) else {
        hprintln!("certificate: FAIL: failures of {} refused", set.name);
        return false;
    };
    let e = team.effectiveness(&mask);
    let sets = [AdmissibleSet::from_limits(team.limits()); N];
    let mut ok = true;
    for allocator in Certified::ALL {
        let mut worst = 0;
        for q in set.requests {
            let r = AllocationRequest {
                effectiveness: &e,
                sets: &sets,
                wrench: Vector6::from_column_slice(&q.wrench),
            };
            let c = match allocator {
                Certified::PseudoInverse => cost(&mut PseudoInverse, &r, per_tick),
                Certified::Weighted => match WeightedPseudoInverse::new([1.0f32; N]) {
                    Ok(mut w) => cost(&mut w, &r, per_tick),
                    Err(_) => u32::MAX,
                },
                Certified::Redistributed => cost(&mut RedistributedPseudoInverse, &r, per_tick),
                Certified::Capped(k) => match CappedRedistribution::new(k) {
                    Ok(mut c) => cost(&mut c, &r, per_tick),
                    Err(_) => u32::MAX,
                },
                Certified::ExactBoundary(cap) => cost(
                    &mut ExactBoundaryRedistribution::<f32, N>::new().with_round_cap(cap),
                    &r,
                    per_tick,
                ),
            };
            worst = worst.max(c);
        }
        let certified = certificates.allocation(allocator);
        let within = worst <= certified;
        ok &= within;
        hprintln!(
            "certificate: allocation n = {:2} {:28} certified {:7} instructions; worst over the set {:10} {:7}{}",
            N,
            allocator.name(),
            certified,
            set.name,
            worst,
            if within { "" } else { "  FAIL: above its certificate" }
        );
    }
    ok
}

/// Prints the units of `c`.
pub fn print_units(c: &Certificates) {
    let u = &c.units;
    hprintln!(
        "certificate: units n = {:2} (max over {} generated requests): pseudo-inverse {}, weighted {}, redistributed one round {} + {} per further round (at most {}), capped {} + {} per further round, exact-boundary start {} + {} per further start round, {} per walk round (at most {} + 1 walk rounds capped at 2, {} + 1 uncapped)",
        c.n,
        FAMILY,
        u.pseudo_inverse,
        u.weighted,
        u.rpi_base,
        u.rpi_round,
        c.n.saturating_sub(1),
        u.capped_base,
        u.capped_round,
        u.start_base,
        u.start_round,
        u.walk_round,
        WalkCost::bound(c.n, tvmd_core::allocation::DEFAULT_MAX_ROUNDS).rounds,
        WalkCost::bound(c.n, u32::MAX).rounds
    );
}
