//! rapier's motion of the team body against an independent RK4 integration of the paper's
//! dynamics (eqs. 2-3) under a scripted open-loop program of agent forces, in the air.

use nalgebra::Vector3;
use tvmd_plant::math::rotation_distance;
use tvmd_plant::physics::{ExtraWrench, PhysicsConfig, PhysicsWorld, PlantState, TeamBody};
use tvmd_plant::rk4::{BodyWrench, RigidBodyParams, Rk4Body};
use tvmd_plant::GRAVITY;

/// Body-frame force of agent `i` at time `t`: thrust a little above its weight share plus
/// sinusoidal lateral components, different for every agent so that torques arise.
fn agent_force(team: &TeamBody, i: usize, t: f64) -> Vector3<f64> {
    let m = team.agents[i].mass;
    let k = i as f64;
    Vector3::new(
        0.15 * (2.0 * t + k).sin(),
        -0.1 * (3.0 * t + 0.5 * k).cos(),
        m * GRAVITY * (1.03 + 0.01 * (1.7 * t + k).sin()),
    )
}

fn program(team: &TeamBody, t: f64) -> BodyWrench {
    let mut w = BodyWrench::default();
    for (i, a) in team.agents.iter().enumerate() {
        let f = agent_force(team, i, t);
        w.force += f;
        w.torque += a.position_vector().cross(&f);
    }
    w
}

struct Errors {
    position: f64,
    velocity: f64,
    attitude: f64,
    omega: f64,
}

fn compare(team: &TeamBody, dt: f64, solver_iterations: usize) -> (Errors, PlantState) {
    let mut initial = PlantState::at_rest(Vector3::new(0.0, 0.0, 10.0));
    initial.velocity = Vector3::new(0.2, -0.1, 0.3);
    initial.omega = Vector3::new(0.1, -0.05, 0.2);
    let config = PhysicsConfig {
        dt,
        ground: false,
        solver_iterations,
        ..PhysicsConfig::default()
    };
    let mut world = PhysicsWorld::new(team, &config, &initial).unwrap();
    let params = RigidBodyParams {
        mass: team.mass(),
        inertia: team.inertia(),
        gravity: GRAVITY,
    };
    let mut truth = Rk4Body::new(params, &initial).unwrap();
    let rk_dt = 1e-4;
    let duration = 2.0;
    let steps = (duration / dt).round() as usize;
    let sub = (dt / rk_dt).round() as usize;
    let mut e = Errors {
        position: 0.0,
        velocity: 0.0,
        attitude: 0.0,
        omega: 0.0,
    };
    for k in 0..steps {
        let t = k as f64 * dt;
        // rapier: the program sampled at mid-step and held over the step (the midpoint rule
        // for the input; the simulator itself holds controller commands, a true ZOH).
        let forces: Vec<_> = (0..team.len())
            .map(|i| agent_force(team, i, t + 0.5 * dt))
            .collect();
        world.step(&forces, &ExtraWrench::default()).unwrap();
        // RK4: the continuous program.
        for _ in 0..sub {
            truth.step(rk_dt, |tt, _| program(team, tt));
        }
        let (a, b) = (world.state(), truth.state());
        e.position = e.position.max((a.position - b.position).norm());
        e.velocity = e.velocity.max((a.velocity - b.velocity).norm());
        e.attitude = e.attitude.max(rotation_distance(&a.rotation, &b.rotation));
        e.omega = e.omega.max((a.omega - b.omega).norm());
    }
    (e, truth.state())
}

#[test]
fn rapier_matches_rk4_over_two_seconds() {
    let team = TeamBody::a4_inc();
    let (e, end) = compare(&team, 1e-3, 4);
    eprintln!(
        "dt = 1 ms: max |dx| = {:.3e} m, |dv| = {:.3e} m/s, attitude {:.3e} rad, |dOmega| = {:.3e} rad/s",
        e.position, e.velocity, e.attitude, e.omega
    );
    // The motion is not trivial: it climbs, drifts and turns.
    assert!((end.position - Vector3::new(0.0, 0.0, 10.0)).norm() > 0.5);
    assert!(rotation_distance(&end.rotation, &nalgebra::Matrix3::identity()) > 0.3);
    // Tolerances. rapier integrates semi-implicitly (symplectic Euler over 4 substeps of each
    // 1 ms step), an O(dt) scheme: its position error grows like dt/8 times the velocity
    // change. Measured (rapier 0.36.1): |dx| 6.3e-4 m, |dv| 3.7e-4 m/s, attitude 4.6e-5 rad,
    // |dOmega| 2.7e-5 rad/s, while the body reaches 3.6 m/s and turns by more than 0.3 rad.
    assert!(e.position < 1e-3, "position error {:.3e} m", e.position);
    assert!(e.velocity < 1e-3, "velocity error {:.3e} m/s", e.velocity);
    assert!(e.attitude < 2e-4, "attitude error {:.3e} rad", e.attitude);
    assert!(
        e.omega < 1e-4,
        "angular velocity error {:.3e} rad/s",
        e.omega
    );
}

#[test]
fn rapier_error_shrinks_with_the_step() {
    let team = TeamBody::a4_inc();
    let (coarse, _) = compare(&team, 2e-3, 4);
    let (fine, _) = compare(&team, 5e-4, 4);
    eprintln!(
        "position error: dt = 2 ms {:.3e} m, dt = 0.5 ms {:.3e} m",
        coarse.position, fine.position
    );
    assert!(fine.position < 0.5 * coarse.position);
}
