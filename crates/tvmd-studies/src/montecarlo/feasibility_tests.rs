//! The verdict on constructed plants, and its certificates checked by brute force on drawn ones.

use super::*;
use crate::montecarlo::{Distributions, Draw};
use tvmd_plant::actuators::{agent_force_body, ActuatorCommand};
use tvmd_scenario::PlantError;

fn hover(team: &str, plant: PlantError) -> Scenario {
    let mut s = Scenario::builtin("hover").unwrap();
    s.team.preset = Some(team.into());
    s.plant = plant;
    s
}

fn verdict(s: &Scenario) -> Feasibility {
    Plant::new(s).unwrap().verdict(s).feasibility
}

/// The wrench the simulator's own force map makes for `commands` about the model's centre of
/// mass: `[sum p_i x f_i; sum f_i]` (not the atlas model's map).
fn simulated_wrench(s: &Scenario, commands: &[GimbalCommand<f64>]) -> Vector6<f64> {
    let body = s.team_body().unwrap();
    let outputs: Vec<ActuatorCommand> = commands
        .iter()
        .map(|c| ActuatorCommand {
            eta_x: c.eta_x,
            eta_y: c.eta_y,
            thrust: c.thrust,
        })
        .collect();
    let forces = tvmd_sim::sim::agent_forces(&outputs, &body, &s.plant);
    let mut w = Vector6::zeros();
    for (a, f) in body.agents.iter().zip(forces) {
        let f = Vector3::from(f);
        let tau = a.position_vector().cross(&f);
        w += Vector6::new(tau.x, tau.y, tau.z, f.x, f.y, f.z);
    }
    w
}

/// An upper bound of `max y . w` over the whole attainable set, by brute force over every
/// agent's admissible commands: a dense grid of cells (40 x 40 per agent), each cell bounded by
/// by its centre's `u = y . w` per newton of thrust plus `L` times its half-widths
/// (`L = e |y_tau x p_i + y_f|` bounds the change of `u` per radian of either angle), at the
/// thrust end where `T u` peaks, cells whose bound is not within `slack` of the best value found split in
/// four (branch and bound; `slack` only sets how far it refines, the bound holds whatever it
/// is). Uses the plant's force function, not the atlas model.
fn brute_support(s: &Scenario, model: &AtlasModel, y: &Vector6<f64>, slack: f64) -> f64 {
    let body = s.team_body().unwrap();
    let b = model.agent_box;
    let y_tau = Vector3::new(y[0], y[1], y[2]);
    let y_f = Vector3::new(y[3], y[4], y[5]);
    let mut total = 0.0;
    for (i, a) in body.agents.iter().enumerate() {
        let p = a.position_vector();
        let [ox, oy] = s.plant.gimbal_offset(i);
        let e = s.plant.efficiency(i);
        // `u`: `y . w` per newton of commanded thrust; the agent's best is `max_T T u`.
        let unit = |eta_x: f64, eta_y: f64| {
            let real = ActuatorCommand {
                eta_x: eta_x + ox,
                eta_y: eta_y + oy,
                thrust: e,
            };
            let f = agent_force_body(&real, a.quarter_turns);
            y_tau.dot(&p.cross(&f)) + y_f.dot(&f)
        };
        let best_thrust = |u: f64| (b.min_thrust * u).max(b.max_thrust * u);
        let value = |eta_x: f64, eta_y: f64| best_thrust(unit(eta_x, eta_y));
        // `u = e c . a_hat` with `c = y_tau x p + y_f` (body frame), `|d a_hat / d eta| <= 1`.
        let lipschitz = e * (y_tau.cross(&p) + y_f).norm();
        let k = 40;
        let (hx, hy) = (b.sigma_x / k as f64, b.sigma_y / k as f64);
        let mut cells: Vec<(f64, f64, f64, f64)> = (0..k * k)
            .map(|c| {
                let (ix, iy) = ((c / k) as f64, (c % k) as f64);
                (
                    -b.sigma_x + hx * (2.0 * ix + 1.0),
                    -b.sigma_y + hy * (2.0 * iy + 1.0),
                    hx,
                    hy,
                )
            })
            .collect();
        // The grid first: a good best value before any cell splits.
        let mut best = cells
            .iter()
            .map(|(cx, cy, _, _)| value(*cx, *cy))
            .fold(f64::NEG_INFINITY, f64::max);
        let mut bound = f64::NEG_INFINITY;
        let mut visited = 0usize;
        while let Some((cx, cy, hx, hy)) = cells.pop() {
            visited += 1;
            if visited > 2_000_000 {
                return f64::INFINITY;
            }
            let u = unit(cx, cy);
            best = best.max(best_thrust(u));
            let upper = best_thrust(u + lipschitz * (hx + hy));
            if upper <= best + slack {
                bound = bound.max(upper);
            } else {
                let (hx, hy) = (0.5 * hx, 0.5 * hy);
                for (sx, sy) in [(-1.0, -1.0), (-1.0, 1.0), (1.0, -1.0), (1.0, 1.0)] {
                    cells.push((cx + sx * hx, cy + sy * hy, hx, hy));
                }
            }
        }
        total += bound.max(best);
    }
    total
}

