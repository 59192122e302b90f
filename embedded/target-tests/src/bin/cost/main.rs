//! On-target cost of the f32 control cycle (`Controller::step`, redistributed pseudo-inverse,
//! named rather than the default allocator: BENCHMARKS.md's counts are of the paper's cycle),
//! with the paper's law and with the offset-free law (`ControllerSettings::offset_free_law`;
//! n = 4 searching fails above 1,500 extra instructions), and with the fault detector reporting,
//! under the threshold and isolating (n = 4 fails above 1,500 and 3,500 extra instructions
//! over the offset-free law):
//! instructions per cycle counted on QEMU (`mps2-an386` Cortex-M4F, `mps2-an500` Cortex-M7)
//! run with `-icount shift=0`, and the cycle's peak stack measured by painting. Cases: hover and
//! planner-searching cycles of the paper's team (n = 4, A4-Inc) and of a 16-agent inconsistent
//! ring (the inputs of `examples/cycle_instructions.rs` and `benches/control_cycle.rs`).
//! Then the default allocator (`ExactBoundaryRedistribution`, issue 46): its hover and searching
//! cycles (paper's law), and over the allocation benchmark set's requests (`allocation.rs`) the
//! worst and median instructions per allocation, stack peak and agreement with the host's f32
//! forces, the walk capped at 0-2 rounds, and the n = 4 whole-cycle bound against issue 46's
//! 30,000 / 12,000 instructions (reported, not a failure: not met, see
//! docs/allocation-benchmark.md), with a tighter estimate: the searching cycle around an
//! allocation that hands back given forces, plus each allocation.
//! Then the C handle's per-call storage check at n = 4 and 16 (`storage.rs`), and the agents'
//! reports in the fault detector at n = 4 and 16 (`reports.rs`; n = 4 fails above 800 extra
//! instructions, issue 60).
//! Worst-case certificates (issue 59; `certificate.rs`, `cycle_certificate.rs`): per
//! allocator and n = 4, 6, 8, 16 the bound from the code's loop limits times per-unit maxima
//! measured on generated requests, checked against the allocation set's worst, every measured
//! cycle, and the recorded flights' cycles (`recorded.rs`): a count above its certificate fails.
//! Then issue 59's n = 16 saturating cycle with the redistribution capped (`capped.rs`; fails
//! above twice the paper law's cycle at the default cap), and the n = 4 whole-cycle estimate
//! checked on the one cycle that can be measured whole (`estimate.rs`).
//! Prints one line per case over semihosting; exits with failure if the clock cannot be
//! calibrated or a cycle does not run as intended. Run by `scripts/target.sh`.
#![no_std]
#![no_main]

use core::hint::black_box;
use core::panic::PanicInfo;

use cortex_m_rt::{entry, exception, ExceptionFrame};
use cortex_m_semihosting::{debug, hprintln};
use tvmd_core::controller::roll;
use tvmd_core::nalgebra::{convert, ComplexField, Vector3};
use tvmd_core::team::presets;
use tvmd_core::RoundCap;
use tvmd_core::{
    Allocator, Controller, ControllerSettings, ExactBoundaryRedistribution, FaultDetection,
    FaultResponse, PlannerStatus, PseudoInverse, RedistributedPseudoInverse, Reference, RigidState,
    TeamConfig,
};

mod allocation;
mod capped;
mod certificate;
mod clock;
mod cycle_certificate;
mod estimate;
mod recorded;
#[path = "../../recorded_file.rs"]
mod recorded_file;
mod reports;
mod stack;
mod storage;

use certificate::{Certificates, Certified};
use cycle_certificate::{law_of, Around};

/// Cycles per measurement: the tick quantization (one tick, 40 instructions, at each end of the
/// cycles' timing and of the overhead's) is spread over them: each count is within
/// 4 * 40 / REPS = 0.8 instructions.
const REPS: u32 = 200;

type Cycle<const N: usize, A = RedistributedPseudoInverse> = Controller<f32, N, A>;

