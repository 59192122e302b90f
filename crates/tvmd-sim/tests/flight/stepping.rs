//! The steppable entry (`Simulation::observe`, `step_output`, `step`, `step_wrench`,
//! `reset`): the tvmd controller flown through it reproduces `run_scenario`'s flight bit for
//! bit, user laws hold a hover through commands and through a body wrench, bad input is an
//! error that changes nothing.

use nalgebra::{Matrix3, Vector3};

use crate::common::PdHover;
use tvmd_plant::actuators::ActuatorCommand;
use tvmd_scenario::{Scenario, StateNoise, TeamSpec};
use tvmd_sim::flight::FlightController;
use tvmd_sim::sim::Simulation;
use tvmd_sim::{run_scenario, AnyTvmdController, SimError, GRAVITY};

/// A6-Inc losing an agent at 1.5 s, with state noise, one period of feedback latency and a
/// steady wind: every input the loop feeds the controller.
fn busy_scenario() -> Scenario {
    let mut s = Scenario::builtin("a6-agent-failure").unwrap();
    s.duration = 3.0;
    s.failures[0].time = 1.5;
    s.disturbances.state_noise = Some(StateNoise {
        position: 0.002,
        velocity: 0.01,
        attitude: 0.002,
        angular_velocity: 0.01,
        seed: 7,
    });
    s.disturbances.feedback_latency = 1;
    s.disturbances.wind = [0.3, -0.2, 0.0];
    s
}

/// Flies the tvmd controller of `s` through `observe` and `step_output`.
fn fly_stepped(s: &Scenario) -> tvmd_sim::RunResult {
    let mut sim = Simulation::new(s).unwrap();
    let mut controller = AnyTvmdController::from_scenario(s).unwrap();
    while !sim.is_finished() {
        let input = sim.observe().unwrap().clone();
        let out = controller.step(&input.input()).unwrap();
        let stepped = sim.step_output(out).unwrap();
        assert_eq!(stepped.t, sim.time());
    }
    sim.take_result()
}

#[test]
fn the_tvmd_controller_through_the_steps_reproduces_run_bit_for_bit() {
    let s = busy_scenario();
    let run = run_scenario(&s, None, None).unwrap();
    let stepped = fly_stepped(&s);
    assert_eq!(run.samples.len(), 300);
    assert!(run.samples.iter().any(|x| x.failed[0]), "the failure flew");
    // Every sample (state, reference, commands, actual outputs, diagnostics) equal, not close.
    assert_eq!(stepped.samples, run.samples);
    assert_eq!(stepped.summary.final_position, run.summary.final_position);
    assert_eq!(stepped.summary.final_velocity, run.summary.final_velocity);
    assert_eq!(stepped.paper, run.paper);
}

#[test]
fn commands_without_diagnostics_fly_the_same_trajectory() {
    // `step` (commands only) is `step_output` without diagnostics: the same flight.
    let s = busy_scenario();
    let run = run_scenario(&s, None, None).unwrap();
    let mut sim = Simulation::new(&s).unwrap();
    let mut controller = AnyTvmdController::from_scenario(&s).unwrap();
    while !sim.is_finished() {
        let input = sim.observe().unwrap().clone();
        let out = controller.step(&input.input()).unwrap();
        sim.step(&out.commands).unwrap();
    }
    let stepped = sim.take_result();
    for (a, b) in stepped.samples.iter().zip(&run.samples) {
        assert_eq!((a.t, a.position, a.velocity), (b.t, b.position, b.velocity));
        assert_eq!(a.commands, b.commands);
        assert_eq!(a.e_f, None);
    }
    assert_eq!(stepped.samples.len(), run.samples.len());
}

fn hover_sim() -> Simulation {
    Simulation::for_team(TeamSpec {
        preset: Some("a4-inc".into()),
        ..TeamSpec::default()
    })
    .unwrap()
}

fn vee(m: &Matrix3<f64>) -> Vector3<f64> {
    Vector3::new(m[(2, 1)], m[(0, 2)], m[(1, 0)])
}

