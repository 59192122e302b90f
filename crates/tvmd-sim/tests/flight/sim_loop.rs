//! The control loop with test-only controllers: hover, landing, ZOH timing, failures, noise.

use std::cell::RefCell;
use std::rc::Rc;

use crate::common::{zero_thrust, PdHover};
use tvmd_plant::actuators::{ActuatorCommand, FailureKind};
use tvmd_plant::reference::ReferenceConfig;
use tvmd_scenario::{Failure, Scenario, StateNoise};
use tvmd_sim::flight::{FlightInput, FlightOutput};
use tvmd_sim::sim::Simulation;
use tvmd_sim::SimError;

type BoxedError = Box<dyn std::error::Error + Send + Sync>;

fn hover_scenario(height: f64, duration: f64) -> Scenario {
    Scenario {
        name: "test-hover".into(),
        duration,
        initial_position: [0.0, 0.0, 0.0],
        reference: ReferenceConfig::Hover {
            position: [0.0, 0.0, height],
            roll: 0.0,
        },
        ..Scenario::default()
    }
}

fn speed(v: &[f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

#[test]
fn starts_at_rest_on_the_ground() {
    // Zero thrust from the paper's x_0 = [0.5, -0.5, 0]: the team stays where it is.
    let s = Scenario {
        duration: 1.0,
        ..Scenario::default()
    };
    let mut sim = Simulation::new(&s).unwrap();
    let n = sim.team().len();
    let r = sim.run(&mut zero_thrust(n), None).unwrap();
    let p = r.summary.final_position;
    eprintln!(
        "resting position after 1 s: {p:?}, velocity {:?}",
        r.summary.final_velocity
    );
    // Contact settling moves it by micrometres at most.
    assert!((p[0] - 0.5).abs() < 1e-4 && (p[1] + 0.5).abs() < 1e-4);
    assert!(p[2].abs() < 2e-3, "sinks by {} m", -p[2]);
    assert!(speed(&r.summary.final_velocity) < 1e-3);
}

#[test]
fn drop_from_half_a_metre_lands_at_rest() {
    let mut s = hover_scenario(0.0, 3.0);
    s.initial_position = [0.0, 0.0, 0.5];
    let mut sim = Simulation::new(&s).unwrap();
    let n = sim.team().len();
    let r = sim.run(&mut zero_thrust(n), None).unwrap();
    let sum = &r.summary;
    eprintln!(
        "landing: final position {:?}, velocity {:?}, omega {:?}",
        sum.final_position, sum.final_velocity, sum.final_omega
    );
    assert!(
        speed(&sum.final_velocity) < 1e-3,
        "still moving: {:?}",
        sum.final_velocity
    );
    assert!(speed(&sum.final_omega) < 1e-3);
    assert!(
        sum.final_position[2].abs() < 2e-3,
        "rest height {}",
        sum.final_position[2]
    );
    assert!(sum.final_roll_pitch_yaw[0].abs() < 1e-3 && sum.final_roll_pitch_yaw[1].abs() < 1e-3);
}

#[test]
fn pd_hover_takes_off_and_holds_the_setpoint() {
    let s = hover_scenario(1.0, 8.0);
    let mut sim = Simulation::new(&s).unwrap();
    let mut ctl = PdHover::new(sim.team());
    let r = sim.run(&mut ctl, None).unwrap();
    let p = r.summary.final_position;
    eprintln!(
        "hover: final position {p:?}, final error {:.2e} m",
        r.summary.final_position_error
    );
    assert!((p[2] - 1.0).abs() < 5e-3, "height {}", p[2]);
    assert!(p[0].abs() < 1e-3 && p[1].abs() < 1e-3);
    assert!(r.summary.max_tilt < 1e-3);
    // V_x is logged by the test controller and decreases.
    let v_end = r.samples.last().unwrap().v_x.unwrap();
    assert!(v_end < 1e-3 * r.samples[0].v_x.unwrap());
}

#[test]
fn thrust_cut_after_takeoff_lands_at_rest() {
    let s = hover_scenario(1.0, 7.0);
    let mut sim = Simulation::new(&s).unwrap();
    let mut ctl = PdHover::new(sim.team());
    ctl.cut_at = Some(4.0);
    let r = sim.run(&mut ctl, None).unwrap();
    let before = r.samples.iter().find(|x| x.t >= 3.99).unwrap();
    assert!(
        (before.position[2] - 1.0).abs() < 0.02,
        "was not flying: {:?}",
        before.position
    );
    let sum = &r.summary;
    eprintln!(
        "after thrust cut: final position {:?}, velocity {:?}",
        sum.final_position, sum.final_velocity
    );
    assert!(speed(&sum.final_velocity) < 1e-3);
    assert!(sum.final_position[2].abs() < 2e-3);
}

#[test]
fn controller_runs_at_its_period_with_zero_order_hold() {
    let mut s = hover_scenario(0.0, 0.1);
    s.controller_period = 0.02;
    s.physics.dt = 0.002;
    let times = Rc::new(RefCell::new(Vec::new()));
    let seen = times.clone();
    let mut ctl = move |input: &FlightInput<'_>| -> Result<FlightOutput, BoxedError> {
        let t = input.t;
        seen.borrow_mut().push(t);
        Ok(FlightOutput {
            commands: vec![
                ActuatorCommand {
                    thrust: t,
                    ..Default::default()
                };
                4
            ],
            ..Default::default()
        })
    };
    let mut sim = Simulation::new(&s).unwrap();
    let r = sim.run(&mut ctl, None).unwrap();
    let times = times.borrow();
    assert_eq!(times.len(), 5);
    for (k, t) in times.iter().enumerate() {
        assert!((t - 0.02 * k as f64).abs() < 1e-12);
    }
    assert_eq!(r.summary.physics_steps, 50);
    // At each tick the actuators still hold the previous command (ideal actuators).
    for w in r.samples.windows(2) {
        assert_eq!(w[1].actual[0].thrust, w[0].commands[0].thrust);
    }
}

fn failure_flags_seen(informed: bool, informed_after: f64) -> Vec<(f64, bool, f64)> {
    let mut s = hover_scenario(0.0, 0.2);
    s.failures = vec![Failure {
        agent: 2,
        time: 0.1,
        kind: FailureKind::NoThrust,
        controller_informed: informed,
        informed_after,
    }];
    let mut sim = Simulation::new(&s).unwrap();
    let log = Rc::new(RefCell::new(Vec::new()));
    let l2 = log.clone();
    let mut ctl = move |input: &FlightInput<'_>| -> Result<FlightOutput, BoxedError> {
        l2.borrow_mut().push((input.t, input.failed[2]));
        Ok(FlightOutput {
            commands: vec![
                ActuatorCommand {
                    thrust: 1.0,
                    ..Default::default()
                };
                4
            ],
            ..Default::default()
        })
    };
    let r = sim.run(&mut ctl, None).unwrap();
    let seen = log.borrow().clone();
    seen.iter()
        .zip(&r.samples)
        .map(|((t, f), smp)| {
            assert!(smp.failed[2] == (*t >= 0.1 - 1e-12));
            (*t, *f, smp.actual[2].thrust)
        })
        .collect()
}

