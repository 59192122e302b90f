//! The longer sweep behind `crates/tvmd-core/tests/clarabel_sequential.rs`: attainable requests
//! (`u = M f` with admissible `f`, about half of the gimbal angles and thrusts on a bound, so
//! many forces sit on corners of the gimbal set) per team; the fraction allocated exactly
//! (relative wrench error `<= 1e-9`) by the sequential convex allocator, the pyramid QP, the
//! redistributed pseudo-inverse and the exact-boundary redistribution, the sequential
//! allocator's largest step count and its mean wall time per call.
//!
//! Run: `cargo run --release --features clarabel --example sequential_convex_sweep [REQUESTS]`
//! (default 600 per team).

use std::time::Instant;

use tvmd::core::nalgebra::Vector3;
use tvmd::core::team::presets;
use tvmd::core::RoundCap;
use tvmd::core::{
    AdmissibleSet, Allocation, AllocationRequest, Allocator, ClarabelAllocator,
    ExactBoundaryRedistribution, FailureMask, GimbalCommand, RedistributedPseudoInverse,
    SequentialConvexAllocator, TeamConfig,
};

const CAP: usize = 10;

/// A small deterministic generator (xorshift64*): the root crate has no `rand`, and the sweep
/// only needs reproducible uniform draws.
struct Draws(u64);

impl Draws {
    fn unit(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
    }

    /// `lo` or `hi` with probability 1/6 each, else uniform in between.
    fn pick(&mut self, lo: f64, hi: f64) -> f64 {
        match (self.unit() * 6.0) as u32 {
            0 => lo,
            1 => hi,
            _ => lo + (hi - lo) * self.unit(),
        }
    }
}

fn exact(a: &Allocation<f64, CAP>, norm: f64) -> bool {
    a.wrench_error / norm.max(1.0) <= 1e-9
}

fn main() {
    let requests: usize = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(600);
    let teams: [(&str, TeamConfig<f64, CAP>); 4] = [
        ("A4-Inc", presets::a4_inc().expect("preset")),
        ("A4-Con", presets::a4_con().expect("preset")),
        (
            "ring of 6",
            presets::ring(6, 0.5, true, presets::paper_limits()).expect("preset"),
        ),
        (
            "ring of 8",
            presets::ring(8, 0.6, false, presets::paper_limits()).expect("preset"),
        ),
    ];
    let mut draws = Draws(0x5eed_1603);
    for (name, team) in &teams {
        let e = team.effectiveness(&FailureMask::none());
        let sets = [AdmissibleSet::from_limits(team.limits()); CAP];
        let set = sets[0];
        let mut seq = SequentialConvexAllocator::<f64, CAP>::default().with_warm_start(false);
        let mut qp = ClarabelAllocator::<f64, CAP>::new(1e-9, None).expect("lambda");
        let mut counts = [0usize; 4];
        let (mut steps, mut seconds) = (0, 0.0);
        for _ in 0..requests {
            let mut forces = [Vector3::zeros(); CAP];
            for f in forces.iter_mut().take(team.len()) {
                *f = GimbalCommand {
                    eta_x: draws.pick(set.eta_x().lo, set.eta_x().hi),
                    eta_y: draws.pick(set.eta_y().lo, set.eta_y().hi),
                    thrust: draws.pick(set.thrust().lo, set.thrust().hi),
                }
                .force();
            }
            let wrench = e.wrench(&forces);
            let request = AllocationRequest {
                effectiveness: &e,
                sets: &sets,
                wrench,
            };
            let started = Instant::now();
            let a = seq.allocate(&request);
            seconds += started.elapsed().as_secs_f64();
            steps = steps.max(a.rounds);
            let others = [
                qp.allocate(&request),
                RedistributedPseudoInverse.allocate(&request),
                ExactBoundaryRedistribution::new()
                    .with_round_cap(RoundCap::Uncapped)
                    .allocate(&request),
            ];
            let norm = wrench.norm();
            counts[0] += usize::from(exact(&a, norm));
            for (count, other) in counts.iter_mut().skip(1).zip(&others) {
                *count += usize::from(exact(other, norm));
            }
        }
        let pct = |c: usize| 100.0 * c as f64 / requests as f64;
        println!(
            "{name}: exact {:.1}% sequential convex, {:.1}% pyramid QP, {:.1}% redistributed \
             pseudo-inverse, {:.1}% exact-boundary redistribution; at most {steps} steps, \
             {:.0} us per sequential call",
            pct(counts[0]),
            pct(counts[1]),
            pct(counts[2]),
            pct(counts[3]),
            seconds / requests as f64 * 1e6
        );
    }
}
