//! Constrained allocation as a second-order-cone QP solved by Clarabel (feature `clarabel`);
//! see [`ClarabelAllocator`]. One file per concept, as Clarabel.rs lays out its solver:
//! [`settings`] (defaults), [`report`] (what a solve did), [`cones`] (one agent's constraint
//! geometry), [`qp`] (assembly of `P`, `q`, `A`, `b`), [`polish`] (least squares, shortcut and
//! active-set polish) and [`cache`] (the solver reused between periods). The sequential convex
//! allocator on the exact gimbal set ([`SequentialConvexAllocator`]) adds [`linearize`] (the
//! convexification at a force), [`sequential`] and [`sequential_report`].

mod cache;
mod cones;
mod linearize;
mod polish;
mod qp;
mod report;
mod sequential;
mod sequential_report;
mod settings;

use core::fmt;
use core::marker::PhantomData;
use std::boxed::Box;
use std::time::{Duration, Instant};
use std::vec::Vec;

use ::clarabel::solver::{DefaultSettings, IPSolver};
use nalgebra::Vector3;

use super::{Allocation, AllocationRequest, Allocator, RedistributedPseudoInverse};
#[cfg(doc)]
use crate::agent::admissible::AdmissibleSet;
use crate::foundation::error::{ConfigError, ConfigField};
use crate::foundation::real::{lit, to_f64, Real};
use cache::Cache;
use qp::Problem;
pub use report::{ClarabelStatus, FallbackReason, SolveReport};
pub use sequential::SequentialConvexAllocator;
pub use sequential_report::{SequentialReport, StopReason};
use settings::{default_settings, DEFAULT_LAMBDA};