#[test]
fn failures_are_reported_only_when_the_controller_is_informed() {
    for (t, f, thrust) in failure_flags_seen(true, 0.0) {
        assert_eq!(f, t >= 0.1 - 1e-12, "t = {t}");
        if t > 0.1 + 1e-9 {
            assert_eq!(thrust, 0.0);
        }
    }
    for (t, f, thrust) in failure_flags_seen(false, 0.0) {
        assert!(!f);
        if t > 0.1 + 1e-9 {
            assert_eq!(thrust, 0.0);
        }
    }
    // Told late: the agent fails at 0.1 s, the controller learns it at 0.16 s (the first tick
    // from then on).
    let late = failure_flags_seen(true, 0.06);
    assert!(late.iter().any(|(t, f, _)| *t > 0.1 + 1e-9 && !f));
    for (t, f, thrust) in late {
        assert_eq!(f, t >= 0.16 - 1e-12, "t = {t}");
        if t > 0.1 + 1e-9 {
            assert_eq!(thrust, 0.0);
        }
    }
    // A delay for a controller never told would be ignored: refused (issue 57, item 10).
    let mut s = hover_scenario(0.0, 0.2);
    s.failures = vec![Failure {
        agent: 2,
        time: 0.1,
        kind: FailureKind::NoThrust,
        controller_informed: false,
        informed_after: 0.06,
    }];
    let e = Simulation::new(&s).err().expect("refused").to_string();
    assert!(e.contains("failures[0].informed_after"), "{e}");
}

