//! The attitude planner's saturation angle for the paper's A4-Inc team in hover.
//!
//! With the reference rolled past the attainable set, the planner stops at
//! `phi_max = atan(c_y(1, s))` (`docs/method.md`, "Reproduction targets"). Run with
//! `cargo run --release --example planner_saturation`.

use tvmd::core::nalgebra::{Rotation3, Vector3};
use tvmd::core::rotation::roll_angle;
use tvmd::core::team::presets;
use tvmd::core::{AgentLimits, AttitudePlanner, Relaxation, TeamConfig};

fn planned_roll(
    team: &TeamConfig<f64, 4>,
    s: f64,
) -> Result<(f64, f64, u32), Box<dyn std::error::Error>> {
    let afs = team.afs(&Default::default())?;
    let relaxation = Relaxation::new(s)?;
    // The paper's stage-B peak: roll pi/3, infeasible for every s.
    let r_r = *Rotation3::from_axis_angle(&Vector3::x_axis(), std::f64::consts::FRAC_PI_3).matrix();
    let f_r = Vector3::new(0.0, 0.0, team.mass() * presets::GRAVITY);
    let out = AttitudePlanner::new(relaxation).plan(&afs, &r_r, &f_r)?;
    let roll = roll_angle(&out.r_d);
    Ok((
        roll,
        afs.semi_axes(1.0, relaxation).c_y.atan(),
        out.iterations,
    ))
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let pi = std::f64::consts::PI;
    let inc = presets::a4_inc::<f64, 4>()?;
    let narrow = presets::square::<f64, 4>(
        [1, 1, 0, 0],
        AgentLimits::new(pi / 6.0, pi / 6.0, 2.0 * 0.7 * 9.81)?,
    )?;
    println!(
        "Planner saturation in hover, reference roll pi/3 (paper team A4-Inc, m_C = {} kg)",
        inc.mass()
    );
    println!(
        "{:<22} {:>5} {:>14} {:>16} {:>6}",
        "team", "s", "planned roll", "atan(c_y(1,s))", "iters"
    );
    for (name, team) in [("A4-Inc", &inc), ("A4-Inc sigma_y=pi/6", &narrow)] {
        for s in [0.25, 0.5, 0.75, 1.0] {
            let (roll, law, iterations) = planned_roll(team, s)?;
            println!("{name:<22} {s:>5.2} {roll:>14.6} {law:>16.6} {iterations:>6}");
        }
    }
    Ok(())
}
