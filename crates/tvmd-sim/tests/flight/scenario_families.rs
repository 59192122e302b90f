//! The scenario families (wind, payload, model error, reference jump, tracking, initial
//! attitudes) against the physics they model: each steady state where the paper's law (no
//! integral action, `law = "paper"`) puts it, and every family flown to its end by more than
//! one team with its own (default) law. The default law's steady states: `offset_free.rs`.

use tvmd_plant::turbulence::{Turbulence, LIGHT_W20, MODERATE_W20};
use tvmd_scenario::{Air, LawConfig, Payload, Scenario, FAMILY_NAMES, HOVER_HEIGHT};
use tvmd_sim::runner::run_scenario;
use tvmd_sim::sim::RunResult;
use tvmd_sim::GRAVITY;

fn fly(s: &Scenario) -> RunResult {
    s.validate().unwrap();
    let r = run_scenario(s, None, None).unwrap();
    assert!(r.summary.error.is_none() && !r.summary.interrupted);
    r
}

/// The final position error, split into horizontal and vertical parts (m).
fn final_error(r: &RunResult) -> (f64, f64) {
    let x = r.samples.last().unwrap();
    let d: Vec<f64> = (0..3)
        .map(|k| x.position[k] - x.reference_position[k])
        .collect();
    (d[0].hypot(d[1]), d[2])
}

#[test]
fn every_family_flies_to_its_end_with_two_teams() {
    for name in FAMILY_NAMES {
        for team in ["a4-inc", "a6-inc"] {
            let mut s = Scenario::builtin(name).unwrap();
            // The first seconds: each family's disturbance or task has begun by then.
            s.duration = s.duration.min(5.0);
            if team != "a4-inc" {
                if !s.plant.thrust_efficiency.is_empty() {
                    continue; // per-agent errors are given for A4's four agents
                }
                s.team.preset = Some(team.into());
            }
            let r = fly(&s);
            let m = &r.summary.metrics;
            eprintln!("{name} / {team}: {:?}", r.summary.verdict);
            assert!(
                m.position.is_some() && m.thrust_efficiency.is_some(),
                "{name}"
            );
            assert!((r.summary.time - s.duration).abs() < 1e-9, "{name}");
        }
    }
}

/// Mass +2% unknown to the controller: the vertical loop settles where `K_x,z e = dm g`.
#[test]
fn an_unmodelled_mass_sags_by_dm_g_over_k_z() {
    let mut s = Scenario::builtin("hover").unwrap();
    s.law = LawConfig::paper();
    s.duration = 40.0;
    s.plant.mass_scale = 1.02;
    let r = fly(&s);
    let (h, v) = final_error(&r);
    let expected = 0.02 * 2.8 * GRAVITY / s.gains.k_x[2];
    assert!(
        h < 1e-6 && (v + expected).abs() < 0.01 * expected,
        "{h} {v} vs -{expected}"
    );
    assert!(!r.summary.verdict.success);
}

/// A steady 1 m/s wind: drag `(rho / 2) C_d A w^2` against `K_x,x e`.
#[test]
fn a_steady_wind_pushes_the_team_downwind_by_drag_over_k_x() {
    let mut s = Scenario::builtin("hover").unwrap();
    s.law = LawConfig::paper();
    s.duration = 40.0;
    s.disturbances.air = Some(Air {
        velocity: [1.0, 0.0, 0.0],
        ..Air::default()
    });
    let r = fly(&s);
    let x = r.samples.last().unwrap();
    let drag = 0.5 * 1.225 * 0.2 * 1.0;
    let expected = drag / s.gains.k_x[0];
    let dx = x.position[0] - x.reference_position[0];
    assert!(
        (dx - expected).abs() < 0.01 * expected,
        "{dx} vs {expected}"
    );
    assert!((x.position[2] - HOVER_HEIGHT).abs() < 1e-3);
}

/// A payload attached off the centre: it sags by `dm g / K_x,z` and tilts the team until
/// `K_R e_R` holds its moment `dm g d`.
#[test]
fn a_payload_off_the_centre_sags_and_tilts() {
    let mut s = Scenario::builtin("hover").unwrap();
    s.law = LawConfig::paper();
    s.duration = 40.0;
    s.payloads = vec![Payload {
        mass: 0.1,
        offset: [0.1, 0.0, 0.0],
        time: 2.0,
    }];
    let r = fly(&s);
    let before = r.samples.iter().find(|x| x.t >= 1.99).unwrap();
    assert!(before.position_error() < 1e-9);
    let (_, v) = final_error(&r);
    let sag = 0.1 * GRAVITY / s.gains.k_x[2];
    assert!((v + sag).abs() < 0.02 * sag, "{v} vs -{sag}");
    let tilt = r.samples.last().unwrap().attitude_error.unwrap();
    // e_R = sin(angle) for one axis; the moment arm shrinks with the tilt only to second order.
    let expected = (0.1 * GRAVITY * 0.1 / s.gains.k_r[1]).asin();
    assert!(
        (tilt - expected).abs() < 0.05 * expected,
        "{tilt} vs {expected}"
    );
}

