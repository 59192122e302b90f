//! Hover classification of failures in the loop (issue 13, Deliver 3): the README's failure
//! scenario with A4-Inc is logged "not hover-capable" at the failure, the `land` response
//! turns it into a controlled descent, and the A6-Inc failure is logged "capable". Both
//! precisions, since the classification runs in the controller's float type.

use mcap::MessageStream;
use tvmd_scenario::{OnHoverLoss, Precision, Scenario};
use tvmd_sim::runner::run_scenario;
use tvmd_sim::sim::RunResult;

fn run(name: &str, land: bool, precision: Precision) -> RunResult {
    run_with(name, land, precision, None)
}

fn run_with(name: &str, land: bool, precision: Precision, allocator: Option<&str>) -> RunResult {
    let mut s = Scenario::builtin(name).unwrap();
    if let Some(a) = allocator {
        s.allocator = a.into();
    }
    if land {
        s.failure_response.on_hover_loss = OnHoverLoss::Land;
        assert_eq!(s.failure_response.landing_acceleration, 1.0);
    }
    s.controller_precision = precision;
    run_scenario(&s, None, None).unwrap()
}

#[test]
fn a4_inc_failure_is_classified_not_capable_and_keeps_flying_by_default() {
    for precision in Precision::ALL {
        // Pinned to the redistributed pseudo-inverse, whose saturation issue 13 made honest.
        // The default exact-boundary redistribution: the test after this one.
        let r = run_with(
            "agent-failure",
            false,
            precision,
            Some("redistributed-pseudo-inverse"),
        );
        let c = &r.summary.hover_classifications;
        assert_eq!(c.len(), 1, "{c:?}");
        assert!(
            (c[0].time - 5.0).abs() < 1e-9 && !c[0].capable && !c[0].landing,
            "{c:?}"
        );
        assert!(c[0].margin.abs() < 1e-3, "{c:?}");
        // The default response keeps flying. With honest saturation (issue 13: a saturated
        // force projected onto its clamped direction) the noise-free flight balances on the
        // zero margin instead of flipping (measured max tilt 0.085 rad); the flip was an
        // artifact of saturated forces keeping their norm along a direction they lacked.
        assert!(r.summary.max_tilt < 0.15, "{}", r.summary.max_tilt);
    }
}

/// The exact-boundary walk chooses its result torque first
/// (`ExactBoundaryRedistribution::TORQUE_PRIORITY`): chosen by the plain wrench error it left the
/// torque short while the three agents sat on their limits, and the team tilted to 0.613 rad
/// (f64; 0.521 rad in f32) in the descent from 12 s. Measured now: 0.054 rad (f32: 0.0067).
#[test]
fn a4_inc_failure_keeps_its_attitude_with_the_exact_boundary_walk() {
    for precision in Precision::ALL {
        let mut s = Scenario::builtin("agent-failure").unwrap();
        s.allocator = "exact-boundary-redistribution".into();
        s.controller_precision = precision;
        let r = run_scenario(&s, None, None).unwrap();
        assert!(
            r.summary.max_tilt < 0.15,
            "{precision:?}: {}",
            r.summary.max_tilt
        );
    }
}

#[test]
fn a4_inc_failure_with_land_is_a_controlled_descent() {
    for precision in Precision::ALL {
        let r = run("agent-failure", true, precision);
        let c = &r.summary.hover_classifications;
        assert!(c.len() == 1 && !c[0].capable && c[0].landing, "{c:?}");
        let after: Vec<_> = r.samples.iter().filter(|x| x.t >= 5.0).collect();
        // Level: the tilt stays below 0.1 rad (it reaches pi without landing).
        let tilt = |x: &tvmd_sim::sim::Sample| {
            let [roll, pitch, _] = x.roll_pitch_yaw;
            (roll.cos() * pitch.cos()).acos()
        };
        let max_tilt = after.iter().map(|x| tilt(x)).fold(0.0, f64::max);
        assert!(max_tilt < 0.1, "{precision:?}: max tilt {max_tilt}");
        // On the ground with rotors idle well before the scenario's own descent at 12 s.
        let landed = after
            .iter()
            .find(|x| x.commands.iter().all(|c| c.thrust == 0.0))
            .expect("rotors idle after touchdown");
        assert!(
            landed.t < 9.0 && landed.position[2] < 0.06,
            "{} {:?}",
            landed.t,
            landed.position
        );
        // Until then: at the failure's x, y (within 5 cm), never climbing, never faster down
        // than the reference's touchdown speed sqrt(2 a z_0) = 1.73 m/s (a = 1.0, z_0 = 1.5 m).
        // (After touchdown the ground contact may bounce it a few cm/s.)
        for x in after.iter().filter(|x| x.t < landed.t) {
            assert!(
                x.position[0].hypot(x.position[1]) < 0.05,
                "{:?}",
                x.position
            );
            assert!(
                x.velocity[2] < 0.05 && x.velocity[2] > -1.8,
                "{:?}",
                x.velocity
            );
        }
        // It stays where it landed.
        for x in after.iter().filter(|x| x.t >= landed.t) {
            assert!(x.position[0].hypot(x.position[1]) < 0.05 && x.position[2] < 0.06);
        }
        let end = &r.summary;
        assert!(
            end.final_position[2].abs() < 0.01,
            "{:?}",
            end.final_position
        );
        assert!(
            end.final_roll_pitch_yaw[0].abs() < 0.01 && end.final_roll_pitch_yaw[1].abs() < 0.01
        );
    }
}

