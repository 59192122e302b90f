//! Processor in the loop: `paper-tilt` flown with the f32 controller inside QEMU (Cortex-M4F,
//! `mps2-an386`; Cortex-M7, `mps2-an500`) matches the in-process f32 flight and reproduces the
//! planner saturation. Needs `qemu-system-arm` and the PIL firmware, so `#[ignore]`d in plain
//! `cargo test`; `scripts/target.sh` builds the firmware and runs these with `--ignored`.

use tvmd_scenario::{Precision, Scenario};
use tvmd_sim::control::hover_roll_limit;
use tvmd_sim::pil::PilTarget;
use tvmd_sim::runner::{run_scenario, run_scenario_on};
use tvmd_sim::sim::FlightDifference;
use tvmd_sim::SimError;

fn paper_tilt_f32() -> Scenario {
    Scenario {
        controller_precision: Precision::F32,
        ..Scenario::builtin("paper-tilt").unwrap()
    }
}

fn pil_flight_matches_the_host_f32_flight(target: PilTarget) {
    let s = paper_tilt_f32();
    let host = run_scenario(&s, None, None).unwrap();
    let pil = run_scenario_on(&s, Some(target), None, None).unwrap();
    assert_eq!(host.summary.controller_target, "host");
    assert_eq!(pil.summary.controller_target, target.label());
    assert_eq!(pil.summary.controller_precision, Precision::F32);
    let d = FlightDifference::between(&host.samples, &pil.samples).expect("matching samples");
    eprintln!("{target} PIL vs host f32, paper-tilt: {d:#?}");
    assert_eq!(d.samples, 1600);
    // Bounds 5-10x the differences measured on both boards (README, "Processor in the
    // loop"): position 1.9e-6 m (t = 15.99 s, sliding on the ground), attitude 3.6e-7 rad,
    // gimbal angles 4.5e-7 rad, thrust 8.0e-5 N (at touchdown, t = 14.37 s). The two libm
    // builds differ by an ulp in about a tenth of the cycles (the target tests' recording,
    // all within HOST_REL = 1e-5), and the closed loop carries that round-off along.
    assert!(d.position < 1e-5, "{d:?}");
    assert!(d.attitude < 2e-6, "{d:?}");
    assert!(d.gimbal < 5e-6, "{d:?}");
    assert!(d.thrust < 5e-4, "{d:?}");
    assert_eq!(pil.summary.cycle_errors, 0);
    // The planner saturation reproduced on the target: the planned roll stops at
    // atan(c_y(1, s)), as the in-process flights do (tests/closed_loop.rs).
    let limit = hover_roll_limit(&s, s.relaxation).unwrap();
    let planned = pil.summary.max_planned_roll.unwrap();
    assert!((planned - limit).abs() < 0.01, "{planned} vs {limit}");
    let host_planned = host.summary.max_planned_roll.unwrap();
    eprintln!("max planned roll: {target} {planned}, host {host_planned}, limit {limit}");
    assert!(
        (planned - host_planned).abs() < 1e-5,
        "{planned} vs {host_planned}"
    );
    assert!(pil.summary.max_roll < planned + 0.01);
}

#[test]
#[ignore = "needs qemu-system-arm and the PIL firmware; run by scripts/target.sh"]
fn cortex_m4_pil_flight_of_paper_tilt() {
    pil_flight_matches_the_host_f32_flight(PilTarget::CortexM4);
}

#[test]
#[ignore = "needs qemu-system-arm and the PIL firmware; run by scripts/target.sh"]
fn cortex_m7_pil_flight_of_paper_tilt() {
    pil_flight_matches_the_host_f32_flight(PilTarget::CortexM7);
}

#[test]
fn pil_needs_the_f32_controller_and_a_known_target() {
    let s = Scenario::builtin("paper-tilt").unwrap();
    let e = run_scenario_on(&s, Some(PilTarget::CortexM4), None, None).unwrap_err();
    assert!(
        matches!(&e, SimError::Scenario(tvmd_scenario::ScenarioError::InvalidScenario { field, .. }) if field == "controller_precision"),
        "{e}"
    );
    let e = tvmd_sim::runner::RunSpec::on_target(
        s.clone(),
        None,
        Some(PilTarget::CortexM7),
        Some(Precision::F64),
    )
    .unwrap_err();
    assert!(e.to_string().contains("f32"), "{e}");
    let spec =
        tvmd_sim::runner::RunSpec::on_target(s, None, Some(PilTarget::CortexM7), None).unwrap();
    assert_eq!(spec.scenario.controller_precision, Precision::F32);
    assert!("cortex-m3".parse::<PilTarget>().is_err());
}