#[test]
fn a_user_pd_law_holds_hover_through_the_wrench() {
    let mut sim = hover_sim();
    let mass = sim.team().mass();
    let mut worst: f64 = 0.0;
    for _ in 0..300 {
        let o = sim.observe().unwrap().clone();
        let (s, r) = (&o.state, &o.reference);
        // World force from a PD law on the position, rotated into the body frame; a PD
        // torque towards R_r.
        let f = mass
            * (GRAVITY * Vector3::z()
                - 4.0 * (s.position - r.position)
                - 4.0 * (s.velocity - r.velocity));
        let f_body = s.rotation.transpose() * f;
        let e_r =
            0.5 * vee(&(r.rotation.transpose() * s.rotation - s.rotation.transpose() * r.rotation));
        let tau = -2.0 * e_r - 0.5 * s.omega;
        let u = [tau.x, tau.y, tau.z, f_body.x, f_body.y, f_body.z];
        let stepped = sim.step_wrench(&u).unwrap();
        worst = worst.max((stepped.state.position - r.position).norm());
    }
    assert_eq!(sim.time(), 3.0);
    assert!(worst < 0.01, "hover error {worst} m");
    // The team hovers on thrust: the commands hold it up.
    let last = sim.samples().last().unwrap();
    let total: f64 = last.commands.iter().map(|c| c.thrust).sum();
    assert!(
        (total - mass * GRAVITY).abs() < 0.05 * mass * GRAVITY,
        "{total}"
    );
}

#[test]
fn a_user_pd_law_holds_hover_through_commands() {
    let mut sim = hover_sim();
    let mut pd = PdHover::new(sim.team());
    let mut worst: f64 = 0.0;
    while !sim.is_finished() {
        let o = sim.observe().unwrap().clone();
        let out = pd.step(&o.input()).unwrap();
        let stepped = sim.step(&out.commands).unwrap();
        worst = worst.max((stepped.state.position - o.reference.position).norm());
    }
    assert!(worst < 0.02, "hover error {worst} m");
    assert!(
        sim.step(&[ActuatorCommand::default(); 4]).is_err(),
        "past the end"
    );
    // The last state is still observed (no step follows it).
    let last = sim.observe().unwrap().clone();
    assert_eq!(last.t, 12.0);
    assert_eq!(last.truth, sim.state());
}

#[test]
fn bad_input_is_an_error_that_changes_nothing() {
    let mut sim = hover_sim();
    let ok = vec![ActuatorCommand::default(); 4];
    sim.step(&ok).unwrap();
    let (t, state) = (sim.time(), sim.state());
    let nan = ActuatorCommand {
        thrust: f64::NAN,
        ..ActuatorCommand::default()
    };
    for bad in [vec![ActuatorCommand::default(); 3], vec![nan; 4], vec![]] {
        let e = sim.step(&bad).unwrap_err();
        assert!(matches!(e, SimError::Physics(_)), "{e}");
    }
    let e = sim
        .step_wrench(&[0.0, 0.0, 0.0, 0.0, 0.0, f64::INFINITY])
        .unwrap_err();
    assert!(e.to_string().contains("non-finite wrench"), "{e}");
    assert_eq!((sim.time(), sim.state()), (t, state));
    assert_eq!(sim.samples().len(), 1);
    sim.step(&ok).unwrap();
    assert_eq!(sim.samples().len(), 2);
}

#[test]
fn reset_starts_over_and_reseeds_the_noise() {
    let mut s = busy_scenario();
    s.duration = 0.5;
    let fly = |sim: &mut Simulation| {
        let mut c = AnyTvmdController::from_scenario(&s).unwrap();
        let mut fed = Vec::new();
        while !sim.is_finished() {
            let o = sim.observe().unwrap().clone();
            fed.push(o.state.position);
            sim.step_output(c.step(&o.input()).unwrap()).unwrap();
        }
        fed
    };
    let mut sim = Simulation::new(&s).unwrap();
    let first = fly(&mut sim);
    sim.reset(None).unwrap();
    assert_eq!(sim.time(), 0.0);
    assert_eq!(fly(&mut sim), first, "the same seed, the same flight");
    sim.reset(Some(8)).unwrap();
    let other = fly(&mut sim);
    assert_ne!(other, first, "another seed, other noise");
    sim.reset(Some(8)).unwrap();
    assert_eq!(fly(&mut sim), other);
}