/// Nominal plants hover; a plant whose thrust cannot carry its weight, or whose centre of mass
/// lies beyond its outermost agent (no thrust pattern balances that torque), does not.
#[test]
fn constructed_plants_get_the_verdict_physics_gives() {
    for team in ["a4-inc", "a6-inc", "a8-inc"] {
        assert_eq!(
            verdict(&hover(team, PlantError::default())),
            Feasibility::Feasible
        );
    }
    // A4-Inc weighs 27.5 N on 4 x 13.734 N of thrust: at 45% efficiency it makes 24.7 N.
    let weak = |e: f64| PlantError {
        thrust_efficiency: vec![e; 4],
        gimbal_offsets: vec![[0.0; 2]; 4],
        ..PlantError::default()
    };
    assert_eq!(
        verdict(&hover("a4-inc", weak(0.45))),
        Feasibility::Infeasible
    );
    assert_eq!(verdict(&hover("a4-inc", weak(0.55))), Feasibility::Feasible);
    // Vertical thrust balances the centre of mass only between the agents.
    let s = hover("a4-inc", PlantError::default());
    let reach = s
        .team_body()
        .unwrap()
        .agents
        .iter()
        .map(|a| a.position[1].abs())
        .fold(0.0, f64::max);
    let offset = |y: f64| PlantError {
        com_offset: [0.0, y, 0.0],
        ..PlantError::default()
    };
    assert_eq!(
        verdict(&hover("a4-inc", offset(0.5 * reach))),
        Feasibility::Feasible
    );
    assert_eq!(
        verdict(&hover("a4-inc", offset(1.5 * reach))),
        Feasibility::Infeasible
    );
    // A heavy payload far out makes the payload family infeasible from its attachment on.
    let mut payload = Scenario::builtin("payload").unwrap();
    payload.payloads[0].mass = 1.5;
    payload.payloads[0].offset = [1.0, 0.0, 0.0];
    let v = Plant::new(&payload).unwrap().verdict(&payload);
    assert_eq!(v.feasibility, Feasibility::Infeasible);
    let at = v.first_infeasible.unwrap();
    assert!(
        (at - payload.payloads[0].time).abs() < SAMPLE_PERIOD + 1e-9,
        "{at}"
    );
}

/// On 200 drawn plants (A4-Inc, wide centre-of-mass and efficiency errors so that both verdicts
/// occur), every certificate holds against a check of its own: a feasible verdict's commands
/// lie in the box and the simulator's force map turns them into the wrench needed; an
/// infeasible verdict's multiplier separates, with the maximum over a dense grid of every
/// agent's commands (plus the grid's error bound) below `y . w`.
#[test]
fn verdicts_agree_with_brute_force_on_200_drawn_plants() {
    let d = Distributions {
        model_error: 1.0,
        mass: 0.3,
        com_offset: 0.25,
        thrust_efficiency: 0.6,
        gimbal_offset: 0.1,
        ..Distributions::default()
    };
    let base = hover("a4-inc", PlantError::default());
    let (mut feasible, mut infeasible, mut undecided, mut close) = (0, 0, 0, 0);
    for index in 0..200 {
        let s = Draw::new(&d, 61, index, 4).apply(&base).unwrap();
        let plant = Plant::new(&s).unwrap();
        let target = plant.required_wrench(&s, 0.0);
        let scale = plant.model().scale();
        match wrench_verdict(plant.model(), &target, None) {
            WrenchVerdict::Feasible(x) => {
                feasible += 1;
                assert!(x.iter().all(|c| plant.model().agent_box.contains(c, 1e-12)));
                let w = simulated_wrench(&s, &x);
                assert!(
                    (w - target).norm() < 1e-8 * scale,
                    "{index}: {w} vs {target}"
                );
            }
            WrenchVerdict::Infeasible(y) => {
                infeasible += 1;
                // Relative to `|y| n sigma_Tf`; a target within 1e-4 of the hull's boundary is
                // too close for the grid to settle (counted, and bounded below).
                let margin = y.dot(&target) - plant.model().support(&y).0;
                if margin < 1e-4 * y.norm() * scale {
                    close += 1;
                    continue;
                }
                let slack = 0.25 * margin / plant.model().len() as f64;
                let bound = brute_support(&s, plant.model(), &y, slack);
                assert!(
                    bound < y.dot(&target),
                    "{index}: {bound} >= {}",
                    y.dot(&target)
                );
            }
            WrenchVerdict::Undecided => undecided += 1,
        }
    }
    eprintln!("{feasible} feasible, {infeasible} infeasible ({close} near the boundary), {undecided} undecided");
    assert!(
        feasible >= 20 && infeasible >= 20,
        "{feasible} / {infeasible}"
    );
    assert!(
        close <= 4,
        "{close} infeasible verdicts too near the boundary to check"
    );
    assert_eq!(undecided, 0);
}
