//! [`SequentialConvexAllocator`]: the constrained allocation on the exact gimbal set by
//! sequential convex steps (the convex-concave procedure), each a Clarabel QP.

use core::fmt;
use core::marker::PhantomData;
use std::boxed::Box;
use std::time::{Duration, Instant};
use std::vec::Vec;

use ::clarabel::solver::DefaultSettings;
use nalgebra::Vector3;

use super::cache::Cache;
use super::cones::lerp;
use super::linearize::{solve, SolveRecord};
use super::qp::Problem;
use super::report::{ClarabelStatus, FallbackReason};
use super::sequential_report::{SequentialReport, StopReason};
use super::{within_range, ClarabelAllocator};
#[cfg(doc)]
use crate::agent::admissible::AdmissibleSet;
use crate::allocation::RedistributedPseudoInverse;
use crate::allocation::{outside, Allocation, AllocationRequest, Allocator};
use crate::foundation::error::{ConfigError, ConfigField};
use crate::foundation::linalg::norm;
use crate::foundation::real::{eps, lit, to_f64, Real};

/// Default step limit.
const DEFAULT_MAX_STEPS: u32 = 5;
/// Default relative decrease of the objective under which the steps stop.
const DEFAULT_DECREASE: f64 = 1e-6;
/// Relative weighted wrench error (of `||W u_d||`) under which the forces count as exact.
const EXACT: f64 = 1e-9;

/// Constrained allocation on the exact gimbal set `E_f` (eq. 6) by sequential convex steps
/// (the convex-concave procedure), each a second-order-cone QP solved by
/// [Clarabel](https://clarabel.org) (feature `clarabel`):
///
/// ```text
/// minimize   J(f) = ||W (M f - u_d)||^2 + lambda ||f||^2
/// subject to f_i in C_i(f_i^k)                      (step k + 1, every working agent i)
/// ```
///
/// where `C_i(f0)` is the exact set with its concave constraints replaced by half-spaces
/// through `f0` that lie inside them. With `a = (f0_x, f0_z) / ||(f0_x, f0_z)||` (the vertical
/// plane of `f0`) and `f0_hat = f0 / ||f0||`:
///
/// ```text
/// f_z tan(lo_y) <= f_x <= f_z tan(hi_y)                       (eta_y, exact)
/// tan(lo_x) a . (f_x, f_z) <= -f_y <= tan(hi_x) a . (f_x, f_z)  (eta_x, inner; lo_x <= 0 <= hi_x)
/// f0_hat . f >= T_lo        (T >= T_lo > 0, inner: the tangent of ||f|| >= T_lo; f_z >= 0 if T_lo = 0)
/// ||f|| <= T_hi                                               (second-order cone, exact)
/// ```
///
/// An `eta_x` window that excludes zero keeps its exact cone, as in [`ClarabelAllocator`]. The
/// `eta_x` row holds because `||f|| >= ||(a . (f_x, f_z), f_y)||`; it is tight on the vertical
/// plane through `a`, so unlike the pyramid (`a = z`, [`ClarabelAllocator`]) it contains the
/// corners of the gimbal set where both angles are at their limits.
///
/// # Steps and stop rule
///
/// 1. Start from the [`RedistributedPseudoInverse`]'s forces `f^0` (always admissible), or from
///    the previous period's when they are admissible for this request's sets and have the lower
///    `J` ([`Self::with_warm_start`], default on).
/// 2. Linearize at `f^k`, solve the QP, project its answer onto the linear rows (it violates
///    them by the solver tolerance), step from `f^k` towards it as far as every agent stays in
///    `C_i(f^k)`, and polish (the active-set least squares of [`ClarabelAllocator`]).
/// 3. Check the forces with [`AdmissibleSet::saturate`]: moving by more than round-off
///    (`max(1e-9, 1e3 eps) T_hi`) rejects the step. Take the step if `J` did not increase.
///
/// An admissible `f^k` lies in `C(f^k)`, so every step starts feasible and `J` is non-increasing
/// (each QP's optimum is at most `J(f^k)`); a step that would increase it is not taken. The
/// steps stop at the first of: weighted wrench error `<= 1e-9 ||W u_d||` ([`StopReason::Exact`]),
/// a relative decrease of `J` below [`Self::with_decrease_tolerance`] (default `1e-6`) or a
/// step not taken ([`StopReason::Converged`]), [`Self::with_max_steps`] steps (default 5), a
/// solver failure or a rejected step (the best forces so far are returned).
///
/// The returned forces have `J` at most the start's. With the default `lambda = 0`, `J` is the
/// weighted wrench error, so the allocation is never worse than the redistributed
/// pseudo-inverse's in it (with `W = I`: `wrench_error` never larger); with `lambda > 0` never
/// worse in `J`. (`lambda = 0` because any `lambda > 0` trades an error of about
/// `lambda / sigma_min(W M)^2` of the request for a smaller force, which is not exact.)
///
/// `Allocation::rounds` is the number of convex steps solved (0 when the start was exact);
/// `fallback` is set when the input made solving impossible (no working agent, non-finite
/// input, a request beyond `1e6` times the agents' reach: the redistributed pseudo-inverse's
/// answer is returned) or the first step's solver failed. Computes in `f64` whatever `T` is;
/// the solver is kept between steps and periods and updated in place (one structure).
///
/// ```
/// use tvmd_core::nalgebra::Vector6;
/// use tvmd_core::{team::presets, AdmissibleSet, AllocationRequest, Allocator, FailureMask};
/// use tvmd_core::allocation::SequentialConvexAllocator;
/// let team = presets::a4_inc::<f64, 4>()?;
/// let effectiveness = team.effectiveness(&FailureMask::none());
/// let sets = [AdmissibleSet::from_limits(team.limits()); 4];
/// let mut allocator = SequentialConvexAllocator::default();
/// let wrench = Vector6::new(0.0, 0.0, 0.0, 0.0, 0.0, team.mass() * 9.81);
/// let out = allocator.allocate(&AllocationRequest { effectiveness: &effectiveness, sets: &sets, wrench });
/// assert!(out.e_f < 1e-12 && out.rounds == 0);
/// # Ok::<(), tvmd_core::ConfigError>(())
/// ```
pub struct SequentialConvexAllocator<T: Real, const N: usize> {
    lambda: f64,
    weights: [f64; 6],
    // Boxed: both are large and the allocator sits in enums (`AnyAllocator`).
    settings: Box<DefaultSettings<f64>>,
    max_steps: u32,
    decrease: f64,
    warm_start: bool,
    cache: Option<Box<Cache<N>>>,
    previous: Option<[Vector3<T>; N]>,
    report: Option<SequentialReport>,
    _real: PhantomData<T>,
}

