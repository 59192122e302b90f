//! Hover capability of a (degraded) team: whether the working agents can hold the hover wrench
//! `w_h = [0, 0, 0, 0, 0, m_C g]` (team frame, level; rows `[torque; force]` as eq. 4) strictly
//! inside their attainable wrench set, and with what margin (`docs/method.md`,
//! [Hover capability](../docs/method.md#hover-capability)).
//!
//! The margin is certified by an allocation: forces `f` with `M f = w_h` (to rounding), each
//! inside its exact admissible set `E_f` (eq. 6: gimbal limits on the exact map, thrust
//! range). The margin is the smallest normalized slack of any working agent in `f`: for thrust
//! `T` in `[T_lo, T_hi]`, `min(T - T_lo, T_hi - T) / ((T_hi - T_lo) / 2)`, and the same for each
//! gimbal angle in its range; `1` means every agent sits at the centre of its box, `0` that one
//! touches a bound. With rank-6 `M`, a positive margin puts every agent strictly inside `E_f`
//! where `f = T a_hat(eta)` is a local diffeomorphism (`T > 0`, `|eta_x| < pi/2`), so a
//! neighbourhood of `w_h` is attainable: the hover wrench is strictly inside.
//!
//! The reported margin is a lower bound of the exact one (the best slack over every allocation):
//! a team can be reported incapable although a better allocation exists. The bound is exact
//! when the vertical forces are determined, e.g. for `n = 3` agents at `z = 0`: the vertical
//! force balance and the torques about `x` and `y` fix each vertical force, and the lateral
//! forces (free) only add thrust.

use nalgebra::{Matrix3, Matrix6, Vector3, Vector6};

use crate::agent::admissible::{AdmissibleSet, Interval};
use crate::agent::effectiveness::Effectiveness;
use crate::agent::gimbal::GimbalCommand;
use crate::foundation::linalg::EuclideanNorm;
use crate::foundation::linalg::GramSolver;
use crate::foundation::real::{eps, lit, sqrt, Real};
use crate::foundation::stored::Stored;

/// Reweighting rounds of the certifying allocation (Lawson's iteration for the minimax slack).
pub const HOVER_ITERATIONS: usize = 24;

/// Margins at or below this are "not hover-capable": `sqrt(eps)` (`1.5e-8` in f64, `3.5e-4` in
/// f32), above the rounding of an allocation that touches a bound exactly.
pub fn hover_margin_tolerance<T: Real>() -> T {
    sqrt(eps::<T>())
}

/// Which bound of an agent's admissible set limits the margin (`repr(u8)`: its tag checked raw
/// by [`crate::Controller::storage_intact`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum HoverLimit {
    /// The maximum thrust `sigma_Tf`.
    MaxThrust,
    /// The minimum (idle) thrust.
    MinThrust,
    /// The inner gimbal limit `sigma_x`.
    GimbalX,
    /// The outer gimbal limit `sigma_y`.
    GimbalY,
}

impl HoverLimit {
    /// A stable lowercase name (`"max_thrust"`, `"min_thrust"`, `"gimbal_x"`, `"gimbal_y"`), as
    /// the simulator and the Python bindings spell it.
    pub const fn as_str(self) -> &'static str {
        match self {
            Self::MaxThrust => "max_thrust",
            Self::MinThrust => "min_thrust",
            Self::GimbalX => "gimbal_x",
            Self::GimbalY => "gimbal_y",
        }
    }
}

/// Whether the working agents can hold hover with a margin (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HoverCapability<T: Real> {
    /// `true` when `M` has rank 6, the certifying allocation produces `w_h` and `margin` is above
    /// [`hover_margin_tolerance`]: the hover wrench is strictly inside the attainable set.
    pub capable: bool,
    /// The smallest normalized slack of any working agent in the certifying allocation
    /// (`<= 1`; `<= 0` when that allocation touches or leaves a bound). A lower bound of the
    /// exact margin.
    pub margin: T,
    /// The agent whose slack is `margin` (`None` without working agents).
    pub limiting_agent: Option<usize>,
    /// The bound that agent is closest to.
    pub limit: HoverLimit,
    /// `m_C g` (N), the vertical force of the hover wrench.
    pub weight: T,
}

/// A [`HoverCapability`] as a controller keeps it: the limiting agent in a [`Stored`], whose
/// tag, unlike `Option`'s, [`crate::Controller::storage_intact`] can check raw (with the flag
/// and the limit's tag).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct StoredHover<T: Real> {
    pub(crate) capable: bool,
    pub(crate) margin: T,
    pub(crate) limiting_agent: Stored<usize>,
    pub(crate) limit: HoverLimit,
    pub(crate) weight: T,
}