fn fed_positions(seed: u64) -> Vec<[f64; 3]> {
    let mut s = hover_scenario(0.0, 0.05);
    s.disturbances.state_noise = Some(StateNoise {
        position: 0.01,
        attitude: 0.01,
        seed,
        ..Default::default()
    });
    let mut sim = Simulation::new(&s).unwrap();
    let out = Rc::new(RefCell::new(Vec::new()));
    let o2 = out.clone();
    let mut ctl = move |input: &FlightInput<'_>| -> Result<FlightOutput, BoxedError> {
        let st = input.state;
        o2.borrow_mut()
            .push([st.position.x, st.position.y, st.position.z]);
        // The noisy attitude is still a rotation.
        assert!(
            (st.rotation.transpose() * st.rotation - nalgebra::Matrix3::identity()).norm() < 1e-12
        );
        Ok(FlightOutput {
            commands: vec![ActuatorCommand::default(); 4],
            ..Default::default()
        })
    };
    sim.run(&mut ctl, None).unwrap();
    let v = out.borrow().clone();
    v
}

#[test]
fn state_noise_is_seeded() {
    let (a, b, c) = (fed_positions(3), fed_positions(3), fed_positions(4));
    assert_eq!(a, b);
    assert_ne!(a, c);
    assert!(a.iter().any(|p| p[0].abs() > 1e-4));
}

#[test]
fn wind_pushes_the_team() {
    let mut s = hover_scenario(1.0, 3.0);
    s.disturbances.wind = [1.0, 0.0, 0.0];
    let mut sim = Simulation::new(&s).unwrap();
    let mut ctl = PdHover::new(sim.team());
    let r = sim.run(&mut ctl, None).unwrap();
    assert!(
        r.summary.final_position[0] > 0.3,
        "{:?}",
        r.summary.final_position
    );
}

#[test]
fn controller_errors_and_bad_outputs_stop_the_run() {
    let s = hover_scenario(0.0, 1.0);
    let mut sim = Simulation::new(&s).unwrap();
    let mut bad = |input: &FlightInput<'_>| -> Result<FlightOutput, BoxedError> {
        let t = input.t;
        if t > 0.5 {
            Err("boom".into())
        } else {
            Ok(FlightOutput {
                commands: vec![ActuatorCommand::default(); 4],
                ..Default::default()
            })
        }
    };
    let e = sim.run(&mut bad, None).unwrap_err();
    assert!(matches!(e, SimError::Controller { .. }), "{e}");
    assert!(e.to_string().contains("boom"));
    assert_eq!(sim.samples().len(), 51);

    let mut sim = Simulation::new(&s).unwrap();
    let mut short = |_: &FlightInput<'_>| -> Result<FlightOutput, BoxedError> {
        Ok(FlightOutput {
            commands: vec![ActuatorCommand::default(); 3],
            ..Default::default()
        })
    };
    assert!(matches!(
        sim.run(&mut short, None),
        Err(SimError::Physics(
            tvmd_plant::PhysicsError::InvalidCommand { .. }
        ))
    ));

    let mut sim = Simulation::new(&s).unwrap();
    let mut nan = |_: &FlightInput<'_>| -> Result<FlightOutput, BoxedError> {
        Ok(FlightOutput {
            commands: vec![
                ActuatorCommand {
                    thrust: f64::NAN,
                    ..Default::default()
                };
                4
            ],
            ..Default::default()
        })
    };
    assert!(matches!(
        sim.run(&mut nan, None),
        Err(SimError::Physics(
            tvmd_plant::PhysicsError::InvalidCommand { .. }
        ))
    ));
}