/// The measured unit: one cycle behind a call, as callgrind's `tvmd_cycle_f32` on x86.
#[inline(never)]
/// The measured cycles' state and reference: at rest 0.2 m off the hover point, and either
/// holding where it is (hover) or flying to the point with the paper's pi/3 roll reference, which
/// the planner must truncate (searching).
pub(crate) fn cycle_case(searching: bool) -> (RigidState<f32>, Reference<f32>) {
    let state = RigidState::at_rest(Vector3::new(0.2f32, 0.0, 1.5));
    let mut reference = Reference::hover(if searching {
        Vector3::new(0.0, 0.0, 1.5)
    } else {
        state.position
    });
    if searching {
        reference.attitude = roll(convert::<f64, f32>(core::f64::consts::FRAC_PI_3));
    }
    (state, reference)
}

fn cycle<const N: usize, A: Allocator<f32, N>>(
    c: &mut Cycle<N, A>,
    s: &RigidState<f32>,
    r: &Reference<f32>,
) -> f32 {
    c.step(s, r).map(|o| o.commands[0].thrust).unwrap_or(-1.0)
}

/// The same call shape with no work: its cost (call, return, loop) is subtracted.
#[inline(never)]
fn empty<const N: usize, A: Allocator<f32, N>>(
    _c: &mut Cycle<N, A>,
    s: &RigidState<f32>,
    _r: &Reference<f32>,
) -> f32 {
    s.position.x
}

/// The team of `examples/cycle_instructions.rs` (n = 4), the authors' A6-Inc and A8-Inc, and
/// `benches/control_cycle.rs` (n = 16: an inconsistent ring of radius `0.5 sqrt(n / 4)`).
fn team<const N: usize>() -> Option<TeamConfig<f32, N>> {
    if N == 4 {
        presets::a4_inc().ok()
    } else if N == 6 {
        presets::a6_inc().ok()
    } else if N == 8 {
        presets::a8_inc().ok()
    } else {
        let radius = 0.5 * ComplexField::sqrt(N as f32 / 4.0);
        presets::ring(N, radius, true, presets::paper_limits()).ok()
    }
}

/// One measured case; `None` if the team or controller was refused.
struct Measured {
    instructions: u32,
    stack: usize,
    setup_stack: usize,
    status: PlannerStatus,
    iterations: u32,
}

fn measure<const N: usize, A: Allocator<f32, N> + Clone>(
    searching: bool,
    settings: ControllerSettings<f32>,
    allocator: A,
    per_tick: u32,
) -> Option<Measured> {
    let team = team::<N>()?;
    let mut built = None;
    // Set-up (the team's effectiveness, the Gram factor): once per change of team or failures.
    let setup_stack = stack::peak(&mut || {
        built = black_box(Controller::new(team, settings, allocator.clone()).ok());
    });
    let mut c = built?;
    let (state, reference) = cycle_case(searching);
    let out = c.step(&state, &reference).ok()?;
    let (status, iterations) = (out.planner.status, out.planner.iterations);
    // Each measured cycle steps a copy of the controller as the first step left it, so every
    // repetition is the same period: stepping one controller 200 times on a state that never
    // responds would let the offset-free estimate grow to its bound (a request no flight
    // makes). The copy's cost is in both closures and cancels.
    let work = clock::ticks(REPS, &mut || {
        let mut fresh = black_box(c.clone());
        black_box(cycle(
            black_box(&mut fresh),
            black_box(&state),
            black_box(&reference),
        ));
    });
    let overhead = clock::ticks(REPS, &mut || {
        let mut fresh = black_box(c.clone());
        black_box(empty(
            black_box(&mut fresh),
            black_box(&state),
            black_box(&reference),
        ));
    });
    let instructions = clock::per_call(work, overhead, per_tick, REPS);
    // The stack on the controller itself (a copy would sit on the painted stack).
    let stack = stack::peak(&mut || {
        black_box(cycle(
            black_box(&mut c),
            black_box(&state),
            black_box(&reference),
        ));
    });
    Some(Measured {
        instructions,
        stack,
        setup_stack,
        status,
        iterations,
    })
}

/// Largest extra cost (instructions) of the fault detector over the offset-free law, n = 4,
/// hover or searching, under the threshold or isolating (every working agent's two fits each
/// period): issue 47's bound.
const FAULT_DETECTION_EXTRA_BOUND: u32 = 1_500;