impl<T: Real> From<HoverCapability<T>> for StoredHover<T> {
    fn from(h: HoverCapability<T>) -> Self {
        Self {
            capable: h.capable,
            margin: h.margin,
            limiting_agent: h.limiting_agent.into(),
            limit: h.limit,
            weight: h.weight,
        }
    }
}

impl<T: Real> From<StoredHover<T>> for HoverCapability<T> {
    fn from(h: StoredHover<T>) -> Self {
        Self {
            capable: h.capable,
            margin: h.margin,
            limiting_agent: h.limiting_agent.get(),
            limit: h.limit,
            weight: h.weight,
        }
    }
}

/// A [`HoverCapability`] with the allocation that certifies it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HoverAllocation<T: Real, const N: usize> {
    /// The classification.
    pub capability: HoverCapability<T>,
    /// Agent-frame forces with `M f = w_h` (zero for failed agents).
    pub forces: [Vector3<T>; N],
}

/// [`hover_allocation`]'s classification only.
///
/// ```
/// use tvmd_core::admissible::AdmissibleSet;
/// use tvmd_core::hover::hover_capability;
/// use tvmd_core::{team::presets, FailureMask, TeamConfig};
/// let team: TeamConfig<f64, 4> = presets::a4_inc()?;
/// let set = AdmissibleSet::from_limits(team.limits());
/// let weight = team.mass() * 9.81;
/// let full = hover_capability(&team.effectiveness(&FailureMask::none()), &set, weight);
/// assert!(full.capable && full.margin > 0.9);
/// // Three agents at z = 0: one must give sigma_Tf, so the margin is 0.
/// let degraded = FailureMask::with_failed(&[0])?;
/// let lost = hover_capability(&team.effectiveness(&degraded), &set, weight);
/// assert!(!lost.capable && lost.margin.abs() < 1e-9);
/// # Ok::<(), tvmd_core::ConfigError>(())
/// ```
pub fn hover_capability<T: Real, const N: usize>(
    effectiveness: &Effectiveness<T, N>,
    set: &AdmissibleSet<T>,
    weight: T,
) -> HoverCapability<T> {
    hover_allocation(effectiveness, set, weight).capability
}