#[test]
fn a6_inc_failure_is_classified_capable_and_land_does_not_trigger() {
    for precision in Precision::ALL {
        let r = run("a6-agent-failure", true, precision);
        let c = &r.summary.hover_classifications;
        assert!(c.len() == 1 && c[0].capable && !c[0].landing, "{c:?}");
        assert!((c[0].margin - 0.4).abs() < 1e-3, "{c:?}");
        // The scenario's own flight (hover until the descent at 12 s) is flown.
        let at_10 = r
            .samples
            .iter()
            .find(|x| (x.t - 10.0).abs() < 1e-9)
            .unwrap();
        assert!(
            (at_10.position[2] - 1.5).abs() < 0.02,
            "{:?}",
            at_10.position
        );
    }
}

#[test]
fn the_classification_is_logged_on_the_hover_channel() {
    let mut s = Scenario::builtin("agent-failure").unwrap();
    s.duration = 5.5;
    let path = std::env::temp_dir().join(format!("tvmd-hover-{}.mcap", std::process::id()));
    run_scenario(&s, Some(&path), None).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    let hover: Vec<tvmd_log::proto::Hover> = MessageStream::new(&bytes)
        .unwrap()
        .map(|m| m.unwrap())
        .filter(|m| m.channel.topic == "/hover")
        .map(|m| prost::Message::decode(&*m.data).unwrap())
        .collect();
    assert_eq!(hover.len(), 1, "{hover:?}");
    assert!(!hover[0].capable);
    assert!((hover[0].t - 5.0).abs() < 1e-9);
    assert!(hover[0].margin.abs() < 1e-6);
    assert_eq!(hover[0].limiting_agent.map(|a| a != 0), Some(true));
    let _ = std::fs::remove_file(&path);
}

#[test]
fn failure_response_is_parsed_and_validated() {
    let s = Scenario::from_toml_str(
        "[failure_response]\non_hover_loss = \"land\"\nlanding_acceleration = 0.8\n",
    )
    .unwrap();
    assert_eq!(s.failure_response.on_hover_loss, OnHoverLoss::Land);
    assert_eq!(s.failure_response.landing_acceleration, 0.8);
    assert_eq!(
        Scenario::default().failure_response.on_hover_loss,
        OnHoverLoss::Continue
    );
    let e = Scenario::from_toml_str("[failure_response]\non_hover_loss = \"panic\"\n").unwrap_err();
    assert!(e.to_string().contains("on_hover_loss"), "{e}");
    let e =
        Scenario::from_toml_str("[failure_response]\nlanding_acceleration = 0.0\n").unwrap_err();
    assert!(e.to_string().contains("landing_acceleration"), "{e}");
}

/// Issue 43 item 4: A3-Con cannot lose an agent (the rest cannot produce every wrench), so
/// the controller refuses the mask and keeps allocating to the failed agent. That used to
/// leave only a note inside the MCAP log; the summary now records it as a classification
/// that is not hover-capable and says why.
#[test]
fn a_refused_failure_mask_is_in_the_summary() {
    let overrides = tvmd_scenario::Overrides {
        team: Some("a3-con".into()),
        ..Default::default()
    };
    let mut s = Scenario::builtin("agent-failure")
        .unwrap()
        .with_overrides(&overrides)
        .unwrap();
    s.duration = 5.5;
    let r = run_scenario(&s, None, None).unwrap();
    let c = &r.summary.hover_classifications;
    assert_eq!(c.len(), 1, "{c:?}");
    assert!(!c[0].capable && (c[0].time - 5.0).abs() < 1e-9, "{c:?}");
    let why = c[0].refused.as_deref().unwrap_or_default();
    assert!(why.contains("refused"), "{c:?}");
}
