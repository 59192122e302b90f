//! Inner bounds: commands inside every agent's box that produce a wrench exactly (to rounding),
//! found by a projected Gauss-Newton solve; along a ray, the farthest such wrench found by
//! bisection. Every inner number is attained by the commands it comes with.

use nalgebra::{DMatrix, DVector, Matrix6, Vector6};
use tvmd_core::GimbalCommand;

use super::model::AtlasModel;
use super::ray::Ray;

/// Residual `|w(x) - target|` (N and N m together) accepted as attained: `1e-10 n sigma_Tf`.
pub const ATTAINED_TOLERANCE: f64 = 1e-10;
const MAX_ITERATIONS: usize = 80;
const AT_BOUND: f64 = 1e-12;

fn pack(commands: &[GimbalCommand<f64>], t_hi: f64) -> DVector<f64> {
    DVector::from_iterator(
        3 * commands.len(),
        commands
            .iter()
            .flat_map(|c| [c.thrust / t_hi, c.eta_x, c.eta_y]),
    )
}

fn unpack(x: &DVector<f64>, t_hi: f64) -> Vec<GimbalCommand<f64>> {
    x.as_slice()
        .chunks_exact(3)
        .map(|c| GimbalCommand {
            thrust: c[0] * t_hi,
            eta_x: c[1],
            eta_y: c[2],
        })
        .collect()
}

/// Lower and upper bounds of each packed variable.
fn bounds(model: &AtlasModel) -> Vec<(f64, f64)> {
    let b = &model.agent_box;
    let t = (b.min_thrust / b.max_thrust, 1.0);
    let per_agent = [t, (-b.sigma_x, b.sigma_x), (-b.sigma_y, b.sigma_y)];
    per_agent
        .iter()
        .copied()
        .cycle()
        .take(3 * model.len())
        .collect()
}

/// Commands inside the boxes with `w(x) = target` (residual at most
/// [`ATTAINED_TOLERANCE`]` n sigma_Tf`), from `start` by projected Gauss-Newton (minimum-norm
/// steps on the variables not held at a bound, backtracking, Levenberg damping on failure).
/// `None` when the solve does not converge: not a proof that `target` is unattainable.
pub fn attain(
    model: &AtlasModel,
    target: &Vector6<f64>,
    start: &[GimbalCommand<f64>],
) -> Option<Vec<GimbalCommand<f64>>> {
    let t_hi = model.agent_box.max_thrust;
    let bounds = bounds(model);
    let clamp = |x: &mut DVector<f64>| {
        for (v, (lo, hi)) in x.iter_mut().zip(&bounds) {
            *v = v.clamp(*lo, *hi);
        }
    };
    let tol = ATTAINED_TOLERANCE * model.scale();
    let residual = |x: &DVector<f64>| model.wrench(&unpack(x, t_hi)) - target;
    let mut x = pack(start, t_hi);
    clamp(&mut x);
    let mut r = residual(&x);
    let mut damping = 1e-12;
    for _ in 0..MAX_ITERATIONS {
        let norm = r.norm();
        if !norm.is_finite() {
            return None;
        }
        if norm <= tol {
            return Some(unpack(&x, t_hi));
        }
        let j = model.jacobian(&unpack(&x, t_hi));
        let step = projected_step(&j, &r, &x, &bounds, damping)?;
        let mut accepted = false;
        let mut lambda = 1.0;
        for _ in 0..30 {
            let mut trial = &x + &step * lambda;
            clamp(&mut trial);
            let r_trial = residual(&trial);
            if r_trial.norm() < norm * (1.0 - 1e-4 * lambda) {
                x = trial;
                r = r_trial;
                accepted = true;
                break;
            }
            lambda *= 0.5;
        }
        if accepted {
            damping = (damping * 0.1).max(1e-12);
        } else {
            damping *= 1e3;
            if damping > 1e6 {
                return None;
            }
        }
    }
    (r.norm() <= tol).then(|| unpack(&x, t_hi))
}

/// The minimum-norm step `-J_F^T (J_F J_F^T + mu I)^-1 r` on the free set `F`: variables at a
/// bound that the step would push outward are held, and the step recomputed.
fn projected_step(
    j: &DMatrix<f64>,
    r: &Vector6<f64>,
    x: &DVector<f64>,
    bounds: &[(f64, f64)],
    damping: f64,
) -> Option<DVector<f64>> {
    let mut free = vec![true; x.len()];
    for _ in 0..=x.len() {
        let mut jf = j.clone();
        for (k, f) in free.iter().enumerate() {
            if !f {
                jf.column_mut(k).fill(0.0);
            }
        }
        let gram: Matrix6<f64> = (&jf * jf.transpose()).fixed_view::<6, 6>(0, 0).into_owned();
        let mu = damping * (1.0 + gram.diagonal().max());
        let z = (gram + Matrix6::identity() * mu).cholesky()?.solve(r);
        let step = -(jf.transpose() * z);
        let mut changed = false;
        for (k, (lo, hi)) in bounds.iter().enumerate() {
            let pushes_out = (x[k] <= lo + AT_BOUND && step[k] < 0.0)
                || (x[k] >= hi - AT_BOUND && step[k] > 0.0);
            if free[k] && pushes_out {
                free[k] = false;
                changed = true;
            }
        }
        if !changed {
            return Some(step);
        }
    }
    None
}

/// Whether each packed variable of `commands` sits at a bound.
pub(super) fn at_bounds(model: &AtlasModel, commands: &[GimbalCommand<f64>]) -> Vec<bool> {
    let x = pack(commands, model.agent_box.max_thrust);
    x.iter()
        .zip(bounds(model))
        .map(|(v, (lo, hi))| *v <= lo + 1e-9 || *v >= hi - 1e-9)
        .collect()
}

/// The farthest `t` in `[0, upper]` found with `origin + t direction` attained: the origin by
/// [`attain`] from level hover, then each seed (commands near the boundary, e.g. the dual's
/// maximizers) at its own `t`, then bisection from the best attained point. `None` when the
/// origin itself is not attained.
pub fn farthest_attained(
    model: &AtlasModel,
    ray: &Ray,
    upper: f64,
    seeds: &[Vec<GimbalCommand<f64>>],
) -> Option<(f64, Vec<GimbalCommand<f64>>)> {
    let hover = ray.origin[5] / model.len() as f64;
    let mut best = (0.0, attain(model, &ray.at(0.0), &model.level(hover))?);
    let upper = upper.max(0.0);
    for seed in seeds {
        let t = ray.parameter(&model.wrench(seed)).clamp(0.0, upper);
        if t > best.0 {
            if let Some(x) = attain(model, &ray.at(t), seed) {
                best = (t, x);
            }
        }
    }
    let mut hi = upper;
    for _ in 0..60 {
        if hi - best.0 <= 1e-9 * model.scale() {
            break;
        }
        let mid = 0.5 * (best.0 + hi);
        match attain(model, &ray.at(mid), &best.1) {
            Some(x) => best = (mid, x),
            None => hi = mid,
        }
    }
    Some(best)
}