/// Classifies the working agents of `effectiveness` (each with admissible set `set`) for the
/// hover wrench `[0, 0, 0, 0, 0, weight]`.
///
/// The allocation minimizes `sum_i w_i ||D^-1 (f_i - c_i)||^2` subject to `M f = w_h`, with
/// `c_i` the centre of `E_f` (mid thrust, centred gimbal) and `D` the box's half-widths in
/// force units: `f = c + D^2 W^-1 M^T (M D^2 W^-1 M^T)^-1 (w_h - M c)`. Starting from `w_i = 1`,
/// Lawson's update `w_i <- w_i (1 - slack_i)` lowers the largest deviation; the best of
/// [`HOVER_ITERATIONS`] rounds is kept. Bounded work, no allocation, no panic path.
pub fn hover_allocation<T: Real, const N: usize>(
    effectiveness: &Effectiveness<T, N>,
    set: &AdmissibleSet<T>,
    weight: T,
) -> HoverAllocation<T, N> {
    let target = Vector6::new(
        T::zero(),
        T::zero(),
        T::zero(),
        T::zero(),
        T::zero(),
        weight,
    );
    let half = |i: &Interval<T>| (i.hi - i.lo) * lit(0.5);
    let mid = |i: &Interval<T>| (i.hi + i.lo) * lit(0.5);
    let centre = GimbalCommand {
        thrust: mid(&set.thrust()),
        eta_x: mid(&set.eta_x()),
        eta_y: mid(&set.eta_y()),
    }
    .force();
    // Half-widths of the box in force units near its centre, relative to the thrust's (a
    // common scale cancels, so huge thrust ranges cannot overflow the Gram matrix).
    let thrust_half = half(&set.thrust());
    let lateral =
        |eta_half: T| (centre.euclidean_norm() * eta_half.sin() / thrust_half).max(eps::<T>());
    let d2 = Vector3::new(
        lateral(half(&set.eta_y())).powi(2),
        lateral(half(&set.eta_x())).powi(2),
        T::one(),
    );
    let d2_matrix = Matrix3::from_diagonal(&d2);
    let rank_six = effectiveness.check_rank().is_ok();
    let blocks = effectiveness.blocks();
    let mut weights = [T::one(); N];
    let mut best: Option<(HoverCapability<T>, [Vector3<T>; N], bool)> = None;
    for _ in 0..HOVER_ITERATIONS {
        let mut gram = Matrix6::zeros();
        let mut produced_by_centre = Vector6::zeros();
        for (block, w) in blocks.iter().zip(&weights) {
            if let Some(b) = block.as_ref() {
                gram += b * d2_matrix * b.transpose() / *w;
                produced_by_centre += b * centre;
            }
        }
        let lambda = GramSolver::new(&gram).solve(&(target - produced_by_centre));
        let mut forces = [Vector3::zeros(); N];
        for ((f, block), w) in forces.iter_mut().zip(blocks).zip(&weights) {
            if let Some(b) = block.as_ref() {
                *f = centre + (b.transpose() * lambda).component_mul(&d2) / *w;
            }
        }
        let (capability, slacks, exact) = classify(effectiveness, set, &forces, target, rank_six);
        // Only an allocation that produces w_h certifies anything; the first round's stands in
        // when none does (a damped solve of a rank-deficient M).
        let better = match best {
            None => true,
            Some((b, _, b_exact)) => {
                (exact && !b_exact) || (exact == b_exact && capability.margin > b.margin)
            }
        };
        if better {
            best = Some((capability, forces, exact));
        }
        // Lawson: weight each agent by its deviation from the centre (1 - slack), floored so
        // a centred agent keeps a finite weight, and renormalized to a largest weight of 1.
        let floor: T = lit(1e-3);
        let mut largest = T::zero();
        for (w, (block, slack)) in weights.iter_mut().zip(blocks.iter().zip(&slacks)) {
            if block.is_some() {
                *w = (*w * (T::one() - *slack)).max(floor);
                largest = largest.max(*w);
            }
        }
        if largest > T::zero() && largest.is_finite() {
            for w in weights.iter_mut() {
                *w = (*w / largest).max(floor);
            }
        }
    }
    let (capability, forces, _) = best.unwrap_or((
        classify(effectiveness, set, &[Vector3::zeros(); N], target, false).0,
        [Vector3::zeros(); N],
        false,
    ));
    HoverAllocation { capability, forces }
}

/// The margin of one allocation, each agent's slack (1 for failed slots), and whether it
/// produces `target` to rounding.
fn classify<T: Real, const N: usize>(
    effectiveness: &Effectiveness<T, N>,
    set: &AdmissibleSet<T>,
    forces: &[Vector3<T>; N],
    target: Vector6<T>,
    rank_six: bool,
) -> (HoverCapability<T>, [T; N], bool) {
    let mut slacks = [T::one(); N];
    let mut tightest: Option<(usize, T, HoverLimit)> = None;
    for (i, ((slack, block), f)) in slacks
        .iter_mut()
        .zip(effectiveness.blocks())
        .zip(forces)
        .enumerate()
    {
        if block.is_none() {
            continue;
        }
        let (value, limit) = agent_slack(set, &GimbalCommand::from_force(f));
        *slack = value;
        if tightest.is_none_or(|(_, m, _)| value < m) {
            tightest = Some((i, value, limit));
        }
    }
    let weight = target.z.max(target.amax());
    let residual = (effectiveness.wrench(forces) - target).amax();
    let scale = weight.max(set.thrust().hi);
    let produces_hover = residual <= scale * eps::<T>() * lit(1e3);
    let (limiting_agent, margin, limit) = match tightest {
        Some((i, m, l)) => (Some(i), m, l),
        None => (None, T::zero(), HoverLimit::MaxThrust),
    };
    let capability = HoverCapability {
        capable: rank_six && produces_hover && margin > hover_margin_tolerance(),
        margin,
        limiting_agent,
        limit,
        weight: target.amax(),
    };
    (capability, slacks, produces_hover)
}