/// The offset-free law crosses the link (its settings in the configuration words, the landed
/// hold as its own frame): `paper-experiment-offset-free` (tether, thrust error, servo and
/// rotor dynamics, noise, one period of latency) flown on the Cortex-M4F ends as the host's f32
/// flight does. Through stage B the allocation saturates (about 240 periods) and which agent
/// saturates first hangs on the last bits, so the two flights part there for a while (as the
/// host's f32 and f64 flights do); over the last 4 s of hover they agree.
#[test]
#[ignore = "needs qemu-system-arm and the PIL firmware; run by scripts/target.sh"]
fn pil_flight_of_the_offset_free_paper_experiment_matches_the_host() {
    let s = Scenario {
        controller_precision: Precision::F32,
        ..Scenario::builtin("paper-experiment-offset-free").unwrap()
    };
    assert!(!s.law.is_paper());
    let host = run_scenario(&s, None, None).unwrap();
    let pil = run_scenario_on(&s, Some(PilTarget::CortexM4), None, None).unwrap();
    assert_eq!(pil.summary.cycle_errors, 0);
    let whole = FlightDifference::between(&host.samples, &pil.samples).unwrap();
    let hover = |r: &tvmd_sim::sim::RunResult| -> Vec<_> {
        r.samples.iter().filter(|x| x.t >= 16.0).cloned().collect()
    };
    let d = FlightDifference::between(&hover(&host), &hover(&pil)).unwrap();
    eprintln!(
        "cortex-m4 PIL vs host f32, paper-experiment-offset-free: whole {whole:#?}, 16-20 s {d:#?}"
    );
    assert_eq!(d.samples, 400);
    // Above the differences measured on the Cortex-M4F over 16-20 s (1.4e-5 m at 16.0 s, still
    // decaying; 1.3e-8 rad, 2.6e-6 rad of gimbal, 2.4e-6 N) by 3.5x to 70x; over the whole
    // flight 5.2 cm, a gimbal of an idle agent by pi/2 and 12 N at 7.9 s, inside stage B's
    // saturation.
    assert!(
        d.position < 5e-5 && d.attitude < 1e-6 && d.gimbal < 1e-5 && d.thrust < 1e-4,
        "{d:?}"
    );
    let steady = |r: &tvmd_sim::sim::RunResult| {
        r.summary
            .metrics
            .position
            .as_ref()
            .unwrap()
            .steady_state
            .unwrap()
    };
    let (h, p) = (steady(&host), steady(&pil));
    eprintln!("steady-state position error: host {h}, cortex-m4 {p}");
    assert!(p < 0.01 && (p - h).abs() < 1e-5, "{p} vs {h}");
}

/// A failure mask crosses the link: A4-Inc loses agent 0 at t = 5 s (controller informed); the
/// target's hover classification and flight match the host's.
#[test]
#[ignore = "needs qemu-system-arm and the PIL firmware; run by scripts/target.sh"]
fn pil_flight_with_an_agent_failure_matches_the_host() {
    let mut s = Scenario {
        controller_precision: Precision::F32,
        ..Scenario::builtin("agent-failure").unwrap()
    };
    s.duration = 6.0;
    let host = run_scenario(&s, None, None).unwrap();
    let pil = run_scenario_on(&s, Some(PilTarget::CortexM4), None, None).unwrap();
    assert_eq!(host.summary.hover_classifications.len(), 1);
    assert_eq!(
        pil.summary.hover_classifications,
        host.summary.hover_classifications
    );
    let d = FlightDifference::between(&host.samples, &pil.samples).unwrap();
    eprintln!("cortex-m4 PIL vs host f32, agent-failure to 6 s: {d:#?}");
    assert!(
        d.position < 1e-5 && d.gimbal < 5e-6 && d.thrust < 5e-4,
        "{d:?}"
    );
}

/// The firmware answers a corrupted frame and a cycle before its configuration with an error
/// frame (which the host reports), and the next good frame still parses.
#[test]
#[ignore = "needs qemu-system-arm and the PIL firmware; run by scripts/target.sh"]
fn pil_firmware_reports_a_corrupted_frame_and_an_unconfigured_cycle() {
    use std::time::{Duration, Instant};
    use tvmd_sim::pil::{firmware_path, frame, QemuLink};
    use tvmd_wire as wire;

    let mut link = QemuLink::spawn("mps2-an386", &firmware_path().unwrap()).unwrap();
    let soon = || Instant::now() + Duration::from_secs(30);
    let ready = link.receive(soon()).unwrap();
    assert_eq!(
        (ready.kind, ready.words()),
        (wire::KIND_READY, vec![wire::PROTOCOL_VERSION])
    );
    let step = frame::bytes_of(&[0; wire::INPUT_WORDS]);
    let mut bad = frame::encode(wire::KIND_STEP, 7, &step).unwrap();
    bad[20] ^= 1;
    link.send(&bad).unwrap();
    let reply = link.receive(soon()).unwrap();
    assert_eq!((reply.kind, reply.seq), (wire::KIND_ERROR, 7));
    assert_eq!(reply.text(0), "checksum mismatch");
    link.send(&frame::encode(wire::KIND_STEP, 8, &step).unwrap())
        .unwrap();
    let reply = link.receive(soon()).unwrap();
    assert_eq!((reply.kind, reply.seq), (wire::KIND_ERROR, 8));
    assert_eq!(reply.text(0), "controller not configured");
}

