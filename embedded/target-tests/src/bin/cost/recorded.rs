//! The recorded f32 flights' cycles timed (the recordings `recording.rs` of the target tests
//! replays): each cycle's instructions, the worst per flight checked against the certificate
//! of the recording's controller (`tvmd_wire::WireController`, capacity 16, whatever the team).

use core::hint::black_box;

use cortex_m_semihosting::hprintln;

use crate::recorded_file::{open, words};
use tvmd_core::RoundCap;
use tvmd_wire::{self as wire, Reader, AGENTS};

use crate::certificate::{Certificates, Certified};
use crate::clock;
use crate::cycle_certificate::Around;

/// Each recording, its allocator, and the law it is certified under (`cycle_certificate::LAWS`;
/// the largest where the recording's law is not the paper's).
static RECORDINGS: [(&str, &[u8], Certified, usize); 2] = [
    (
        "paper-tilt",
        include_bytes!("../../../../../crates/tvmd-sim/tests/data/paper_tilt_f32.cycles"),
        Certified::Redistributed,
        0,
    ),
    (
        "agent-failure",
        include_bytes!(
            "../../../../../crates/tvmd-sim/tests/data/agent_failure_default_f32.cycles"
        ),
        Certified::ExactBoundary(RoundCap::Rounds(tvmd_core::allocation::DEFAULT_MAX_ROUNDS)),
        2,
    ),
];

/// Timed passes per cycle.
const REPS: u32 = 2;

#[inline(never)]
fn step(
    c: &mut wire::WireController,
    s: &tvmd_core::RigidState<f32>,
    r: &tvmd_core::Reference<f32>,
) -> bool {
    c.step(s, r).is_ok()
}

#[inline(never)]
fn empty(
    _c: &mut wire::WireController,
    s: &tvmd_core::RigidState<f32>,
    _r: &tvmd_core::Reference<f32>,
) -> bool {
    s.position.x > 0.0
}

/// (agents, cycles, worst instructions, at which cycle) of one recording.
fn time(recording: &[u8], per_tick: u32) -> Result<(usize, usize, u32, usize), &'static str> {
    let flight = open(recording)?;
    let (n, cycles, start, len) = (flight.n, flight.cycles, flight.start, flight.len);
    let mut ctl = flight.controller;
    let (mut worst, mut at) = (0, 0);
    for k in 0..cycles {
        let all = words::<{ wire::cycle_words(AGENTS) }>(recording, start + k * len, len)
            .ok_or("truncated cycle")?;
        let mut r = Reader::new(all.get(..len).ok_or("cycle")?);
        wire::replay_event(&mut ctl, r.u32().ok_or("event")?)?;
        let (state, reference) = wire::get_input(&mut r).ok_or("malformed inputs")?;
        // Each timed pass steps a copy of the controller as the flight left it; the copy's
        // cost is in both closures and cancels.
        let work = clock::ticks(REPS, &mut || {
            let mut fresh = black_box(ctl.clone());
            black_box(step(
                black_box(&mut fresh),
                black_box(&state),
                black_box(&reference),
            ));
        });
        let overhead = clock::ticks(REPS, &mut || {
            let mut fresh = black_box(ctl.clone());
            black_box(empty(
                black_box(&mut fresh),
                black_box(&state),
                black_box(&reference),
            ));
        });
        let instructions = clock::per_call(work, overhead, per_tick, REPS);
        if instructions > worst {
            (worst, at) = (instructions, k);
        }
        // The flight goes on from the real step.
        black_box(ctl.step(&state, &reference).is_ok());
    }
    Ok((n, cycles, worst, at))
}

/// Times every recording and checks its worst cycle against the capacity-16 certificate.
pub fn check(certificates: &Certificates, around: &Around, per_tick: u32) -> bool {
    let mut ok = true;
    for (name, recording, allocator, law) in &RECORDINGS {
        match time(recording, per_tick) {
            Ok((n, cycles, worst, at)) => {
                hprintln!(
                    "cost: recorded flight {} ({} cycles, {} agents, capacity {}): worst cycle {} instructions (cycle {})",
                    name, cycles, n, AGENTS, worst, at
                );
                ok &= around.check((name, "recorded"), *law, *allocator, certificates, worst);
            }
            Err(why) => {
                hprintln!("cost: recorded flight {}: FAIL: {}", name, why);
                ok = false;
            }
        }
    }
    ok
}
