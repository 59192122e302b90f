//! The committed recordings of 1,000 f32 control cycles (`tests/data/paper_tilt_f32.cycles`:
//! `paper-tilt` with the paper's allocator; `tests/data/agent_failure_default_f32.cycles`:
//! `agent-failure` with the default allocator; both replayed on the emulated Cortex-M by
//! `embedded/target-tests`) are what the current code records, and replaying each through a
//! controller built from its configuration words (as the firmware does) reproduces every
//! output bit for bit on the host.

use tvmd_scenario::{Precision, Scenario};
use tvmd_sim::control::{core_of_scenario, wire_config};
use tvmd_sim::recording::{cycle_words, CycleRecording};
use tvmd_sim::runner::record_cycles;
use tvmd_wire::{self as wire, Reader, Writer};

/// A committed recording: its file, its bytes, the scenario and allocator it pins, and the
/// failure-mask events it holds.
struct Committed {
    file: &'static str,
    bytes: &'static [u8],
    scenario: &'static str,
    allocator: &'static str,
    events: usize,
    /// What it must exercise, at least: cycles whose planner bisects, cycles with a saturated
    /// agent.
    min_planned: usize,
    min_saturated: usize,
}

/// The paper's f32 cycle (the redistributed pseudo-inverse), whose on-target cost and stack
/// numbers (docs/benchmarks.md) are of that cycle; and the default allocator, the exact-boundary
/// redistribution, where its walk runs: on `paper-tilt` the planner keeps every request inside
/// the agents' sets and the two allocators' 1,000 cycles are the same bits, while after
/// `agent-failure`'s loss of agent 0 (t = 5 s) the three others saturate.
const RECORDINGS: [Committed; 2] = [
    Committed {
        file: "paper_tilt_f32.cycles",
        bytes: include_bytes!("../data/paper_tilt_f32.cycles"),
        scenario: "paper-tilt",
        allocator: "redistributed-pseudo-inverse",
        events: 0,
        min_planned: 10,
        min_saturated: 0,
    },
    Committed {
        file: "agent_failure_default_f32.cycles",
        bytes: include_bytes!("../data/agent_failure_default_f32.cycles"),
        scenario: "agent-failure",
        allocator: "exact-boundary-redistribution",
        events: 1,
        min_planned: 0,
        min_saturated: 10,
    },
];

#[test]
fn committed_recordings_are_current() {
    for committed in &RECORDINGS {
        let scenario = Scenario {
            allocator: committed.allocator.into(),
            ..Scenario::builtin(committed.scenario).unwrap()
        };
        let fresh = record_cycles(&scenario, 1000).unwrap();
        assert_eq!(fresh.cycles, 1000);
        assert_eq!(fresh.config.allocator_name(), committed.allocator);
        assert!(
            fresh.to_bytes() == committed.bytes,
            "tests/data/{file} is stale: regenerate it with `cargo run --release -p tvmd-cli \
             -- record-cycles {scenario} --allocator {allocator} \
             --out crates/tvmd-sim/tests/data/{file}`",
            file = committed.file,
            scenario = committed.scenario,
            allocator = committed.allocator
        );
        assert_eq!(CycleRecording::from_bytes(committed.bytes).unwrap(), fresh);
    }
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
fn host_replays_are_bit_identical_and_cover_the_planner_saturation() {
    for committed in &RECORDINGS {
        host_replay(committed);
    }
}

fn host_replay(committed: &Committed) {
    let rec = CycleRecording::from_bytes(committed.bytes).unwrap();
    let n = rec.config.n;
    let mut ctl = rec.config.build().unwrap();
    let (mut planned, mut saturated, mut events) = (0, 0, 0);
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
        if matches!(&got_out, Ok(o) if o.allocation.saturated.iter().any(|s| *s)) {
            saturated += 1;
        }
    }
    eprintln!(
        "{}: of {} recorded cycles {planned} bisect, {saturated} saturate an agent",
        committed.file, rec.cycles
    );
    assert_eq!(events, committed.events, "{}", committed.file);
    assert!(
        planned >= committed.min_planned,
        "{planned} bisecting cycles"
    );
    assert!(
        saturated >= committed.min_saturated,
        "{saturated} saturating cycles"
    );
}