#[test]
fn the_model_error_family_misses_its_bounds_with_the_paper_law_and_says_so() {
    let r = fly(&Scenario {
        law: LawConfig::paper(),
        ..Scenario::builtin("model-error").unwrap()
    });
    let v = &r.summary.verdict;
    assert!(
        !v.success && v.failures.iter().any(|f| f.contains("position")),
        "{v:?}"
    );
    // The gimbal offsets and the weak agent tilt the team: the attitude error is not zero.
    let a = r.summary.metrics.planned_attitude.unwrap();
    assert!(a.steady_state.unwrap() > 1e-3, "{a:?}");
}

#[test]
fn tracking_and_the_jump_meet_their_bounds() {
    for name in [
        "sine",
        "figure-eight",
        "reference-jump",
        "initial-attitude-0.5",
    ] {
        let r = fly(&Scenario::builtin(name).unwrap());
        assert!(r.summary.verdict.success, "{name}: {:?}", r.summary.verdict);
    }
    let jump = fly(&Scenario::builtin("reference-jump").unwrap());
    let p = jump.summary.metrics.position.unwrap();
    assert!(
        (p.peak - 0.5).abs() < 1e-9 && (p.peak_time - 2.0).abs() < 1e-9,
        "{p:?}"
    );
    assert!(p.settling_time.unwrap() > 2.0 && p.settling_time.unwrap() < 40.0);
}

#[test]
fn a_far_initial_attitude_is_recovered_in_the_air() {
    let r = fly(&Scenario::builtin("initial-attitude-2.5").unwrap());
    let m = &r.summary.metrics;
    let first = &r.samples[0];
    assert!((first.roll_pitch_yaw[0] - 2.5).abs() < 1e-9);
    // Level again within a few seconds, having fallen a long way but never to the ground.
    let att = m.planned_attitude.unwrap();
    assert!(att.settling_time.unwrap() < 5.0, "{att:?}");
    let p = m.position.unwrap();
    assert!(p.peak > 5.0 && p.peak < 25.0, "{p:?}");
    // Released tilted on the ground, an agent would start inside it.
    let mut low = Scenario::builtin("initial-attitude-2.5").unwrap();
    low.initial_position = [0.0, 0.0, 0.0];
    let e = low.validate().unwrap_err().to_string();
    assert!(e.contains("initial_attitude"), "{e}");
}

/// Issue 61: the standard's turbulence on its mean wind moves the team about its hover, more
/// than the steady wind alone and more at the moderate level than at the light; the default law
/// holds the light level within 0.1 m RMS once the mean wind, which blows from t = 0, has been
/// taken up (from 5 s on). The moderate level's numbers are measured in docs/monte-carlo.md.
#[test]
fn turbulence_is_felt_by_its_level_and_light_turbulence_is_held_within_a_decimetre() {
    let moderate = Scenario::builtin("turbulence").unwrap();
    let at = |w20: Option<f64>| {
        let mut s = moderate.clone();
        s.duration = 20.0;
        let air = s.disturbances.air.as_mut().unwrap();
        match w20 {
            Some(w20) => {
                let t = Turbulence::standard(w20, HOVER_HEIGHT);
                air.velocity = [t.mean_wind_speed(), 0.0, 0.0];
                air.turbulence = Some(t);
            }
            None => air.turbulence = None,
        }
        let r = fly(&s);
        let held: Vec<f64> = r
            .samples
            .iter()
            .filter(|x| x.t >= 5.0)
            .map(|x| {
                (0..3)
                    .map(|k| (x.position[k] - x.reference_position[k]).powi(2))
                    .sum::<f64>()
            })
            .collect();
        (held.iter().sum::<f64>() / held.len() as f64).sqrt()
    };
    let light = at(Some(LIGHT_W20));
    let heavier = at(Some(MODERATE_W20));
    let steady = at(None);
    eprintln!("RMS from 5 s: light {light} m, moderate {heavier} m, steady wind {steady} m");
    assert!(light < 0.1 && light > 2.0 * steady, "{light} {steady}");
    assert!(heavier > 1.5 * light, "{heavier} {light}");
}