/// The constrained allocator of `docs/method.md` ("Allocation"): a QP with second-order cones solved by
/// [Clarabel](https://clarabel.org) over the working agents' forces `f` (agent frames):
///
/// ```text
/// minimize   ||W (M f - u_d)||^2 + lambda ||f||^2
/// subject to f_z tan(lo_y) <= f_x <= f_z tan(hi_y)      (eta_y in [lo_y, hi_y], exact)
///            f_z tan(lo_x) <= -f_y <= f_z tan(hi_x)     (eta_x in [lo_x, hi_x], inner bound)
///            f_z >= max(T_lo, 0)                         (thrust >= T_lo, inner bound)
///            ||f|| <= T_hi                               (second-order cone)
/// ```
///
/// per agent, from its [`AdmissibleSet`] `{eta_x in [lo_x, hi_x], eta_y in [lo_y, hi_y], T in
/// [T_lo, T_hi]}`. In the symmetric case of eq. (6) this is the method's pyramid `|f_x| <= f_z
/// tan(sigma_y)`, `|f_y| <= f_z tan(sigma_x)`, `f_z >= 0`, `||f|| <= sigma_Tf`.
///
/// # Why the constraints lie inside the admissible set
///
/// With `a_hat = [cos ex sin ey, -sin ex, cos ex cos ey]`, `eta_y = atan2(f_x, f_z)`: with
/// `f_z >= 0` the `f_x` rows are exactly `eta_y in [lo_y, hi_y]`. `sin eta_x = -f_y / ||f||` and
/// `||f|| >= sqrt(f_y^2 + f_z^2)`, so `|eta_x| <= atan(|f_y| / f_z)` on the side of `-f_y`: the
/// `f_y` rows keep `eta_x` in `[lo_x, hi_x]` when `lo_x <= 0 <= hi_x`. An `eta_x` window that
/// excludes zero (rate-limited sets, [`AdmissibleSet::with_rate_limit`]) is kept exactly by a cone
/// instead: `lo_x > 0` becomes `||f|| <= -f_y / sin(lo_x)`, `hi_x < 0` becomes `||f|| <= f_y /
/// |sin hi_x|`. A minimum thrust `T_lo > 0` is kept by `f_z >= T_lo` (as `||f|| >= f_z`), which is
/// conservative: it forbids tilted forces of thrust `T_lo` whose vertical part is below `T_lo`.
/// Gimbal limits are capped at `pi/2 - 1e-3` in the `tan` rows so the rows stay finite.
///
/// The pyramid gives up the corners of the exact gimbal set, where both angles are near their
/// limits (`|f_y| / f_z` may reach `tan(sigma_x) / cos(sigma_y)` there). So on requests far outside
/// the attainable set the redistributed pseudo-inverse, which works on the exact set, sometimes
/// ends with a smaller wrench error; on average this allocator's is smaller.
///
/// # Solving
///
/// Clarabel gets the lifted form `min ||r||^2 + lambda ||f||^2` subject to `W M f - r = W u_d`
/// and the cones above (`P` diagonal, the wrench only in `b`). Failed agents have no variables
/// and get zero force.
///
/// - **Shortcut** (default on, [`Self::with_shortcut`]): when the unconstrained minimiser (a 6x6
///   solve) satisfies every constraint it is the optimum, and Clarabel is not called.
/// - **Reuse between periods**: the sparsity structure (which agents work, which kind of
///   `eta_x` constraint each has) keys a cache; while it is unchanged the numbers are written
///   into the existing solver with Clarabel's `update_P` / `update_A` / `update_q` / `update_b`
///   (each only when changed; in normal use `b` changes with the wrench, `A` with the sets),
///   reusing Clarabel's settings, equilibration, symbolic KKT factorisation and buffers.
///   Clarabel 0.11 has no warm start (every solve begins at its default interior point), so no
///   iterate is carried over.
/// - **Polish**: an interior-point answer is only accurate to the solver tolerance, and along
///   the null space of `W M` (curvature `lambda`) much less. The agents with an active
///   constraint are held and the others moved towards their closed-form least-squares forces as
///   far as feasible, holding whoever blocks, until none does; this never increases the
///   objective and makes the wrench exact whenever the free agents can produce it.
/// - The answer is clamped onto the constraints (it moves by the solver tolerance) and then
///   through [`AdmissibleSet::saturate`] (round-off), so it satisfies the allocation contract.
///   `saturated[i]` flags an agent with a constraint active within `1e-6` of its maximum thrust.
/// - **Fallback**: if Clarabel ends other than `Solved` or `AlmostSolved` (iteration or time
///   limit, numerical trouble), or the input is not finite, or the request is beyond `1e6`
///   times what the agents can produce ([`FallbackReason::OutOfRange`]), or no agent works, the allocator
///   returns [`RedistributedPseudoInverse`]'s answer with [`Allocation::fallback`] set;
///   [`Self::last_report`] says why.
///
/// `Allocation::rounds` is the number of interior-point iterations (0 after the shortcut; after
/// a fallback, the redistribution rounds). Computes in `f64` whatever `T` is.
///
/// Cloning copies the configuration and the last report but not the solver, which the clone
/// rebuilds on its first call.
///
/// ```
/// use tvmd_core::nalgebra::Vector6;
/// use tvmd_core::{team::presets, AdmissibleSet, AllocationRequest, Allocator, FailureMask};
/// use tvmd_core::ClarabelAllocator;
/// let team = presets::a4_inc::<f64, 4>()?;
/// let effectiveness = team.effectiveness(&FailureMask::none());
/// let sets = [AdmissibleSet::from_limits(team.limits()); 4];
/// let mut allocator = ClarabelAllocator::new(0.0, None)?;
/// allocator.configure(&effectiveness);
/// // Hover: the weight shared by the four agents, exactly.
/// let wrench = Vector6::new(0.0, 0.0, 0.0, 0.0, 0.0, team.mass() * 9.81);
/// let out = allocator.allocate(&AllocationRequest { effectiveness: &effectiveness, sets: &sets, wrench });
/// assert!(out.e_f < 1e-12 && out.saturated_count() == 0);
/// # Ok::<(), tvmd_core::ConfigError>(())
/// ```
pub struct ClarabelAllocator<T: Real, const N: usize> {
    lambda: f64,
    weights: [f64; 6],
    // Boxed: both are large and the allocator sits in enums (`AnyAllocator`).
    settings: Box<DefaultSettings<f64>>,
    shortcut: bool,
    cache: Option<Box<Cache<N>>>,
    report: Option<SolveReport>,
    _real: PhantomData<T>,
}

impl<T: Real, const N: usize> ClarabelAllocator<T, N> {
    /// An allocator with regularisation `lambda >= 0` (finite) and wrench weights `W =
    /// diag(weights)` (`[torque; force]` order, each positive and finite; `None`: identity).
    ///
    /// Errors with [`ConfigError::Parameter`] naming [`ConfigField::ClarabelLambda`] or [`ConfigField::ClarabelWeights`].
    pub fn new(lambda: T, weights: Option<[T; 6]>) -> Result<Self, ConfigError> {
        let lambda = to_f64(lambda);
        if !lambda.is_finite() || lambda < 0.0 {
            return Err(ConfigError::Parameter {
                field: ConfigField::ClarabelLambda,
            });
        }
        let mut w = [1.0; 6];
        if let Some(given) = weights {
            for (slot, value) in w.iter_mut().zip(given) {
                let value = to_f64(value);
                if !value.is_finite() || value <= 0.0 {
                    return Err(ConfigError::Parameter {
                        field: ConfigField::ClarabelWeights,
                    });
                }
                *slot = value;
            }
        }
        Ok(Self {
            lambda,
            weights: w,
            ..Self::default()
        })
    }

