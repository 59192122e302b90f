//! One control cycle of the paper's A4-Inc team, printing every diagnostic.
//!
//! The team hovers 0.2 m off its reference while the reference rolls to pi/3 (the infeasible
//! peak of the paper's stage B): the planner tilts less, the law and the redistributed
//! pseudo-inverse produce commands inside the gimbal and thrust limits.
//! Run with `cargo run --release --example control_cycle`.

use tvmd::core::controller::roll;
use tvmd::core::nalgebra::Vector3;
use tvmd::core::team::presets;
use tvmd::core::{
    Controller, ControllerSettings, RedistributedPseudoInverse, Reference, RigidState,
};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let team = presets::a4_inc::<f64, 4>()?;
    let mut controller = Controller::new(
        team,
        ControllerSettings::paper(),
        RedistributedPseudoInverse,
    )?;
    let state = RigidState::at_rest(Vector3::new(0.2, 0.0, 1.5));
    let mut reference = Reference::hover(Vector3::new(0.0, 0.0, 1.5));
    reference.attitude = roll(std::f64::consts::FRAC_PI_3);
    let out = controller.step(&state, &reference)?;

    println!(
        "team A4-Inc: m_C = {} kg, n = {}, n_x = {}",
        team.mass(),
        team.len(),
        team.n_x(&Default::default())
    );
    println!(
        "u_fr (from u_r)   = {:.4?}",
        out.law.u_r.fixed_rows::<3>(3).as_slice()
    );
    println!(
        "t_Tf, t_eta       = {:.6}, {:.6}",
        out.projection.t_tf, out.projection.t_eta
    );
    println!("f_r (inertial)    = {:.4?}", out.f_r.as_slice());
    let r_d = out.planner.r_d;
    println!(
        "planner           = {:?} after {} iterations, theta = {:.6} rad, planned roll = {:.6} rad",
        out.planner.status,
        out.planner.iterations,
        out.planner.theta,
        r_d[(2, 1)].atan2(r_d[(2, 2)])
    );
    println!("e_x               = {:.4?}", out.law.e_x.as_slice());
    println!("e_R               = {:.4?}", out.law.e_r.as_slice());
    println!("u_r               = {:.4?}", out.law.u_r.as_slice());
    println!("u_d               = {:.4?}", out.law.u_d.as_slice());
    println!(
        "allocated wrench  = {:.4?}",
        out.allocation.wrench.as_slice()
    );
    println!(
        "e_f               = {:.3e} N ({} round(s), saturated {:?})",
        out.allocation.e_f, out.allocation.rounds, out.allocation.saturated
    );
    println!("V_R, V_x          = {:.6}, {:.6}", out.law.v_r, out.law.v_x);
    println!("agent   eta_x [rad]  eta_y [rad]  thrust [N]  omega [-]");
    for (i, c) in out.commands.iter().enumerate() {
        println!(
            "{i:>5} {:>12.5} {:>12.5} {:>11.4} {:>10.4}",
            c.eta_x, c.eta_y, c.thrust, c.omega
        );
    }
    let limits = team.limits();
    println!(
        "limits: |eta_x| <= {:.4}, |eta_y| <= {:.4}, thrust <= {:.3} N",
        limits.sigma_x(),
        limits.sigma_y(),
        limits.max_thrust()
    );
    Ok(())
}