impl<T: Real, const N: usize> SequentialConvexAllocator<T, N> {
    /// An allocator with regularisation `lambda >= 0` (finite) and wrench weights `W =
    /// diag(weights)` (`[torque; force]` order, each positive and finite; `None`: identity).
    ///
    /// Errors as [`ClarabelAllocator::new`].
    pub fn new(lambda: T, weights: Option<[T; 6]>) -> Result<Self, ConfigError> {
        let checked = ClarabelAllocator::<T, N>::new(lambda, weights)?;
        Ok(Self {
            lambda: checked.lambda,
            weights: checked.weights,
            ..Self::default()
        })
    }

    /// The step limit (default 5; 0 returns the start).
    pub fn with_max_steps(mut self, max_steps: u32) -> Self {
        self.max_steps = max_steps;
        self
    }

    /// The relative decrease of `J` under which the steps stop (default `1e-6`).
    ///
    /// Errors with [`ConfigError::Parameter`] naming [`ConfigField::ClarabelTolerance`] unless
    /// non-negative and finite.
    pub fn with_decrease_tolerance(mut self, tolerance: T) -> Result<Self, ConfigError> {
        let tol = to_f64(tolerance);
        if !tol.is_finite() || tol < 0.0 {
            return Err(ConfigError::Parameter {
                field: ConfigField::ClarabelTolerance,
            });
        }
        self.decrease = tol;
        Ok(self)
    }

    /// Whether to start from the previous period's forces when they are admissible and better
    /// than the redistributed pseudo-inverse's (default `true`).
    pub fn with_warm_start(mut self, warm_start: bool) -> Self {
        self.warm_start = warm_start;
        self
    }

    /// Clarabel's iteration limit per step (default 100); reaching it stops the steps.
    pub fn with_max_iterations(mut self, max_iterations: u32) -> Self {
        self.settings.max_iter = max_iterations;
        self.cache = None;
        self
    }

    /// The regularisation `lambda`.
    pub fn lambda(&self) -> T {
        lit(self.lambda)
    }

    /// The wrench weights (diagonal of `W`).
    pub fn weights(&self) -> [T; 6] {
        self.weights.map(lit)
    }

    /// What happened in the last call (`None` before the first and after a reset).
    pub fn last_report(&self) -> Option<&SequentialReport> {
        self.report.as_ref()
    }