    /// Clarabel's iteration limit (default 100). Reaching it makes the call fall back to the
    /// redistributed pseudo-inverse.
    pub fn with_max_iterations(mut self, max_iterations: u32) -> Self {
        self.settings.max_iter = max_iterations;
        self.cache = None;
        self
    }

    /// Clarabel's absolute and relative duality-gap and feasibility tolerance (default `1e-9`).
    ///
    /// Errors with [`ConfigError::Parameter`] naming [`ConfigField::ClarabelTolerance`] unless positive and
    /// finite.
    pub fn with_tolerance(mut self, tolerance: T) -> Result<Self, ConfigError> {
        let tol = to_f64(tolerance);
        if !tol.is_finite() || tol <= 0.0 {
            return Err(ConfigError::Parameter {
                field: ConfigField::ClarabelTolerance,
            });
        }
        self.settings.tol_gap_abs = tol;
        self.settings.tol_gap_rel = tol;
        self.settings.tol_feas = tol;
        self.cache = None;
        Ok(self)
    }

    /// Clarabel's time limit per solve (default none). Reaching it makes the call fall back to
    /// the redistributed pseudo-inverse. Clarabel 0.11 counts its one-off setup time (tens of
    /// microseconds, spent when the structure changes) in every solve against this limit.
    pub fn with_time_limit(mut self, limit: Duration) -> Self {
        self.settings.time_limit = limit.as_secs_f64();
        self.cache = None;
        self
    }

    /// Whether to skip Clarabel when the unconstrained minimiser already satisfies every
    /// constraint (default `true`; the answer is the same, exactly instead of to the solver
    /// tolerance). `false` always calls the solver (to measure it, say).
    pub fn with_shortcut(mut self, shortcut: bool) -> Self {
        self.shortcut = shortcut;
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

    /// What happened in the last call (`None` before the first).
    pub fn last_report(&self) -> Option<&SolveReport> {
        self.report.as_ref()
    }

    /// Updates or rebuilds the solver, solves, and polishes the solution.
    fn solve(
        &mut self,
        problem: &Problem<N>,
        report: &mut SolveReport,
    ) -> Result<Vec<[f64; 3]>, FallbackReason> {
        // Reuse the solver when the structure is unchanged, else (re)build it.
        let reused = match self.cache.as_mut() {
            Some(cache) if cache.key == problem.key => cache.update(problem).is_ok(),
            _ => false,
        };
        if !reused {
            report.rebuilt = true;
            self.cache = Cache::build(problem, &self.settings).map(Box::new);
        }
        let cache = self.cache.as_mut().ok_or(FallbackReason::Setup)?;
        let solving = Instant::now();
        cache.solver.solve();
        report.solver_time = solving.elapsed();
        let solution = &cache.solver.solution;
        report.status = solution.status;
        report.iterations = solution.iterations;
        if !matches!(
            solution.status,
            ClarabelStatus::Solved | ClarabelStatus::AlmostSolved
        ) {
            return Err(FallbackReason::Status);
        }
        if solution.x.iter().any(|x| !x.is_finite()) {
            return Err(FallbackReason::NonFiniteSolution);
        }
        let forces: Vec<[f64; 3]> = problem
            .agents
            .iter()
            .zip(solution.x.chunks_exact(3))
            .map(|(agent, x)| {
                let f = <[f64; 3]>::try_from(x).unwrap_or([0.0; 3]);
                agent.bounds.repair(f).0
            })
            .collect();
        match problem.polish(&forces) {
            Some(polished) => {
                report.polished = true;
                Ok(polished)
            }
            None => Ok(forces),
        }
    }

    fn fallback(
        &mut self,
        request: &AllocationRequest<'_, T, N>,
        report: SolveReport,
        started: Instant,
    ) -> Allocation<T, N> {
        let mut allocation = RedistributedPseudoInverse.allocate(request);
        allocation.fallback = true;
        let objective = self.objective(request, &allocation.forces);
        self.report = Some(SolveReport {
            objective,
            wall_time: started.elapsed(),
            ..report
        });
        allocation
    }

    /// `||W (M f - u)||^2 + lambda ||f||^2` in `f64` for the report.
    fn objective(&self, request: &AllocationRequest<'_, T, N>, forces: &[Vector3<T>; N]) -> f64 {
        let error = request.wrench - request.effectiveness.wrench(forces);
        let weighted: f64 = error
            .iter()
            .zip(&self.weights)
            .map(|(e, w)| (to_f64(*e) * w).powi(2))
            .sum();
        let norm: f64 = request
            .effectiveness
            .blocks()
            .iter()
            .zip(forces)
            .filter(|(b, _)| b.is_some())
            .map(|(_, f)| to_f64(f.norm_squared()))
            .sum();
        weighted + self.lambda * norm
    }
}

/// Whether every component of the request is at most `1e6` times the largest the working agents
/// can produce, `sum_i sigma_Tf,i 3 max |M_i|` (a non-finite request passes here and falls back
/// as non-finite input).
fn within_range<T: Real, const N: usize>(request: &AllocationRequest<'_, T, N>) -> bool {
    let reach: f64 = request
        .effectiveness
        .blocks()
        .iter()
        .zip(request.sets)
        .filter_map(|(b, set)| b.as_ref().map(|b| to_f64(set.thrust().hi * b.amax()) * 3.0))
        .sum();
    let largest = request
        .wrench
        .iter()
        .fold(0.0_f64, |m, x| m.max(to_f64(x.abs())));
    // No working agent (`reach = 0`) falls back as such, after this check.
    reach == 0.0 || largest <= reach * 1e6 || !largest.is_finite()
}

impl<T: Real, const N: usize> Default for ClarabelAllocator<T, N> {
    /// `lambda = 1e-6`, `W = I`, 100 iterations, tolerance `1e-9`, no time limit.
    fn default() -> Self {
        Self {
            lambda: DEFAULT_LAMBDA,
            weights: [1.0; 6],
            settings: Box::new(default_settings()),
            shortcut: true,
            cache: None,
            report: None,
            _real: PhantomData,
        }
    }
}

impl<T: Real, const N: usize> Clone for ClarabelAllocator<T, N> {
    fn clone(&self) -> Self {
        Self {
            lambda: self.lambda,
            weights: self.weights,
            settings: self.settings.clone(),
            shortcut: self.shortcut,
            cache: None,
            report: self.report,
            _real: PhantomData,
        }
    }
}

impl<T: Real, const N: usize> fmt::Debug for ClarabelAllocator<T, N> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("ClarabelAllocator")
            .field("lambda", &self.lambda)
            .field("weights", &self.weights)
            .field("max_iter", &self.settings.max_iter)
            .field("tolerance", &self.settings.tol_feas)
            .field("time_limit", &self.settings.time_limit)
            .field("shortcut", &self.shortcut)
            .field("solver_built", &self.cache.is_some())
            .field("last_report", &self.report)
            .finish()
    }
}