/// The smallest normalized slack of one command in `set`, and the bound it belongs to.
fn agent_slack<T: Real>(set: &AdmissibleSet<T>, cmd: &GimbalCommand<T>) -> (T, HoverLimit) {
    let to_ends = |x: T, i: &Interval<T>| {
        let half = ((i.hi - i.lo) * lit(0.5)).max(eps::<T>());
        ((x - i.lo) / half, (i.hi - x) / half)
    };
    let (above_min, below_max) = to_ends(cmd.thrust, &set.thrust());
    let (x_lo, x_hi) = to_ends(cmd.eta_x, &set.eta_x());
    let (y_lo, y_hi) = to_ends(cmd.eta_y, &set.eta_y());
    [
        (below_max, HoverLimit::MaxThrust),
        (above_min, HoverLimit::MinThrust),
        (x_lo.min(x_hi), HoverLimit::GimbalX),
        (y_lo.min(y_hi), HoverLimit::GimbalY),
    ]
    .into_iter()
    .fold((T::one(), HoverLimit::MaxThrust), |(m, l), (s, k)| {
        if s < m {
            (s, k)
        } else {
            (m, l)
        }
    })
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use crate::team::presets;
    use crate::{FailureMask, TeamConfig};

    fn check<T: Real, const N: usize>(
        team: &TeamConfig<T, N>,
        failed: &[usize],
    ) -> HoverAllocation<T, N> {
        let mask = FailureMask::with_failed(failed).unwrap();
        let set = AdmissibleSet::from_limits(team.limits());
        let weight = team.mass() * lit(presets::GRAVITY);
        hover_allocation(&team.effectiveness(&mask), &set, weight)
    }

    #[test]
    fn a4_inc_minus_any_one_is_not_capable() {
        let team: TeamConfig<f64, 4> = presets::a4_inc().unwrap();
        let full = check(&team, &[]);
        assert!(full.capability.capable, "{:?}", full.capability);
        assert!(
            (full.capability.margin - 1.0).abs() < 1e-9,
            "{:?}",
            full.capability
        );
        for lost in 0..4 {
            let h = check(&team, &[lost]);
            let c = h.capability;
            assert!(!c.capable, "A4-Inc minus {lost}: {c:?}");
            assert!(c.margin.abs() < 1e-9, "A4-Inc minus {lost}: {c:?}");
            // Torque balance fixes the vertical forces: sigma_Tf = m_C g / 2 on two agents.
            let z_max = h.forces.iter().map(|f| f.z).fold(0.0, f64::max);
            assert!((z_max - 13.734).abs() < 1e-9, "{z_max}");
            assert!(c.limit == HoverLimit::MaxThrust || c.limit == HoverLimit::MinThrust);
        }
    }

    #[test]
    fn a6_inc_minus_any_one_is_capable() {
        let team: TeamConfig<f64, 6> =
            presets::ring(6, 0.5, true, presets::paper_limits()).unwrap();
        for lost in 0..6 {
            let h = check(&team, &[lost]);
            let c = h.capability;
            assert!(c.capable && c.margin > 0.1, "A6-Inc minus {lost}: {c:?}");
            // The certificate: M f = w_h and every force inside E_f.
            let u = team
                .effectiveness(&FailureMask::with_failed(&[lost]).unwrap())
                .wrench(&h.forces);
            assert!(
                (u - Vector6::new(0.0, 0.0, 0.0, 0.0, 0.0, c.weight)).amax() < 1e-9,
                "{u:?}"
            );
        }
        // Lawson's rounds equalize the two tight agents (the lost agent's neighbours at high
        // thrust, the opposite one at low thrust): margin 0.4.
        let c = check(&team, &[0]).capability;
        assert!((c.margin - 0.4).abs() < 1e-6, "{c:?}");
    }

    #[test]
    fn f32_agrees() {
        let a4: TeamConfig<f32, 4> = presets::a4_inc().unwrap();
        assert!(check(&a4, &[]).capability.capable);
        let c = check(&a4, &[0]).capability;
        assert!(
            !c.capable && c.margin < hover_margin_tolerance::<f32>(),
            "{c:?}"
        );
        let a6: TeamConfig<f32, 6> = presets::ring(6, 0.5, true, presets::paper_limits()).unwrap();
        let c = check(&a6, &[3]).capability;
        assert!(c.capable && (c.margin - 0.4).abs() < 1e-3, "{c:?}");
    }

    #[test]
    fn rank_deficient_or_overweight_is_not_capable() {
        let a4: TeamConfig<f64, 4> = presets::a4_inc().unwrap();
        let c = check(&a4, &[0, 1]).capability;
        assert!(!c.capable, "{c:?}");
        // Twice sigma_Tf per agent: no allocation within E_f exists.
        let set = AdmissibleSet::from_limits(a4.limits());
        let heavy = hover_capability(
            &a4.effectiveness(&FailureMask::none()),
            &set,
            4.0 * 2.0 * 13.734,
        );
        assert!(!heavy.capable && heavy.margin < 0.0, "{heavy:?}");
        assert_eq!(heavy.limit, HoverLimit::MaxThrust);
    }
}