    /// The allocation of `forces` (agent order) if each is admissible to round-off (what
    /// [`AdmissibleSet::saturate`] moves), with `J` of the returned forces.
    fn admissible(
        request: &AllocationRequest<'_, T, N>,
        problem: &Problem<N>,
        forces: &[[f64; 3]],
    ) -> Option<(Allocation<T, N>, f64)> {
        let round_off = (1e3 * to_f64(eps::<T>())).max(1e-9);
        let mut out = [Vector3::zeros(); N];
        let mut saturated = [false; N];
        for (agent, f) in problem.agents.iter().zip(forces) {
            let [fx, fy, fz] = *f;
            let force = Vector3::new(lit(fx), lit(fy), lit(fz));
            let set = request.sets.get(agent.slot)?;
            let kept = set.saturate(&force);
            let moved = to_f64(norm(&(kept - force)));
            // A NaN distance rejects too.
            if moved.is_nan() || moved > round_off * agent.bounds.thrust_hi {
                return None;
            }
            *out.get_mut(agent.slot)? = kept;
            *saturated.get_mut(agent.slot)? = agent.bounds.linearized_at(*f).active(*f);
        }
        let objective = problem.objective(&gather(problem, &out));
        Some((
            Allocation::from_forces(request, out, 0, saturated),
            objective,
        ))
    }

    /// The previous period's forces, if admissible for `request` (zero for failed agents).
    fn previous_for(&self, request: &AllocationRequest<'_, T, N>) -> Option<[Vector3<T>; N]> {
        let previous = self.previous.filter(|_| self.warm_start)?;
        let fits = request
            .effectiveness
            .blocks()
            .iter()
            .zip(request.sets)
            .zip(&previous)
            .all(|((block, set), f)| match block.as_ref() {
                Some(_) => !outside(set, f),
                None => *f == Vector3::zeros(),
            });
        fits.then_some(previous)
    }
}

/// The forces of the working agents in agent order, in `f64`.
fn gather<T: Real, const N: usize>(
    problem: &Problem<N>,
    forces: &[Vector3<T>; N],
) -> Vec<[f64; 3]> {
    problem
        .agents
        .iter()
        .map(|a| {
            forces
                .get(a.slot)
                .map_or([0.0; 3], |f| [to_f64(f.x), to_f64(f.y), to_f64(f.z)])
        })
        .collect()
}

impl<T: Real, const N: usize> Default for SequentialConvexAllocator<T, N> {
    /// `lambda = 0`, `W = I`, 5 steps, decrease tolerance `1e-6`, warm start on, Clarabel's
    /// settings as [`ClarabelAllocator`]'s (100 iterations, tolerance `1e-9`).
    fn default() -> Self {
        let base = ClarabelAllocator::<T, N>::default();
        Self {
            lambda: 0.0,
            weights: [1.0; 6],
            settings: base.settings,
            max_steps: DEFAULT_MAX_STEPS,
            decrease: DEFAULT_DECREASE,
            warm_start: true,
            cache: None,
            previous: None,
            report: None,
            _real: PhantomData,
        }
    }
}

impl<T: Real, const N: usize> Clone for SequentialConvexAllocator<T, N> {
    /// Copies the configuration, the previous forces and the report; the clone rebuilds the
    /// solver on its first step.
    fn clone(&self) -> Self {
        Self {
            lambda: self.lambda,
            weights: self.weights,
            settings: self.settings.clone(),
            max_steps: self.max_steps,
            decrease: self.decrease,
            warm_start: self.warm_start,
            cache: None,
            previous: self.previous,
            report: self.report,
            _real: PhantomData,
        }
    }
}

impl<T: Real, const N: usize> fmt::Debug for SequentialConvexAllocator<T, N> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("SequentialConvexAllocator")
            .field("lambda", &self.lambda)
            .field("weights", &self.weights)
            .field("max_steps", &self.max_steps)
            .field("decrease", &self.decrease)
            .field("warm_start", &self.warm_start)
            .field("max_iter", &self.settings.max_iter)
            .field("solver_built", &self.cache.is_some())
            .field("last_report", &self.report)
            .finish()
    }
}

impl<T: Real, const N: usize> Allocator<T, N> for SequentialConvexAllocator<T, N> {
    fn reset(&mut self) {
        self.previous = None;
        self.report = None;
    }

