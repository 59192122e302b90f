//! Planner properties over random teams, attitudes and forces, and the paper's hover
//! saturation law.

use std::f64::consts::FRAC_PI_2;

use nalgebra::{Matrix3, Rotation3, Vector3};
use proptest::prelude::*;
use tvmd_core::planner::tilted_attitude;
use tvmd_core::team::presets;
use tvmd_core::{AgentLimits, AttitudePlanner, PlannerStatus, Relaxation, TeamConfig};

fn roll_of(r: &Matrix3<f64>) -> f64 {
    r[(2, 1)].atan2(r[(2, 2)])
}

fn orthonormality_error(r: &Matrix3<f64>) -> f64 {
    (r.transpose() * r - Matrix3::identity()).amax() + (r.determinant() - 1.0).abs()
}

/// In hover (`f_r = m_C g e_3`) with a reference roll beyond the limit, the planned roll is
/// `atan(c_y(1, s))`.
fn planned_hover_roll(team: &TeamConfig<f64, 4>, s: f64, reference_roll: f64) -> (f64, f64) {
    let afs = team.afs(&Default::default()).unwrap();
    let relaxation = Relaxation::new(s).unwrap();
    let law = afs.semi_axes(1.0, relaxation).c_y.atan();
    let planner = AttitudePlanner::new(relaxation);
    let r_r = *Rotation3::from_axis_angle(&Vector3::x_axis(), reference_roll).matrix();
    let f_r = Vector3::new(0.0, 0.0, team.mass() * presets::GRAVITY);
    let out = planner.plan(&afs, &r_r, &f_r).unwrap();
    assert_eq!(out.status, PlannerStatus::Planned);
    (roll_of(&out.r_d), law)
}

#[test]
fn hover_saturation_law_paper_team() {
    let team = presets::a4_inc::<f64, 4>().unwrap();
    let (roll, law) = planned_hover_roll(&team, 0.5, std::f64::consts::FRAC_PI_3);
    println!("A4-Inc, s = 0.5: planned roll {roll:.6} rad, atan(c_y(1, s)) = {law:.6}");
    assert!((law - 0.3287).abs() < 5e-5, "law {law}");
    assert!((roll - law).abs() < 1e-8, "planned {roll} vs law {law}");
    for s in [0.25, 0.75, 1.0] {
        let (roll, law) = planned_hover_roll(&team, s, 1.4);
        println!("A4-Inc, s = {s}: planned roll {roll:.6} rad, law {law:.6}");
        assert!((roll - law).abs() < 1e-8);
    }
}

#[test]
fn hover_saturation_law_sigma_y_pi_over_6() {
    let pi = std::f64::consts::PI;
    let limits = AgentLimits::new(pi / 6.0, pi / 6.0, 2.0 * 0.7 * 9.81).unwrap();
    let team = presets::square::<f64, 4>([1, 1, 0, 0], limits).unwrap();
    let (roll, law) = planned_hover_roll(&team, 0.5, pi / 3.0);
    println!(
        "sigma_y = pi/6, s = 0.5: planned roll {roll:.9} rad, pi/12 = {:.9}",
        pi / 12.0
    );
    assert!((law - pi / 12.0).abs() < 1e-12);
    assert!((roll - pi / 12.0).abs() < 1e-8);
}

#[test]
fn hover_saturation_law_f32() {
    let team = presets::a4_inc::<f32, 4>().unwrap();
    let afs = team.afs(&Default::default()).unwrap();
    let relaxation = Relaxation::new(0.5f32).unwrap();
    let r_r = *Rotation3::from_axis_angle(&Vector3::x_axis(), 1.0f32).matrix();
    let out = AttitudePlanner::new(relaxation)
        .plan(&afs, &r_r, &Vector3::new(0.0, 0.0, team.mass() * 9.81))
        .unwrap();
    let roll = out.r_d[(2, 1)].atan2(out.r_d[(2, 2)]);
    assert!((roll - 0.328_7).abs() < 1e-4, "f32 planned roll {roll}");
}