#[test]
fn reset_at_starts_from_another_pose_or_refuses_it() {
    let mut sim = hover_sim();
    sim.reset_at(None, Some([0.5, -0.25, 2.0]), Some([0.1, 0.0, 0.3]))
        .unwrap();
    let s = sim.state();
    assert_eq!(s.position, Vector3::new(0.5, -0.25, 2.0));
    let rpy = tvmd_plant::math::roll_pitch_yaw(&s.rotation);
    assert!(
        (rpy[0] - 0.1).abs() < 1e-12 && (rpy[2] - 0.3).abs() < 1e-12,
        "{rpy:?}"
    );
    sim.step(&[ActuatorCommand::default(); 4]).unwrap();
    // A NaN pose is refused and the simulation goes on where it was.
    let t = sim.time();
    assert!(sim
        .reset_at(None, Some([f64::NAN, 0.0, 1.0]), None)
        .is_err());
    assert_eq!(sim.time(), t);
    // Later resets start from the new pose.
    sim.reset(None).unwrap();
    assert_eq!(sim.state().position, Vector3::new(0.5, -0.25, 2.0));
}

#[test]
fn a_batch_steps_each_team_as_alone_and_keeps_errors_per_team() {
    use tvmd_sim::sim::{BatchAction, SimOptions, SimulationBatch};
    let scenario = Scenario::builtin("hover").unwrap();
    let batch = SimulationBatch::new(&scenario, 3, SimOptions::default(), Some(2)).unwrap();
    let mut alone = Simulation::new(&scenario).unwrap();
    let hover = |dz: f64| [0.0, 0.0, 0.0, 0.0, 0.0, alone_weight() + dz];
    let wrenches = [hover(1.0), hover(0.0), [f64::NAN; 6]];
    let mut last = Vec::new();
    for _ in 0..20 {
        last = batch.step(BatchAction::Wrench(&wrenches), None).unwrap();
        alone.step_wrench(&wrenches[0]).unwrap();
    }
    let first = last[0].as_ref().unwrap();
    // The same flight as the team flown alone, bit for bit.
    assert_eq!(first.observation.truth, alone.state());
    assert!(
        first.observation.truth.position.z > 1.5,
        "the extra newton lifts team 0"
    );
    assert!(last[2].is_err(), "team 2's NaN wrench is its own error");
    assert_eq!(batch.with(2, |s| s.time()).unwrap(), 0.0);
    assert_eq!(batch.with(1, |s| s.time()).unwrap(), 0.2);
    // Only the active teams step; a wrong count is the batch's error.
    let out = batch
        .step(BatchAction::Wrench(&wrenches), Some(&[false, true, false]))
        .unwrap();
    assert_eq!(out[0].as_ref().unwrap().observation.t, 0.2);
    assert_eq!(out[1].as_ref().unwrap().observation.t, 0.21);
    assert!(batch
        .step(BatchAction::Wrench(&wrenches[..2]), None)
        .is_err());
    let reset = batch.reset(0, None, Some([1.0, 0.0, 1.5]), None).unwrap();
    assert_eq!((reset.observation.t, reset.finished), (0.0, false));
    assert_eq!(reset.observation.truth.position.x, 1.0);
    assert!(SimulationBatch::new(&scenario, 0, SimOptions::default(), None).is_err());
}

/// The weight of the built-in hover's team (N).
fn alone_weight() -> f64 {
    hover_sim().team().mass() * GRAVITY
}

#[test]
fn the_wrench_allocation_idles_an_agent_from_its_failure_tick() {
    use tvmd_plant::actuators::FailureKind;
    use tvmd_scenario::Failure;
    let mut scenario = Scenario::builtin("hover").unwrap();
    scenario.team.preset = Some("a6-inc".into());
    scenario.failures = vec![Failure {
        agent: 2,
        time: 0.05,
        kind: FailureKind::NoThrust,
        controller_informed: true,
        informed_after: 0.0,
    }];
    let mut sim = Simulation::new(&scenario).unwrap();
    let weight = sim.team().mass() * GRAVITY;
    for _ in 0..10 {
        // No observe between the steps: the step itself applies the tick's failures first.
        sim.step_wrench(&[0.0, 0.0, 0.0, 0.0, 0.0, weight]).unwrap();
    }
    let samples = sim.samples();
    assert!(samples[4].commands[2].thrust > 0.0);
    assert_eq!(
        samples[5].commands[2].thrust, 0.0,
        "idle from the failure's tick on"
    );
    assert!(samples[5].failed[2]);
    let total: f64 = samples[9].commands.iter().map(|c| c.thrust).sum();
    // The five working agents hold the weight (their thrusts' vertical parts).
    assert!(
        total >= weight * (1.0 - 1e-9) && total < 1.1 * weight,
        "{total} against {weight}"
    );
}
