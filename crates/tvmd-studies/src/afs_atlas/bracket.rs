//! The bracket of a ray: the dual minimized, the inner search seeded from it, the dual
//! polished from the inner point's multiplier.

use nalgebra::Vector6;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use tvmd_core::GimbalCommand;

use super::inner::{at_bounds, farthest_attained};
use super::model::AtlasModel;
use super::outer::{minimize_dual, DualBound};

use super::ray::{Bracket, Ray, RayBound};

/// Restarts of the dual minimization while a bracket is open.
pub const RESTARTS: usize = 16;
const RESTART_SEED: u64 = 0x7e3d;

/// The bracket of the farthest attainable point of `ray`: the dual minimized from `starts`
/// (and from `direction` itself), the inner search seeded with the dual's maximizers, then the
/// dual polished from the inner point's Lagrange multiplier.
pub fn bound_ray(model: &AtlasModel, ray: &Ray, starts: &[Vector6<f64>]) -> RayBound {
    let mut best: DualBound = minimize_dual(model, ray, &ray.direction);
    for s in starts {
        let d = minimize_dual(model, ray, s);
        if d.value < best.value {
            best = d;
        }
    }
    let inner = farthest_attained(model, ray, best.value, &[best.commands.clone()]);
    if let Some((_, commands)) = &inner {
        if let Some(y) = kkt_multiplier(model, ray, commands) {
            let d = minimize_dual(model, ray, &y);
            if d.value < best.value {
                best = d;
            }
        }
    }
    // The dual is non-smooth where agents sit on the flat faces of their sets, and BFGS can
    // stall on a kink: restart from random perturbations of the best multiplier (seeded, so
    // results repeat) while the bracket is open.
    let open = |best: &DualBound, inner: &Option<(f64, Vec<GimbalCommand<f64>>)>| {
        inner
            .as_ref()
            .is_none_or(|(t, _)| best.value - t > 1e-7 * model.scale())
    };
    let mut rng = ChaCha8Rng::seed_from_u64(RESTART_SEED);
    for round in 0..RESTARTS {
        if !open(&best, &inner) {
            break;
        }
        let spread = if round % 2 == 0 { 0.3 } else { 3.0 };
        let start = best.multiplier + Vector6::from_fn(|_, _| spread * rng.random_range(-1.0..1.0));
        let d = minimize_dual(model, ray, &start);
        if d.value < best.value {
            best = d;
        }
    }
    // A second inner pass from the polished dual's maximizers when the bracket is still open
    // (bisection can stall where the first seed led it to a thin part of the set).
    let mut inner = inner;
    if let Some((t, commands)) = &inner {
        if best.value - t > 1e-7 * model.scale() {
            // At a kink of the dual the maximizers are not unique: perturbing the multiplier
            // picks the different vertices, one of which is usually near the ray.
            let mut seeds = vec![best.commands.clone(), commands.clone()];
            for k in 0..6 {
                for sign in [-1.0, 1.0] {
                    let mut y = best.multiplier;
                    y[k] += sign * 1e-6 * (1.0 + y[k].abs());
                    seeds.push(model.support(&y).1);
                }
            }
            if let Some(again) = farthest_attained(model, ray, best.value, &seeds) {
                if again.0 > *t {
                    inner = Some(again);
                }
            }
        }
    }
    RayBound {
        bracket: Bracket {
            lower: inner.as_ref().map(|(t, _)| *t),
            upper: best.value,
        },
        commands: inner.map(|(_, c)| c),
        multiplier: best.multiplier,
    }
}

/// The least-squares Lagrange multiplier of "maximize `t`" at `commands`: `y` with
/// `y . direction = 1` minimizing `|J_F^T y|` over the variables `F` not at a bound.
fn kkt_multiplier(
    model: &AtlasModel,
    ray: &Ray,
    commands: &[GimbalCommand<f64>],
) -> Option<Vector6<f64>> {
    let mut j = model.jacobian(commands);
    for (k, at) in at_bounds(model, commands).iter().enumerate() {
        if *at {
            j.column_mut(k).fill(0.0);
        }
    }
    let gram: nalgebra::Matrix6<f64> = (&j * j.transpose()).fixed_view::<6, 6>(0, 0).into_owned();
    let mu = 1e-10 * (1.0 + gram.diagonal().max());
    let z = (gram + nalgebra::Matrix6::identity() * mu)
        .cholesky()?
        .solve(&ray.direction);
    let scale = z.dot(&ray.direction);
    (scale.abs() > 0.0 && scale.is_finite()).then(|| z / scale)
}
