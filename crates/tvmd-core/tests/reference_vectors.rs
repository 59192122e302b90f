//! Every case of the shared reference vectors, in f64 (relative 1e-9, planner angle 1e-6 rad)
//! and in f32 (relative 1e-4).

mod common;

use common::*;
use nalgebra::{Matrix3, Vector3};
use tvmd_core::effectiveness::agent_block;
use tvmd_core::real::Real;
use tvmd_core::{
    project_force, AttainableForceSpace, AttitudePlanner, GimbalCommand, PlannerStatus, Relaxation,
};

fn t<T: Real>(x: f64) -> T {
    nalgebra::convert(x)
}

fn back<T: Real>(x: T) -> f64 {
    x.to_subset().unwrap()
}

fn v3<T: Real>(a: [f64; 3]) -> Vector3<T> {
    Vector3::new(t(a[0]), t(a[1]), t(a[2]))
}

fn out3<T: Real>(v: &Vector3<T>) -> Vec<f64> {
    v.iter().map(|x| back(*x)).collect()
}

fn m3<T: Real>(r: &[Vec<f64>]) -> Matrix3<T> {
    Matrix3::from_fn(|i, j| t(r[i][j]))
}

fn n_x_of(quarter_turns: &[i32]) -> usize {
    quarter_turns
        .iter()
        .filter(|m| m.rem_euclid(2) == 0)
        .count()
}

/// Runs every group for `T`; returns the number of cases checked.
fn check_all<T: Real>(rel: f64, theta_tol: f64) -> usize {
    let v = vectors();
    let mut checked = 0;

    for (i, c) in cases(&v, "gimbal").iter().enumerate() {
        let cmd = GimbalCommand {
            thrust: t::<T>(f(c, "thrust")),
            eta_x: t(f(c, "eta_x")),
            eta_y: t(f(c, "eta_y")),
        };
        let want = vec3(&c["force"]);
        assert_close(
            &out3(&cmd.force()),
            &want,
            rel,
            &format!("gimbal[{i}].force"),
        );
        let inv = GimbalCommand::from_force(&v3::<T>(want));
        assert_close(
            &[back(inv.thrust), back(inv.eta_x), back(inv.eta_y)],
            &[f(c, "inv_thrust"), f(c, "inv_eta_x"), f(c, "inv_eta_y")],
            rel,
            &format!("gimbal[{i}].inverse"),
        );
        checked += 1;
    }

    for (i, c) in cases(&v, "effectiveness").iter().enumerate() {
        let positions = rows(&c["positions"]);
        let turns = ints(&c["psi_quarter_turns"]);
        let want_m = rows(&c["M"]);
        let forces = list(&c["f"]);
        let mut wrench = nalgebra::Vector6::<T>::zeros();
        for (k, (p, m)) in positions.iter().zip(&turns).enumerate() {
            let block = agent_block::<T>(&v3([p[0], p[1], p[2]]), *m);
            for r in 0..6 {
                let got: Vec<f64> = (0..3).map(|col| back(block[(r, col)])).collect();
                let want: Vec<f64> = want_m[r][3 * k..3 * k + 3].to_vec();
                // Scale by the whole row so structural zeros compare at the row's magnitude.
                let scale = want_m[r].iter().fold(1e-12f64, |a, x| a.max(x.abs()));
                for (g, w) in got.iter().zip(&want) {
                    assert!((g - w).abs() <= rel * scale, "effectiveness[{i}].M row {r}");
                }
            }
            wrench += block * v3::<T>([forces[3 * k], forces[3 * k + 1], forces[3 * k + 2]]);
        }
        let got: Vec<f64> = wrench.iter().map(|x| back(*x)).collect();
        assert_close(
            &got,
            &list(&c["wrench"]),
            rel,
            &format!("effectiveness[{i}].wrench"),
        );
        checked += 1;
    }

    for (i, c) in cases(&v, "afs_semi_axes").iter().enumerate() {
        let afs = AttainableForceSpace::<T>::new(
            u(c, "n"),
            u(c, "n_x"),
            t(f(c, "sigma_x")),
            t(f(c, "sigma_y")),
            t(f(c, "max_thrust")),
        )
        .unwrap();
        let axes = afs.semi_axes(t(f(c, "z")), Relaxation::new(t(f(c, "s"))).unwrap());
        assert_close(
            &[back(axes.c_x), back(axes.c_y)],
            &[f(c, "c_x"), f(c, "c_y")],
            rel,
            &format!("afs_semi_axes[{i}]"),
        );
        checked += 1;
    }

    for (i, c) in cases(&v, "force_projection").iter().enumerate() {
        let turns = ints(&c["psi_quarter_turns"]);
        let afs = AttainableForceSpace::<T>::new(
            u(c, "n"),
            n_x_of(&turns),
            t(f(c, "sigma_x")),
            t(f(c, "sigma_y")),
            t(f(c, "max_thrust")),
        )
        .unwrap();
        let p = project_force(&afs, &v3::<T>(vec3(&c["u"])));
        assert_close(
            &out3(&p.force),
            &vec3(&c["u_projected"]),
            rel,
            &format!("force_projection[{i}]"),
        );
        checked += 1;
    }

    for (i, c) in cases(&v, "attitude_planner").iter().enumerate() {
        let turns = ints(&c["psi_quarter_turns"]);
        let afs = AttainableForceSpace::<T>::new(
            u(c, "n"),
            n_x_of(&turns),
            t(f(c, "sigma_x")),
            t(f(c, "sigma_y")),
            t(f(c, "max_thrust")),
        )
        .unwrap();
        let planner = AttitudePlanner::new(Relaxation::new(t::<T>(f(c, "s"))).unwrap());
        let out = planner
            .plan(&afs, &m3(&rows(&c["R_r"])), &v3(vec3(&c["f_r"])))
            .unwrap();
        let want_theta = f(c, "theta");
        assert!(
            (back(out.theta) - want_theta).abs() <= theta_tol,
            "attitude_planner[{i}].theta: got {}, want {want_theta}",
            back(out.theta)
        );
        if want_theta == 0.0 {
            assert_eq!(out.status, PlannerStatus::AlreadyFeasible, "planner[{i}]");
        } else {
            assert_eq!(out.status, PlannerStatus::Planned, "planner[{i}]");
        }
        let want_r: Vec<f64> = rows(&c["R_d"]).concat();
        let got_r: Vec<f64> = (0..3)
            .flat_map(|r| (0..3).map(move |col| (r, col)))
            .map(|(r, col)| back(out.r_d[(r, col)]))
            .collect();
        // R_d moves with theta at unit rate, so it gets the angle's tolerance.
        assert_close(
            &got_r,
            &want_r,
            theta_tol.max(rel),
            &format!("planner[{i}].R_d"),
        );
        checked += 1;
    }
    checked
}

#[test]
fn every_reference_vector_f64() {
    let n = check_all::<f64>(1e-9, 1e-6);
    assert_eq!(n, 40 + 25 + 60 + 60 + 60);
    println!("checked {n} reference vectors in f64");
}

#[test]
fn every_reference_vector_f32() {
    let n = check_all::<f32>(1e-4, 1e-4);
    assert_eq!(n, 40 + 25 + 60 + 60 + 60);
    println!("checked {n} reference vectors in f32");
}