impl<T: Real, const N: usize> Allocator<T, N> for ClarabelAllocator<T, N> {
    fn allocate(&mut self, request: &AllocationRequest<'_, T, N>) -> Allocation<T, N> {
        let started = Instant::now();
        let mut report = SolveReport {
            status: ClarabelStatus::Unsolved,
            iterations: 0,
            solver_time: Duration::ZERO,
            wall_time: Duration::ZERO,
            objective: f64::NAN,
            rebuilt: false,
            unconstrained: false,
            polished: false,
            fallback: None,
        };
        if !within_range(request) {
            report.fallback = Some(FallbackReason::OutOfRange);
            return self.fallback(request, report, started);
        }
        let Some(problem) = Problem::new(request, &self.weights, self.lambda) else {
            report.fallback = Some(FallbackReason::NonFiniteInput);
            return self.fallback(request, report, started);
        };
        if problem.agents.is_empty() {
            // Nothing works: the fallback returns zero forces.
            report.fallback = Some(FallbackReason::NoAgents);
            return self.fallback(request, report, started);
        }

        let (forces, iterations) = match self.shortcut.then(|| problem.unconstrained()).flatten() {
            Some(forces) => {
                report.unconstrained = true;
                (forces, 0)
            }
            None => match self.solve(&problem, &mut report) {
                Ok(forces) => (forces, report.iterations),
                Err(reason) => {
                    report.fallback = Some(reason);
                    return self.fallback(request, report, started);
                }
            },
        };

        let mut out = [Vector3::zeros(); N];
        let mut saturated = [false; N];
        for (agent, f) in problem.agents.iter().zip(&forces) {
            let ([fx, fy, fz], active) = agent.bounds.repair(*f);
            let force = Vector3::new(lit(fx), lit(fy), lit(fz));
            if let (Some(slot), Some(sat), Some(set)) = (
                out.get_mut(agent.slot),
                saturated.get_mut(agent.slot),
                request.sets.get(agent.slot),
            ) {
                *slot = set.saturate(&force);
                *sat = active;
            }
        }
        let allocation = Allocation::from_forces(request, out, iterations, saturated);
        report.objective = self.objective(request, &allocation.forces);
        report.wall_time = started.elapsed();
        self.report = Some(report);
        allocation
    }

    fn name(&self) -> &'static str {
        super::names::CLARABEL
    }
}
