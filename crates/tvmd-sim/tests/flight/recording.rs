//! The committed recording of 1,000 f32 control cycles of `paper-tilt`
//! (`tests/data/paper_tilt_f32.cycles`, replayed on the emulated Cortex-M by
//! `embedded/target-tests`) is what the current code records, and replaying it through a
//! controller built from its configuration words (as the firmware does) reproduces every
//! output bit for bit on the host.

use tvmd_scenario::{Precision, Scenario};
use tvmd_sim::control::{core_of_scenario, wire_config};
use tvmd_sim::recording::{cycle_words, CycleRecording};
use tvmd_sim::runner::record_cycles;
use tvmd_wire::{self as wire, Reader, Writer};

const COMMITTED: &[u8] = include_bytes!("../data/paper_tilt_f32.cycles");

/// The recording pins the paper's allocator, the redistributed pseudo-inverse (not the
/// default exact-boundary redistribution): it is the paper's f32 cycle the firmware replays, and
/// the on-target cost and stack numbers (BENCHMARKS.md) are of that cycle.
const RECORDED_ALLOCATOR: &str = "redistributed-pseudo-inverse";

#[test]
fn committed_recording_is_current() {
    let scenario = Scenario {
        allocator: RECORDED_ALLOCATOR.into(),
        ..Scenario::builtin("paper-tilt").unwrap()
    };
    let fresh = record_cycles(&scenario, 1000).unwrap();
    assert_eq!(fresh.cycles, 1000);
    assert_eq!(fresh.config.allocator_name(), RECORDED_ALLOCATOR);
    assert!(
        fresh.to_bytes() == COMMITTED,
        "tests/data/paper_tilt_f32.cycles is stale: regenerate it with `cargo run -p tvmd-cli \
         -- record-cycles paper-tilt --allocator redistributed-pseudo-inverse \
         --out crates/tvmd-sim/tests/data/paper_tilt_f32.cycles`"
    );
    assert_eq!(CycleRecording::from_bytes(COMMITTED).unwrap(), fresh);
}

#[test]
fn configuration_words_build_the_simulators_controller() {
    let s = Scenario {
        controller_precision: Precision::F32,
        ..Scenario::builtin("paper-tilt").unwrap()
    };
    let config = wire_config(&s).unwrap();
    let mut words = [0u32; wire::config_words(16)];
    let mut w = Writer::new(&mut words);
    config.put(&mut w).unwrap();
    assert_eq!(w.len(), wire::config_words(config.n));
    let back = wire::CoreConfig::get(&mut Reader::new(&words)).unwrap();
    assert_eq!(back, config);
    let (sim_core, n) = core_of_scenario::<f32>(&s).unwrap();
    assert_eq!(n, back.n);
    // Every field (team, AFS, cones, gains, allocator, ...) the same, to the last bit.
    assert_eq!(
        format!("{:?}", back.build().unwrap()),
        format!("{sim_core:?}")
    );
}

#[test]
fn host_replay_is_bit_identical_and_covers_the_planner_saturation() {
    let rec = CycleRecording::from_bytes(COMMITTED).unwrap();
    let n = rec.config.n;
    let mut ctl = rec.config.build().unwrap();
    let (mut planned, mut events) = (0, 0);
    for k in 0..rec.cycles {
        let words = rec.cycle(k).unwrap();
        assert_eq!(words.len(), cycle_words(n));
        let mut r = Reader::new(words);
        let event = r.u32().unwrap();
        if wire::replay_event(&mut ctl, event).unwrap_or_else(|e| panic!("cycle {k}: {e}")) {
            events += 1;
        }
        let (state, reference) = wire::get_input(&mut r).unwrap();
        let mut want = [0u32; wire::recorded_words(16)];
        let got_out = ctl.step(&state, &reference);
        let mut w = Writer::new(&mut want);
        match &got_out {
            Ok(o) => wire::put_recorded(&mut w, Some(o), &o.commands, n).unwrap(),
            Err(e) => wire::put_recorded(&mut w, None, &e.commands, n).unwrap(),
        }
        let len = w.len();
        assert_eq!(&want[..len], &words[words.len() - len..], "cycle {k}");
        if matches!(&got_out, Ok(o) if o.planner.status == tvmd_core::PlannerStatus::Planned) {
            planned += 1;
        }
    }
    // paper-tilt has no failure; the planner saturates (bisects) over part of the flight.
    assert_eq!(events, 0);
    eprintln!("{planned} of {} recorded cycles bisect", rec.cycles);
    assert!(planned > 10, "{planned} bisecting cycles");
}
