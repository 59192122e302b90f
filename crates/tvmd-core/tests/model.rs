//! Gimbal, effectiveness and AFS behaviour beyond the reference vectors.

use nalgebra::Vector3;
use proptest::prelude::*;
use tvmd_core::gimbal::thrust_direction;
use tvmd_core::team::presets;
use tvmd_core::{project_force, FailureMask, GimbalCommand, Relaxation};

#[test]
fn zero_force_gives_idle_gimbal() {
    assert_eq!(
        GimbalCommand::from_force(&Vector3::<f64>::zeros()),
        GimbalCommand::idle()
    );
}

#[test]
fn failed_agents_leave_n_nx_and_m() {
    let team = presets::a4_inc::<f64, 4>().unwrap();
    let mask = FailureMask::with_failed(&[0]).unwrap();
    let afs = team.afs(&mask).unwrap();
    assert_eq!((afs.n(), afs.n_x()), (3, 2));
    let m = team.effectiveness(&mask);
    assert!(m.block(0).is_none() && m.block(1).is_some());
    assert_eq!(m.working_count(), 3);
    // The failed agent's force does not enter the wrench.
    let mut forces = [Vector3::zeros(); 4];
    forces[0] = Vector3::new(1.0, 2.0, 3.0);
    assert_eq!(m.wrench(&forces), nalgebra::Vector6::zeros());
    let mut dense = vec![0.0; 18 * 4];
    assert!(m.write_dense(4, &mut dense));
    assert!(dense
        .chunks(12)
        .all(|row| row[..3].iter().all(|x| *x == 0.0)));
}

#[test]
fn projection_is_identity_inside_and_lands_on_boundary_outside() {
    let team = presets::a4_inc::<f64, 4>().unwrap();
    let afs = team.afs(&Default::default()).unwrap();
    let hover = Vector3::new(0.5, -0.3, 27.0);
    let p = project_force(&afs, &hover);
    assert_eq!((p.t_tf, p.t_eta, p.force), (1.0, 1.0, hover));
    let wild = Vector3::new(40.0, 30.0, 5.0);
    let p = project_force(&afs, &wild);
    assert!(p.t_eta < 1.0);
    let q = afs.quadratic_form(&p.force, Relaxation::none());
    assert!((q - 1.0).abs() < 1e-12, "q = {q}");
    let huge = Vector3::new(0.0, 0.0, 1e3);
    let p = project_force(&afs, &huge);
    assert!((p.force.norm() - afs.max_force()).abs() < 1e-9);
    assert!(afs.contains(&p.force, Relaxation::none()));
    let nan = project_force(&afs, &Vector3::new(f64::NAN, 0.0, 1.0));
    assert_eq!(nan.force, Vector3::zeros());
}

proptest! {
    #[test]
    fn gimbal_inverse_round_trips(ex in -1.5f64..1.5, ey in -3.1f64..3.1, t in 0.01f64..50.0) {
        let cmd = GimbalCommand { thrust: t, eta_x: ex, eta_y: ey };
        let back = GimbalCommand::from_force(&cmd.force());
        prop_assert!((back.thrust - t).abs() < 1e-12 * t.max(1.0));
        prop_assert!((back.eta_x - ex).abs() < 1e-9);
        prop_assert!((back.eta_y - ey).abs() < 1e-9);
        prop_assert!((thrust_direction(ex, ey).norm() - 1.0).abs() < 1e-15);
    }

    #[test]
    fn projection_output_is_in_the_afs(x in -80.0f64..80.0, y in -80.0f64..80.0, z in 0.01f64..120.0) {
        let team = presets::a4_inc::<f64, 4>().unwrap();
        let afs = team.afs(&Default::default()).unwrap();
        let p = project_force(&afs, &Vector3::new(x, y, z));
        prop_assert!(p.t_tf > 0.0 && p.t_tf <= 1.0 && p.t_eta >= 0.0 && p.t_eta <= 1.0);
        prop_assert!(p.force.norm() <= afs.max_force() * (1.0 + 1e-12));
        prop_assert!(afs.quadratic_form(&p.force, Relaxation::none()) <= 1.0 + 1e-9);
    }
}
