//! Changing a running controller: a refused reconfiguration leaves it stepping exactly as
//! before; an accepted one keeps the failure mask, the landed flag, the held commands and the
//! offset-free estimate; the cheap setters and the command seed check their inputs.

mod flight;

use flight::{rk4, Body, Truth};
use tvmd_core::nalgebra::{Matrix3, Vector3};
use tvmd_core::rotation::roll;
use tvmd_core::team::presets;
use tvmd_core::{
    AgentCommand, Controller, ControllerSettings, ExactBoundaryRedistribution, FailureMask, Gains,
    InputError, RateLimits, Reference, Relaxation,
};

type C = Controller<f64, 6, ExactBoundaryRedistribution<f64, 6>>;

fn flown(settings: ControllerSettings<f64>) -> (C, Body) {
    let team = presets::a6_inc::<f64, 6>().unwrap();
    let mut c = Controller::new(team, settings, ExactBoundaryRedistribution::new()).unwrap();
    let truth = Truth {
        mass: team.mass(),
        inertia: team.inertia(),
        gravity: 9.81,
        force: Vector3::new(0.5, 0.0, -1.0),
        torque: Vector3::zeros(),
    };
    let mut body = Body::at(Vector3::new(0.1, 0.0, 1.5));
    let reference = Reference::hover(Vector3::new(0.0, 0.0, 1.5));
    for _ in 0..200 {
        let out = c.step(&body.state(), &reference).unwrap();
        for _ in 0..10 {
            body = rk4(&body, &truth, &out.allocation.wrench, 0.001);
        }
    }
    (c, body)
}

#[test]
fn a_refused_reconfiguration_changes_nothing() {
    let (mut c, body) = flown(ControllerSettings::offset_free_law());
    let before = c.clone();
    let team = *c.team();
    // A period of zero is refused by `Controller::new`, after nothing was touched.
    let bad = ControllerSettings {
        period: 0.0,
        ..ControllerSettings::offset_free_law()
    };
    assert!(c
        .reconfigure(&team, &bad, ExactBoundaryRedistribution::new)
        .is_err());
    let mut twin = before;
    let mut reference = Reference::hover(Vector3::new(0.0, 0.0, 1.5));
    reference.attitude = roll(0.8);
    for _ in 0..20 {
        let a = c.step(&body.state(), &reference).unwrap();
        let b = twin.step(&body.state(), &reference).unwrap();
        assert_eq!(a, b);
    }
}

#[test]
fn an_accepted_reconfiguration_keeps_the_flight_state() {
    let (mut c, _) = flown(ControllerSettings::offset_free_law());
    c.set_failures(FailureMask::with_failed(&[5]).unwrap())
        .unwrap();
    let held = *c.previous_commands();
    let compensation = c.offset_free_compensation();
    assert!(compensation.force.norm() > 0.3, "{compensation:?}");
    let team = *c.team();
    let settings = ControllerSettings {
        relaxation: Relaxation::new(0.8).unwrap(),
        ..ControllerSettings::offset_free_law()
    };
    c.reconfigure(&team, &settings, ExactBoundaryRedistribution::new)
        .unwrap();
    assert_eq!(c.failures(), &FailureMask::with_failed(&[5]).unwrap());
    assert_eq!(c.settings().relaxation, Relaxation::new(0.8).unwrap());
    assert_eq!(c.offset_free_compensation(), compensation);
    // The working agents' held commands are admissible for the (same) team: kept; the failed
    // agent's is idle.
    assert_eq!(c.previous_commands()[..5], held[..5]);
    assert_eq!(c.previous_commands()[5], AgentCommand::idle());
}

#[test]
fn setters_and_the_seed_check_their_inputs() {
    let team = presets::a4_inc::<f64, 4>().unwrap();
    let mut c = Controller::new(
        team,
        ControllerSettings::paper(),
        ExactBoundaryRedistribution::new(),
    )
    .unwrap();
    let stiffer = Gains::diagonal([2.0; 3], [3.0; 3], [1.0; 6]).unwrap();
    c.set_gains(stiffer).unwrap();
    assert_eq!(c.gains(), &stiffer);
    c.set_relaxation(Relaxation::new(1.0).unwrap());
    assert_eq!(c.settings().relaxation, Relaxation::new(1.0).unwrap());
    c.set_rate_limits(Some(RateLimits::new(1.0, 1.0).unwrap()));
    assert!(c.settings().rate_limits.is_some());

    let hover = AgentCommand {
        eta_x: 0.0,
        eta_y: 0.0,
        thrust: 6.9,
        omega: 0.7,
    };
    c.seed_commands(&[hover; 4]).unwrap();
    assert_eq!(c.previous_commands(), &[hover; 4]);
    let tilted = AgentCommand {
        eta_x: 1.2,
        ..hover
    };
    assert!(matches!(
        c.seed_commands(&[tilted, hover, hover, hover]),
        Err(InputError::OutOfRange { .. })
    ));
    let nan = AgentCommand {
        thrust: f64::NAN,
        ..hover
    };
    assert!(matches!(
        c.seed_commands(&[hover, nan, hover, hover]),
        Err(InputError::NonFinite { .. })
    ));
    assert_eq!(
        c.previous_commands(),
        &[hover; 4],
        "unchanged after a refusal"
    );
    // A seeded command is what a refused period holds.
    let mut bad = tvmd_core::RigidState::at_rest(Vector3::new(0.0, 0.0, 1.0));
    bad.attitude = Matrix3::identity() * 2.0;
    let held = c
        .step(&bad, &Reference::hover(Vector3::zeros()))
        .unwrap_err();
    assert_eq!(held.commands, [hover; 4]);
}

/// Steps two controllers on the same body and reference and asserts every output is equal.
fn step_alike(a: &mut C, b: &mut C, body: &Body) {
    let mut reference = Reference::hover(Vector3::new(0.0, 0.0, 1.5));
    reference.attitude = roll(0.8);
    for _ in 0..20 {
        assert_eq!(
            a.step(&body.state(), &reference).unwrap(),
            b.step(&body.state(), &reference).unwrap()
        );
    }
}

#[test]
fn built_in_place_equals_built_anew() {
    let team = presets::a6_inc::<f64, 6>().unwrap();
    let settings = ControllerSettings::offset_free_law();
    let mut fresh = Controller::new(team, settings, ExactBoundaryRedistribution::new()).unwrap();
    let mut slot = core::mem::MaybeUninit::uninit();
    let in_place = Controller::init_in(
        &mut slot,
        &team,
        &settings,
        ExactBoundaryRedistribution::new,
    )
    .unwrap();
    let body = Body::at(Vector3::new(0.1, 0.0, 1.5));
    step_alike(&mut fresh, in_place, &body);
    // A never-flown controller reconfigured (same mask, no state to carry) flies as one built
    // anew with the new settings.
    let paper = ControllerSettings::paper();
    let mut reconfigured = fresh.clone();
    reconfigured
        .reconfigure(&team, &paper, ExactBoundaryRedistribution::new)
        .unwrap();
    let mut anew = Controller::new(team, paper, ExactBoundaryRedistribution::new()).unwrap();
    reconfigured.reset();
    anew.reset();
    step_alike(&mut reconfigured, &mut anew, &body);
}
