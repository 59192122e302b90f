//! Recorded f32 flights replayed on the target: the 1,000 consecutive control cycles
//! `tvmd-sim record-cycles` (crate tvmd-cli) wrote into
//! `crates/tvmd-sim/tests/data/paper_tilt_f32.cycles` (`paper-tilt`, the paper's allocator) and
//! `agent_failure_default_f32.cycles` (`agent-failure`, the default allocator, whose walk runs
//! after the loss) (the core's exact f32 inputs, failure masks, and the host's outputs), fed in
//! order to a fresh controller built from the recording's configuration words by the simulator's
//! own code (`wire::CoreConfig::build`), each output compared with the host's: bit-identical, or within
//! [`crate::HOST_REL`] of the quantity's scale.
//!
//! Scales: commanded gimbal angles and rotor speeds relative to the cycle's largest magnitude of
//! the same quantity (at least 1 rad, 1 rad/s), thrusts likewise (at least 1 N), `e_f` relative
//! to the cycle's total commanded thrust, `R_d` and `theta` absolute (entries of a rotation,
//! an angle in `[0, pi]`); the planner status must be equal.

use cortex_m_semihosting::hprintln;

use crate::recorded_file::{open, words, Opened};

// Shared with tvmd-sim (crate `tvmd-wire`): the recording's layout and the controller's
// construction.
use tvmd_wire as wire;

use wire::{Reader, Writer, AGENTS};

/// The committed recordings, each with the allocator it names.
static RECORDINGS: [(&str, &[u8]); 2] = [
    (
        "paper-tilt, paper's allocator",
        include_bytes!("../../../crates/tvmd-sim/tests/data/paper_tilt_f32.cycles"),
    ),
    (
        "agent-failure, default allocator",
        include_bytes!("../../../crates/tvmd-sim/tests/data/agent_failure_default_f32.cycles"),
    ),
];

/// Largest cycle of the recording format.
const MAX_CYCLE_WORDS: usize = wire::cycle_words(AGENTS);

/// The worst difference of a replay and where it is.
#[derive(Clone, Copy, Default)]
struct Worst {
    rel: f64,
    cycle: usize,
    what: &'static str,
}

impl Worst {
    fn update(&mut self, rel: f64, cycle: usize, what: &'static str) {
        if rel > self.rel {
            *self = Self { rel, cycle, what };
        }
    }
}

fn f(w: u32) -> f64 {
    f64::from(f32::from_bits(w))
}

/// Compares one cycle's recorded outputs; `Err` when the planner status differs.
fn compare(
    n: usize,
    got: &[u32],
    want: &[u32],
    cycle: usize,
    worst: &mut Worst,
) -> Result<(), &'static str> {
    let (gc, gr) = got.split_at(4 * n);
    let (wc, wr) = want.split_at(4 * n);
    // Per agent: eta_x, eta_y, thrust, omega.
    for (slots, floor, what) in [
        (&[0usize, 1][..], 1.0, "gimbal angle"),
        (&[2][..], 1.0, "thrust"),
        (&[3][..], 1.0, "rotor speed"),
    ] {
        let scale = wc
            .chunks(4)
            .flat_map(|a| slots.iter().map(move |s| f(a[*s]).abs()))
            .fold(floor, f64::max);
        for (g, w) in gc.chunks(4).zip(wc.chunks(4)) {
            for s in slots {
                worst.update((f(g[*s]) - f(w[*s])).abs() / scale, cycle, what);
            }
        }
    }
    let total_thrust = wc.chunks(4).map(|a| f(a[2]).abs()).sum::<f64>().max(1.0);
    worst.update((f(gr[0]) - f(wr[0])).abs() / total_thrust, cycle, "e_f");
    for k in 1..10 {
        worst.update((f(gr[k]) - f(wr[k])).abs(), cycle, "R_d");
    }
    worst.update((f(gr[10]) - f(wr[10])).abs(), cycle, "theta");
    if gr[11] != wr[11] {
        return Err("planner status differs from the host's");
    }
    Ok(())
}

/// Replays every recording; prints their summaries and returns whether every cycle passed.
pub fn replay() -> bool {
    let mut ok = true;
    for (name, recording) in RECORDINGS {
        ok &= replay_one(name, recording);
    }
    ok
}

fn replay_one(name: &str, recording: &[u8]) -> bool {
    match run(recording) {
        Ok((cycles, identical, planner, worst)) => {
            let ok = worst.rel <= crate::HOST_REL;
            hprintln!(
                "{} recording ({}): {} consecutive f32 cycles, {} bit-identical to the host ({} differ in R_d or theta, {} in the commands only), worst rel diff {:e} ({} at cycle {}; limit {:e})",
                if ok { "ok  " } else { "FAIL" },
                name,
                cycles,
                identical,
                planner,
                cycles - identical - planner,
                worst.rel,
                worst.what,
                worst.cycle,
                crate::HOST_REL
            );
            ok
        }
        Err(why) => {
            hprintln!("FAIL recording ({}): {}", name, why);
            false
        }
    }
}

/// Cycles, bit-identical cycles, cycles whose `R_d` or `theta` differ, the worst difference.
fn run(recording: &[u8]) -> Result<(usize, usize, usize, Worst), &'static str> {
    let Opened {
        n,
        cycles,
        start,
        len,
        controller: mut ctl,
    } = open(recording)?;
    let (mut identical, mut planner, mut worst) = (0, 0, Worst::default());
    for k in 0..cycles {
        let all =
            words::<MAX_CYCLE_WORDS>(recording, start + k * len, len).ok_or("truncated cycle")?;
        let cycle = all.get(..len).ok_or("cycle")?;
        let mut r = Reader::new(cycle);
        let event = r.u32().ok_or("event")?;
        wire::replay_event(&mut ctl, event)?;
        let (state, reference) = wire::get_input(&mut r).ok_or("malformed inputs")?;
        let mut got = [0u32; wire::recorded_words(AGENTS)];
        let mut w = Writer::new(&mut got);
        let written = match &ctl.step(&state, &reference) {
            Ok(o) => wire::put_recorded(&mut w, Some(o), &o.commands, n),
            Err(e) => wire::put_recorded(&mut w, None, &e.commands, n),
        };
        written.ok_or("output buffer")?;
        let out = w.len();
        let got = got.get(..out).ok_or("output")?;
        let want = cycle.get(len - out..).ok_or("output layout")?;
        if got == want {
            identical += 1;
        } else {
            // After the 4n command words: e_f, then R_d (9) and theta.
            let plan = 4 * n + 1..4 * n + 11;
            if got.get(plan.clone()) != want.get(plan) {
                planner += 1;
            }
            compare(n, got, want, k, &mut worst)?;
        }
    }
    Ok((cycles, identical, planner, worst))
}
