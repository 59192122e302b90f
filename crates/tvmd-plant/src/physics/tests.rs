//! Tests of the team body and the physics world.

use nalgebra::{Matrix3, Vector3};

use super::*;
use crate::PhysicsError;

fn rel_err(a: &Matrix3<f64>, b: &Matrix3<f64>) -> f64 {
    (a - b).abs().max() / b.abs().max()
}

#[test]
fn rapier_mass_and_inertia_match_the_model() {
    let mut teams = vec![TeamBody::a4_inc(), TeamBody::a4_con()];
    // An irregular, non-planar team with a heavy navigator whose CoM is at the origin.
    let mut t = TeamBody {
        agents: vec![
            AgentBody {
                position: [0.4, 0.1, 0.05],
                mass: 0.7,
                quarter_turns: 1,
            },
            AgentBody {
                position: [-0.2, 0.3, -0.05],
                mass: 0.7,
                quarter_turns: 2,
            },
            AgentBody {
                position: [-0.2, -0.4, 0.0],
                mass: 0.7,
                quarter_turns: 3,
            },
        ],
        navigator_mass: 0.3,
        navigator_inertia: [[0.01, 0.001, 0.0], [0.001, 0.02, 0.0], [0.0, 0.0, 0.03]],
        collider_radius: 0.04,
    };
    t.validate().unwrap();
    teams.push(t.clone());
    t.navigator_mass = 0.0;
    t.navigator_inertia = [[0.0; 3]; 3];
    teams.push(t);
    for team in teams {
        let w = PhysicsWorld::new(
            &team,
            &PhysicsConfig::default(),
            &PlantState::at_rest(Vector3::new(0.0, 0.0, 1.0)),
        )
        .unwrap();
        let dm = (w.mass() - team.mass()).abs() / team.mass();
        let dj = rel_err(&w.inertia(), &team.inertia());
        eprintln!("mass rel err {dm:.1e}, inertia rel err {dj:.1e}");
        assert!(dm < 1e-12, "mass {} vs {}", w.mass(), team.mass());
        assert!(
            dj < 1e-9,
            "inertia rel err {dj:e}:\n{}\n{}",
            w.inertia(),
            team.inertia()
        );
        assert!(w.local_center_of_mass().norm() < 1e-12);
    }
}

/// A model error and a payload move the centre of mass off the body origin: the mass
/// properties follow, and the reported velocity stays the origin's (the finite difference
/// of the reported position).
#[test]
fn mass_errors_and_payloads_keep_the_origin_state() {
    let team = TeamBody::a4_inc();
    let config = PhysicsConfig {
        gravity: 0.0,
        ground: false,
        ..PhysicsConfig::default()
    };
    let error = MassError {
        mass_scale: 1.1,
        inertia_scale: 1.5,
        com_offset: Vector3::new(0.05, -0.02, 0.01),
    };
    let initial = PlantState {
        omega: Vector3::new(0.3, -0.2, 0.5),
        velocity: Vector3::new(0.1, 0.0, 0.0),
        ..PlantState::at_rest(Vector3::new(0.0, 0.0, 1.0))
    };
    let mut w = PhysicsWorld::with_mass_error(&team, &config, &initial, &error).unwrap();
    assert!((w.mass() - 1.1 * team.mass()).abs() < 1e-12);
    assert!((w.local_center_of_mass() - error.com_offset).norm() < 1e-12);
    let j = w.inertia();
    assert!((j - team.inertia() * 1.5).abs().max() < 1e-12, "{j}");
    let s0 = w.state();
    assert!((s0.velocity - initial.velocity).norm() < 1e-12);
    assert!((s0.omega - initial.omega).norm() < 1e-12);
    w.attach_payload(0.3, &Vector3::new(0.2, 0.0, 0.0)).unwrap();
    assert!((w.mass() - (1.1 * team.mass() + 0.3)).abs() < 1e-12);
    let s1 = w.state();
    assert!((s1.velocity - s0.velocity).norm() < 1e-12);
    let com_velocity = |w: &PhysicsWorld, s: &PlantState| {
        s.velocity + (s.rotation * s.omega).cross(&(s.rotation * w.local_center_of_mass()))
    };
    let v0 = com_velocity(&w, &s1);
    let forces = vec![Vector3::zeros(); team.len()];
    let extra = ExtraWrench::default();
    for _ in 0..50 {
        let a = w.state();
        w.step(&forces, &extra).unwrap();
        let b = w.state();
        let fd = (b.position - a.position) / config.dt;
        let mid = 0.5 * (a.velocity + b.velocity);
        assert!((fd - mid).norm() < 1e-4, "{fd} vs {mid}");
    }
    // Free of forces, the centre of mass moves in a straight line at constant speed.
    let v = com_velocity(&w, &w.state());
    assert!((v - v0).norm() < 1e-9, "{v} vs {v0}");
}

#[test]
fn off_centre_team_is_rejected() {
    let mut t = TeamBody::a4_inc();
    t.agents[0].position[0] += 0.01;
    assert!(matches!(t.validate(), Err(PhysicsError::InvalidTeam(_))));
}

#[test]
fn paper_team_numbers() {
    let t = TeamBody::a4_inc();
    assert!((t.mass() - 2.8).abs() < 1e-12);
    let a2 = TeamBody::paper_arm().powi(2);
    let j = t.inertia();
    assert!((j[(0, 0)] - 4.0 * 0.7 * a2).abs() < 1e-12);
    assert!((j[(2, 2)] - 8.0 * 0.7 * a2).abs() < 1e-12);
    assert!((t.rest_height() - DEFAULT_COLLIDER_RADIUS).abs() < 1e-15);
}