#[test]
fn zero_force_and_degenerate_axes() {
    let team = presets::a4_inc::<f64, 4>().unwrap();
    let afs = team.afs(&Default::default()).unwrap();
    let planner = AttitudePlanner::new(Relaxation::new(0.5).unwrap());
    let r_r = *Rotation3::from_euler_angles(0.3, -0.2, 1.0).matrix();
    let out = planner.plan(&afs, &r_r, &Vector3::zeros()).unwrap();
    assert_eq!(out.status, PlannerStatus::ZeroForce);
    assert_eq!(out.r_d, r_r);
    // f_r antiparallel to b_zr: the tilt runs about b_xr and ends upright w.r.t. f_r.
    let f_r = -r_r.column(2) * 20.0;
    let out = planner.plan(&afs, &r_r, &f_r).unwrap();
    assert_eq!(out.status, PlannerStatus::Planned);
    assert!(out.theta > 0.0 && out.theta.is_finite());
    assert!(afs.contains(&(out.r_d.transpose() * f_r), planner.relaxation()));
    assert!(orthonormality_error(&out.r_d) < 1e-12);
    // Beyond n sigma_Tf nothing is feasible: aligned with f_r, flagged unreachable.
    let f_r = Vector3::new(3.0, -1.0, 1.0) * 100.0;
    let out = planner.plan(&afs, &r_r, &f_r).unwrap();
    assert_eq!(out.status, PlannerStatus::Unreachable);
    assert!((out.r_d.column(2).dot(&f_r.normalize()) - 1.0).abs() < 1e-12);
    // Non-finite input is a typed error.
    assert!(planner
        .plan(&afs, &r_r, &Vector3::new(f64::NAN, 0.0, 1.0))
        .is_err());
}

fn team_strategy() -> impl Strategy<Value = TeamConfig<f64, 16>> {
    (
        3usize..=10,
        0.2f64..1.5,
        any::<bool>(),
        0.1f64..=FRAC_PI_2,
        0.1f64..=FRAC_PI_2,
        2.0f64..30.0,
    )
        .prop_map(|(n, radius, inc, sx, sy, thrust)| {
            let limits = AgentLimits::new(sx, sy, thrust).unwrap();
            presets::ring::<f64, 16>(n, radius, inc, limits).unwrap()
        })
}

fn rotation_strategy() -> impl Strategy<Value = Matrix3<f64>> {
    (-3.2f64..3.2, -1.6f64..1.6, -3.2f64..3.2)
        .prop_map(|(r, p, y)| *Rotation3::from_euler_angles(r, p, y).matrix())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    #[test]
    fn planner_output_is_feasible_minimal_and_orthonormal(
        team in team_strategy(),
        r_r in rotation_strategy(),
        dir in (-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0),
        scale in 0.0f64..1.0,
        s in 0.05f64..=1.0,
    ) {
        let afs = team.afs(&Default::default()).unwrap();
        let relaxation = Relaxation::new(s).unwrap();
        let planner = AttitudePlanner::new(relaxation);
        let dir = Vector3::new(dir.0, dir.1, dir.2);
        prop_assume!(dir.norm() > 1e-3);
        // Within n sigma_Tf, as the cycle's t_Tf guarantees.
        let f_r = dir.normalize() * scale * afs.max_force();
        let out = planner.plan(&afs, &r_r, &f_r).unwrap();
        prop_assert!(out.r_d.iter().all(|x| x.is_finite()) && out.theta.is_finite());
        prop_assert!(orthonormality_error(&out.r_d) < 1e-9);
        match out.status {
            PlannerStatus::AlreadyFeasible => {
                prop_assert_eq!(out.theta, 0.0);
                prop_assert!(afs.contains(&(r_r.transpose() * f_r), relaxation));
            }
            PlannerStatus::Planned => {
                prop_assert!(afs.contains(&(out.r_d.transpose() * f_r), relaxation));
                prop_assert!(out.iterations <= 64);
                // The search's safeguard: at most 4 steps more than bisection to the default
                // tolerance (1e-10 rad) would need from [0, theta_max].
                let theta_max = r_r.column(2).dot(&f_r.normalize()).clamp(-1.0, 1.0).acos();
                let bisection_steps = (theta_max / 1e-10).log2().ceil().max(0.0) as u32;
                prop_assert!(
                    out.iterations <= bisection_steps + 4,
                    "{} steps, bisection {}", out.iterations, bisection_steps
                );
                let earlier = tilted_attitude(&r_r, &f_r, out.theta - 1e-7);
                prop_assert!(
                    !afs.contains(&(earlier.transpose() * f_r), relaxation),
                    "theta {} is not minimal", out.theta
                );
            }
            PlannerStatus::ZeroForce => prop_assert_eq!(scale, 0.0),
            PlannerStatus::Unreachable => prop_assert!(false, "f_r within n sigma_Tf must be reachable"),
        }
    }
}