/// The default allocator (the exact-boundary redistribution) in the loop on the Cortex-M4F,
/// where its walk runs: `agent-failure` (agent 0 loses its thrust at t = 5 s, the controller
/// is told, the three others saturate) flown by the firmware matches the in-process f32 flight.
#[test]
#[ignore = "needs qemu-system-arm and the PIL firmware; run by scripts/target.sh"]
fn cortex_m4_pil_flight_with_the_default_allocator() {
    let s = Scenario {
        controller_precision: Precision::F32,
        allocator: "exact-boundary-redistribution".into(),
        ..Scenario::builtin("agent-failure").unwrap()
    };
    let host = run_scenario(&s, None, None).unwrap();
    let pil = run_scenario_on(&s, Some(PilTarget::CortexM4), None, None).unwrap();
    let d = FlightDifference::between(&host.samples, &pil.samples).expect("matching samples");
    eprintln!("cortex-m4 PIL vs host f32, agent-failure, default allocator: {d:#?}");
    assert_eq!(pil.summary.cycle_errors, 0);
    // The same bounds as paper-tilt's (the same libm ulps carried by the closed loop).
    assert!(d.position < 1e-5, "{d:?}");
    assert!(d.attitude < 2e-6, "{d:?}");
    assert!(d.gimbal < 5e-6, "{d:?}");
    assert!(d.thrust < 5e-4, "{d:?}");
}

/// `scenarios/faults/loss-hover.toml` flown by A6-Inc (agent 0 loses its thrust at 4 s, the
/// controller not told; the detector confirms the loss and masks it; the five others hold the
/// hover) with the allocator's round cap at 3, in f32.
fn fault_scenario() -> Scenario {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../scenarios/faults/loss-hover.toml"
    );
    let mut s = Scenario {
        controller_precision: Precision::F32,
        allocator_max_rounds: Some(tvmd_core::RoundCap::Rounds(3)),
        ..Scenario::from_file(path).unwrap()
    };
    s.team.preset = Some("a6-inc".into());
    s.team.agents = None;
    s
}

/// The fault detector and the round cap cross the link (the configuration words carry both;
/// each cycle's answer carries the detector's report, its masking and the mask in force): the
/// Cortex-M4F flies the undetected loss as the host's f32 controller does, within the bounds
/// of paper-tilt's flights, and reports the same detection and masking.
#[test]
#[ignore = "needs qemu-system-arm and the PIL firmware; run by scripts/target.sh"]
fn pil_flight_with_fault_detection_and_a_round_cap_matches_the_host() {
    let s = fault_scenario();
    assert!(s.fault_detection.is_some());
    let host = run_scenario(&s, None, None).unwrap();
    let pil = run_scenario_on(&s, Some(PilTarget::CortexM4), None, None).unwrap();
    assert_eq!(pil.summary.cycle_errors, 0);
    let detected = |r: &tvmd_sim::sim::RunResult| r.summary.fault.unwrap();
    let (h, p) = (detected(&host), detected(&pil));
    eprintln!("fault summary: host {h:?}, cortex-m4 {p:?}");
    assert!(h.masked.is_some(), "{h:?}");
    // The same detection, to the tick; the statistic's peak to the libm ulps.
    let events = |f: &tvmd_sim::FaultSummary| {
        (
            f.first_alarm,
            f.first_suspected,
            f.first_confirmed,
            f.first_loss,
            f.masked,
            f.confirmed_ticks,
        )
    };
    let d = FlightDifference::between(&host.samples, &pil.samples).expect("matching samples");
    eprintln!("cortex-m4 PIL vs host f32, loss-hover with detection, round cap 3: {d:#?}");
    assert_eq!(events(&p), events(&h));
    assert_eq!(
        pil.summary.hover_classifications,
        host.summary.hover_classifications
    );
    assert!(d.position < 1e-5, "{d:?}");
    assert!(d.attitude < 2e-6, "{d:?}");
    assert!(d.gimbal < 5e-6, "{d:?}");
    assert!(d.thrust < 5e-4, "{d:?}");
}

/// The configuration words carry the detector and the round cap, so the recorder records
/// such a flight; the null-space stage, which the target's firmware is built without, is
/// refused rather than flown without it.
#[test]
fn the_words_carry_fault_detection_and_the_round_cap() {
    let s = fault_scenario();
    let config = tvmd_sim::control::wire_config(&s).unwrap();
    assert_eq!(config.max_rounds, tvmd_core::RoundCap::Rounds(3));
    let settings = tvmd_sim::control::controller_settings::<f32>(&s).unwrap();
    assert_eq!(config.fault_detection, settings.fault_detection);
    assert!(config.fault_detection.is_some());
    let recording = tvmd_sim::runner::record_cycles(&s, 10).unwrap();
    assert_eq!(recording.config, config);
    let back = tvmd_sim::CycleRecording::from_bytes(&recording.to_bytes()).unwrap();
    assert_eq!(back, recording);
    let with_stage = Scenario {
        null_space: Some("margin".parse().unwrap()),
        ..s
    };
    let e = run_scenario_on(&with_stage, Some(PilTarget::CortexM4), None, None).unwrap_err();
    assert!(
        matches!(&e, SimError::Scenario(tvmd_scenario::ScenarioError::InvalidScenario { field, .. }) if field == "null_space"),
        "{e}"
    );
}