/// Largest extra cost (instructions) of the offset-free law over the paper's, n = 4,
/// searching (issue 44's bound).
const OFFSET_FREE_EXTRA_BOUND: u32 = 1_500;

fn report<const N: usize>(per_tick: u32, certificates: &Certificates, around: &Around) -> bool {
    let mut ok = true;
    for searching in [false, true] {
        let name = if searching { "searching" } else { "hover" };
        let mut paper_instructions = None;
        let mut offset_free_instructions = None;
        // The offset-free law with the fault detector reporting (issue 47).
        let detecting = ControllerSettings {
            fault_detection: Some(FaultDetection::recommended(FaultResponse::Report)),
            ..ControllerSettings::offset_free_law()
        };
        // The same with a stated model error so small that every residual is above the
        // threshold: the isolation (every working agent's fit) runs each period, the cost of a
        // period while a fault is suspected or confirmed.
        let isolating = ControllerSettings {
            fault_detection: FaultDetection::new(1e-6, 5.0, 5, FaultResponse::Report).ok(),
            ..ControllerSettings::offset_free_law()
        };
        for (law, settings) in [
            ("paper", ControllerSettings::paper()),
            ("offset-free", ControllerSettings::offset_free_law()),
            ("detecting", detecting),
            ("isolating", isolating),
        ] {
            let Some(m) =
                measure::<N, _>(searching, settings, RedistributedPseudoInverse, per_tick)
            else {
                ok = false;
                hprintln!(
                    "cost: n = {} {} {}: FAIL: team or controller refused",
                    N,
                    name,
                    law
                );
                continue;
            };
            let as_intended = (m.status == PlannerStatus::AlreadyFeasible) != searching;
            ok &= as_intended;
            ok &= around.check(
                (name, law),
                law_of(law),
                Certified::Redistributed,
                certificates,
                m.instructions,
            );
            hprintln!(
                "cost: n = {:2} {:9} cycle, {:11} law: {:6} instructions, peak stack {:5} B (Controller::new {:5} B; planner {:?}, {} iterations){}",
                N,
                name,
                law,
                m.instructions,
                m.stack,
                m.setup_stack,
                m.status,
                m.iterations,
                if as_intended { "" } else { "  FAIL: not the intended planner case" }
            );
            if law == "detecting" || law == "isolating" {
                let extra = m
                    .instructions
                    .saturating_sub(offset_free_instructions.unwrap_or(0));
                let bounded = N != 4 || extra <= FAULT_DETECTION_EXTRA_BOUND;
                ok &= bounded;
                hprintln!(
                    "cost: n = {:2} {:9} cycle: the fault detector {} costs {} instructions more than the offset-free law{}",
                    N,
                    name,
                    if law == "detecting" { "(under the threshold)" } else { "(isolating)" },
                    extra,
                    if bounded { "" } else { "  FAIL: above the bound" }
                );
                continue;
            }
            if law == "offset-free" {
                offset_free_instructions = Some(m.instructions);
            }
            match paper_instructions {
                None => paper_instructions = Some(m.instructions),
                Some(paper) => {
                    let extra = m.instructions.saturating_sub(paper);
                    let bounded = N != 4 || !searching || extra <= OFFSET_FREE_EXTRA_BOUND;
                    ok &= bounded;
                    hprintln!(
                        "cost: n = {:2} {:9} cycle: the offset-free law costs {} instructions more than the paper's{}",
                        N,
                        name,
                        extra,
                        if bounded { "" } else { "  FAIL: above the bound of 1,500" }
                    );
                }
            }
        }
    }
    // The default allocator's cycles under each certified law (the paper's first: the
    // pseudo-inverse's searching cycle, the law and planner with the cheapest allocation, to
    // which each allocation of the set is added for an upper bound of the default's whole cycle).
    for (law, law_name) in cycle_certificate::LAWS.iter().enumerate() {
        for searching in [false, true] {
            let name = if searching { "searching" } else { "hover" };
            let default = ExactBoundaryRedistribution::<f32, N>::new();
            let settings = cycle_certificate::settings(law);
            match measure::<N, _>(searching, settings, default, per_tick) {
                Some(m) => {
                    hprintln!(
                        "cost: n = {:2} {:9} cycle, {} law, exact-boundary-redistribution: {:6} instructions, peak stack {:5} B (Controller::new {:5} B)",
                        N, name, law_name, m.instructions, m.stack, m.setup_stack
                    );
                    let default = Certified::ExactBoundary(RoundCap::default());
                    let case = (name, *law_name);
                    ok &= around.check(case, law, default, certificates, m.instructions);
                }
                None => {
                    ok = false;
                    hprintln!("cost: n = {} {} default allocator: FAIL: refused", N, name);
                }
            }
        }
    }
    hprintln!(
        "cost: n = {:2} controller state (size_of Controller<f32, {}, _>): {} B",
        N,
        N,
        core::mem::size_of::<Cycle<N>>()
    );
    ok
}