    fn allocate(&mut self, request: &AllocationRequest<'_, T, N>) -> Allocation<T, N> {
        let started = Instant::now();
        let start = RedistributedPseudoInverse.allocate(request);
        let mut report = SequentialReport {
            steps: 0,
            accepted: 0,
            iterations: 0,
            status: ClarabelStatus::Unsolved,
            stop: StopReason::NotSolved,
            warm_start: false,
            start_objective: f64::NAN,
            objective: f64::NAN,
            solver_time: Duration::ZERO,
            wall_time: Duration::ZERO,
            rebuilt: false,
            fallback: None,
        };
        let problem = if within_range(request) {
            match Problem::new(request, &self.weights, self.lambda) {
                None => Err(FallbackReason::NonFiniteInput),
                Some(p) if p.agents.is_empty() => Err(FallbackReason::NoAgents),
                Some(p) => Ok(p),
            }
        } else {
            Err(FallbackReason::OutOfRange)
        };
        let mut problem = match problem {
            Ok(p) => p,
            Err(reason) => {
                report.fallback = Some(reason);
                report.wall_time = started.elapsed();
                self.report = Some(report);
                self.previous = None;
                return Allocation {
                    fallback: true,
                    ..start
                };
            }
        };

        let mut best = start;
        let mut current = gather(&problem, &start.forces);
        let mut objective = problem.objective(&current);
        if let Some(previous) = self.previous_for(request) {
            let warm = gather(&problem, &previous);
            let warm_objective = problem.objective(&warm);
            if warm_objective < objective {
                // Checked admissible as they are: kept unchanged (no second saturation).
                let mut saturated = [false; N];
                for (agent, f) in problem.agents.iter().zip(&warm) {
                    if let Some(s) = saturated.get_mut(agent.slot) {
                        *s = agent.bounds.linearized_at(*f).active(*f);
                    }
                }
                best = Allocation::from_forces(request, previous, 0, saturated);
                (current, objective) = (warm, warm_objective);
                report.warm_start = true;
            }
        }
        report.start_objective = objective;

        let scale = problem.target.norm();
        let mut record = SolveRecord {
            status: ClarabelStatus::Unsolved,
            iterations: 0,
            solver_time: Duration::ZERO,
            rebuilt: false,
        };
        let mut stalled = false;
        let stop = loop {
            if problem.residual(&current) <= EXACT * scale {
                break StopReason::Exact;
            }
            if stalled {
                break StopReason::Converged;
            }
            if report.steps >= self.max_steps {
                break StopReason::StepLimit;
            }
            report.steps += 1;
            problem.linearize(&current);
            // `current` is admissible, so inside its own linearization; the projection only
            // removes the round-off of a start computed in `T`.
            let from: Vec<[f64; 3]> = problem
                .agents
                .iter()
                .zip(&current)
                .map(|(a, f)| a.bounds.project(*f))
                .collect();
            // `objective > 0`: a zero objective has a zero wrench error, caught above.
            let scaled = problem.scaled(objective.sqrt().recip());
            let Ok(solution) = solve(&mut self.cache, &self.settings, &scaled, &mut record) else {
                break StopReason::Solver;
            };
            let to: Vec<[f64; 3]> = problem
                .agents
                .iter()
                .zip(&solution)
                .map(|(a, f)| a.bounds.project(*f))
                .collect();
            // The largest common step inside every agent's (convex) linearized set: `J` is
            // convex along it, so at most the larger of its ends.
            let t = problem
                .agents
                .iter()
                .zip(from.iter().zip(&to))
                .fold(1.0, |t, (a, (f, x))| a.bounds.max_step(*f, *x, t));
            let stepped: Vec<[f64; 3]> =
                from.iter().zip(&to).map(|(f, x)| lerp(*f, *x, t)).collect();
            let candidate = problem.polish(&stepped).unwrap_or(stepped);
            let Some((allocation, j)) = Self::admissible(request, &problem, &candidate) else {
                break StopReason::Rejected;
            };
            if j > objective {
                break StopReason::Converged;
            }
            report.accepted += 1;
            stalled = objective - j <= self.decrease * objective;
            (best, current, objective) = (allocation, candidate, j);
        };

        report.stop = stop;
        report.status = record.status;
        report.iterations = record.iterations;
        report.solver_time = record.solver_time;
        report.rebuilt = record.rebuilt;
        report.objective = objective;
        best.rounds = report.steps;
        best.fallback = stop == StopReason::Solver && report.accepted == 0 && !report.warm_start;
        self.previous = Some(best.forces);
        report.wall_time = started.elapsed();
        self.report = Some(report);
        best
    }

    fn name(&self) -> &'static str {
        super::super::names::CLARABEL_SEQUENTIAL
    }
}