#[entry]
fn main() -> ! {
    let ok = run();
    debug::exit(if ok {
        debug::EXIT_SUCCESS
    } else {
        debug::EXIT_FAILURE
    });
    #[allow(clippy::empty_loop)]
    loop {}
}

fn run() -> bool {
    let Some(mut cp) = cortex_m::Peripherals::take() else {
        hprintln!("cost: FAIL: core peripherals already taken");
        return false;
    };
    hprintln!(
        "cost: DWT CYCCNT {}",
        if clock::dwt_cyccnt_runs(&mut cp.DCB, &mut cp.DWT) {
            "runs"
        } else {
            "does not run (not modelled): SysTick used"
        }
    );
    clock::start(&mut cp.SYST);
    let cal = clock::calibrate();
    let per_tick = cal.instructions_per_tick();
    hprintln!(
        "cost: calibration: nop loops of 1,002,002 and 11,022,002 instructions took {} and {} SysTick ticks: {} instructions per tick{}",
        cal.short,
        cal.long,
        per_tick,
        if cal.is_exact() { " (exact)" } else { " (NOT exact)" }
    );
    if per_tick == 0 || !cal.is_exact() {
        hprintln!(
            "cost: FAIL: the SysTick does not count instructions (run QEMU with -icount shift=0)"
        );
        return false;
    }
    let (ok4, c4, around4) =
        certified::<4>(per_tick, &[&allocation::A4_INC, &allocation::A4_INC_F1]);
    let (ok6, _, _) = certified::<6>(per_tick, &[&allocation::A6_INC]);
    let (ok8, _, _) = certified::<8>(per_tick, &[&allocation::A8_INC]);
    let (ok16, c16, around16) = certified::<16>(per_tick, &[&allocation::RING16_INC]);
    let flights = recorded::check(&c16, &around16, per_tick);
    let checks = storage::report::<4>(per_tick) & storage::report::<16>(per_tick);
    let reports = reports::report::<4>(per_tick) & reports::report::<16>(per_tick);
    let capped = capped::report::<16>(per_tick, &[1, 2, 3], &c16, &around16);
    let estimate = estimate::report(per_tick).is_some();
    ok4 && ok6
        && ok8
        && ok16
        && flights
        && checks
        && reports
        && capped
        && estimate
        && report_set(per_tick, &c4, &around4)
}

/// The certificates of a team of `N` (`certificate.rs`), checked over the allocation set's
/// teams of that size, then the cycles of [`report`] checked against theirs.
fn certified<const N: usize>(
    per_tick: u32,
    sets: &[&allocation::SetTeam<N>],
) -> (bool, Certificates, Around) {
    let (Some(team), Some(around)) = (team::<N>(), Around::measure::<N>(per_tick)) else {
        hprintln!(
            "cost: n = {}: FAIL: team or the cycle around the allocation refused",
            N
        );
        return (false, Certificates::default(), Around::default());
    };
    let c = certificate::calibrate(&team, per_tick);
    certificate::print_units(&c);
    let mut ok = sets.iter().fold(true, |ok, set| {
        ok & certificate::check_set(&c, set, per_tick)
    });
    ok &= report::<N>(per_tick, &c, &around);
    (ok, c, around)
}

/// Issue 59's bounds on the whole n = 4 cycle with the default allocator, its walk capped at
/// `DEFAULT_MAX_ROUNDS` (instructions; issue 46 asked 30,000 of the uncapped walk).
const WORST_CYCLE_BOUND: u32 = 50_000;
const MEDIAN_CYCLE_BOUND: u32 = 12_000;

/// The default allocator over the allocation set, and the n = 4 whole-cycle bound: the
/// pseudo-inverse's searching cycle (law, planner, one solve) plus each allocation.
fn report_set(per_tick: u32, certificates: &Certificates, certified: &Around) -> bool {
    let base = measure::<4, _>(true, ControllerSettings::paper(), PseudoInverse, per_tick)
        .map(|m| m.instructions);
    // The same cycle around an allocation that only hands back the pseudo-inverse's allocation:
    // the law, planner, commands and checks without the allocator's own work.
    let around = estimate::around(per_tick);
    let a4 = allocation::report(&allocation::A4_INC, None, per_tick);
    let mut ok = [
        allocation::report(&allocation::A6_INC, None, per_tick).is_some(),
        allocation::report(&allocation::A8_INC, None, per_tick).is_some(),
        allocation::report(&allocation::RING16_INC, None, per_tick).is_some(),
        allocation::report(&allocation::A4_INC_F1, None, per_tick).is_some(),
    ]
    .iter()
    .all(|x| *x);
    // The other caps (issue 46): the n = 4 set with the walk capped otherwise, and uncapped.
    let mut capped = [None; CAPS.len()];
    for (cap, slot) in CAPS.iter().zip(capped.iter_mut()) {
        *slot = allocation::report(&allocation::A4_INC, Some(*cap), per_tick);
        ok &= slot.is_some();
    }
    let (Some(base), Some((worst, median))) = (base, a4) else {
        hprintln!("cost: FAIL: the n = 4 set or the pseudo-inverse cycle was refused");
        return false;
    };
    let (worst, median) = (base + worst, base + median);
    let within = worst <= WORST_CYCLE_BOUND && median <= MEDIAN_CYCLE_BOUND;
    hprintln!(
        "cost: n =  4 whole cycle with the default allocator over the set (pseudo-inverse searching cycle {} + allocation, an upper bound): worst {}, median {} instructions (issue 59: <= {}, <= {}){}",
        base,
        worst,
        median,
        WORST_CYCLE_BOUND,
        MEDIAN_CYCLE_BOUND,
        if within { "" } else { "  OVER (reported, not failed)" }
    );
    // The certificate of this configuration bounds the upper bound too (its cycle around the
    // allocation is the paper law's searching cycle with the planner's most iterations).
    let default = Certified::ExactBoundary(RoundCap::default());
    let ok = ok & certified.check(("set's worst", "paper"), 0, default, certificates, worst);
    if let Some(around) = around {
        let (worst, median) = (worst - base + around, median - base + around);
        hprintln!(
            "cost: n =  4 whole cycle with the default allocator over the set, estimated (the searching cycle around a given allocation {} + allocation): worst {}, median {} instructions",
            around,
            worst,
            median
        );
    }
    for (cap, c) in CAPS.iter().zip(capped) {
        if let Some((w, m)) = c {
            hprintln!(
                "cost: n =  4 whole cycle, walk {:?} (upper bound as above): worst {}, median {} instructions",
                cap,
                base + w,
                base + m
            );
        }
    }
    ok
}

/// Round caps measured on the n = 4 set beside the default (`Rounds(2)`).
const CAPS: [RoundCap; 3] = [RoundCap::Rounds(0), RoundCap::Rounds(1), RoundCap::Uncapped];

#[panic_handler]
fn panic(info: &PanicInfo<'_>) -> ! {
    hprintln!("cost: panic: {}", info);
    debug::exit(debug::EXIT_FAILURE);
    #[allow(clippy::empty_loop)]
    loop {}
}

#[exception]
unsafe fn HardFault(frame: &ExceptionFrame) -> ! {
    hprintln!("cost: hard fault at pc {:#010x}", frame.pc());
    debug::exit(debug::EXIT_FAILURE);
    #[allow(clippy::empty_loop)]
    loop {}
}
