//! Constrained allocation as a second-order-cone QP solved by Clarabel (feature `clarabel`);
//! see [`ClarabelAllocator`].

use core::fmt;
use core::marker::PhantomData;
use std::boxed::Box;
use std::time::{Duration, Instant};
use std::vec::Vec;

use ::clarabel::algebra::CscMatrix;
use ::clarabel::solver::{DefaultSettings, DefaultSolver, IPSolver, SupportedConeT};
use nalgebra::{Matrix6, Matrix6x3, Vector3, Vector6};

use super::{solve_gram, Allocation, AllocationRequest, Allocator, RedistributedPseudoInverse};
use crate::admissible::AdmissibleSet;
use crate::error::{ConfigError, ConfigField};
use crate::linalg::weighted_gram;
use crate::real::{lit, to_f64, Real};

/// Clarabel's termination status (re-exported from `clarabel::solver::SolverStatus`).
pub use ::clarabel::solver::SolverStatus as ClarabelStatus;

/// Largest gimbal angle used in the `tan` rows (rad): `pi/2 - 1e-3`, `tan` about 1000.
const MAX_TAN_ANGLE: f64 = core::f64::consts::FRAC_PI_2 - 1e-3;
/// Relative slack (of the agent's maximum thrust) under which a constraint counts as active.
const ACTIVE_TOL: f64 = 1e-6;
/// Relative (of the maximum thrust) violation below which a closed-form answer counts as
/// feasible; [`Bounds::repair`] then removes it.
const FEASIBLE_TOL: f64 = 1e-12;
/// Default regularisation `lambda`.
const DEFAULT_LAMBDA: f64 = 1e-6;
/// Default Clarabel gap and feasibility tolerance.
const DEFAULT_TOLERANCE: f64 = 1e-9;
/// Default Clarabel iteration limit.
const DEFAULT_MAX_ITER: u32 = 100;

/// Why [`ClarabelAllocator`] fell back to the redistributed pseudo-inverse.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FallbackReason {
    /// No agent works (every force is zero).
    NoAgents,
    /// The wrench, an effectiveness block or a set bound was NaN or infinite.
    NonFiniteInput,
    /// Clarabel refused the problem or its settings (should not happen; a bug report).
    Setup,
    /// Clarabel stopped without a solution; [`SolveReport::status`] says how.
    Status,
    /// Clarabel reported a solution containing NaN or infinity.
    NonFiniteSolution,
}

impl fmt::Display for FallbackReason {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::NoAgents => "no working agent",
            Self::NonFiniteInput => "non-finite input",
            Self::Setup => "solver setup failed",
            Self::Status => "solver did not converge",
            Self::NonFiniteSolution => "non-finite solution",
        })
    }
}

/// What happened in the last [`ClarabelAllocator::allocate`] call.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolveReport {
    /// Clarabel's status (`Unsolved` when the solver did not run).
    pub status: ClarabelStatus,
    /// Interior-point iterations (0 when the solver did not run).
    pub iterations: u32,
    /// Wall time of Clarabel's `solve()` alone (not the data update or rebuild). Measured
    /// here: Clarabel's own `solve_time` also counts its one-off setup, in every solve.
    pub solver_time: Duration,
    /// Wall time of the whole call: data update (or rebuild), solve and post-processing.
    pub wall_time: Duration,
    /// `||W (M f - u_d)||^2 + lambda ||f||^2` at the returned forces (also after a fallback).
    pub objective: f64,
    /// The solver was (re)built in this call: first call, or the set of working agents or the
    /// kind of an `eta_x` constraint changed. Otherwise the data were updated in place.
    pub rebuilt: bool,
    /// The unconstrained minimiser (a 6x6 solve) satisfied every constraint, so it is the
    /// optimum and Clarabel was not called (status `Unsolved`, 0 iterations).
    pub unconstrained: bool,
    /// The active-set polish replaced Clarabel's answer (see [`ClarabelAllocator`], "Solving").
    pub polished: bool,
    /// `Some` when the returned allocation is the redistributed pseudo-inverse's.
    pub fallback: Option<FallbackReason>,
}

impl SolveReport {
    /// Whether the allocation fell back to the redistributed pseudo-inverse.
    pub fn is_fallback(&self) -> bool {
        self.fallback.is_some()
    }

    /// Whether the returned forces are the QP's optimum (to the solver tolerance): the
    /// unconstrained minimiser was feasible, or Clarabel reported `Solved` / `AlmostSolved`.
    pub fn is_optimal(&self) -> bool {
        !self.is_fallback()
            && (self.unconstrained
                || matches!(
                    self.status,
                    ClarabelStatus::Solved | ClarabelStatus::AlmostSolved
                ))
    }
}

impl fmt::Display for SolveReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.unconstrained {
            return write!(
                f,
                "clarabel not called: unconstrained minimum admissible ({:.1} us, objective {:e})",
                self.wall_time.as_secs_f64() * 1e6,
                self.objective
            );
        }
        write!(
            f,
            "clarabel {} in {} iterations, {:.1} us solver / {:.1} us total, objective {:e}{}",
            self.status,
            self.iterations,
            self.solver_time.as_secs_f64() * 1e6,
            self.wall_time.as_secs_f64() * 1e6,
            self.objective,
            if self.rebuilt { ", rebuilt" } else { "" }
        )?;
        if self.polished {
            f.write_str(", polished")?;
        }
        if let Some(reason) = self.fallback {
            write!(
                f,
                "; fell back to the redistributed pseudo-inverse ({reason})"
            )?;
        }
        Ok(())
    }
}

/// The constrained allocator of the SPEC ("Allocation"): a QP with second-order cones solved by
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
/// [T_lo, T_hi]}`. In the symmetric case of eq. (6) this is the SPEC's pyramid `|f_x| <= f_z
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
///   limit, numerical trouble), or the input is not finite, or no agent works, the allocator
///   returns [`RedistributedPseudoInverse`]'s answer with [`Allocation::fallback`] set;
///   [`Self::last_report`] says why.
///
/// `Allocation::rounds` is the number of interior-point iterations (0 after the shortcut; after
/// a fallback, the redistribution rounds). Computes in `f64` whatever `T` is.
///
/// Cloning copies the configuration and the last report but not the solver, which the clone
/// rebuilds on its first call.
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
        super::any::CLARABEL
    }
}

/// Quiet Clarabel settings with data updates allowed (no presolve, no dropped zeros).
fn default_settings() -> DefaultSettings<f64> {
    DefaultSettings {
        verbose: false,
        max_iter: DEFAULT_MAX_ITER,
        tol_gap_abs: DEFAULT_TOLERANCE,
        tol_gap_rel: DEFAULT_TOLERANCE,
        tol_feas: DEFAULT_TOLERANCE,
        presolve_enable: false,
        input_sparse_dropzeros: false,
        max_threads: 1,
        ..DefaultSettings::default()
    }
}

/// One side of the `eta_x` window.
#[derive(Clone, Copy, Debug, PartialEq)]
enum XBound {
    /// The linear row with `tan` of the bound (window side containing zero).
    Tan(f64),
    /// The cone `||f|| <= s f_y` (`s = -1 / sin(bound)` for the upper side, `1 / sin` for the
    /// lower side, always with the sign that makes it a cone on `f_y` or `-f_y`).
    Cone(f64),
}

impl XBound {
    fn is_cone(self) -> bool {
        matches!(self, Self::Cone(_))
    }
}

/// One agent's constraint data in `f64`.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Bounds {
    tan_y_lo: f64,
    tan_y_hi: f64,
    /// `eta_x <= hi_x`.
    x_hi: XBound,
    /// `eta_x >= lo_x`.
    x_lo: XBound,
    thrust_lo: f64,
    thrust_hi: f64,
}

impl Bounds {
    fn new<T: Real>(set: &AdmissibleSet<T>) -> Option<Self> {
        let capped = |a: T| to_f64(a).clamp(-MAX_TAN_ANGLE, MAX_TAN_ANGLE);
        let (lo_x, hi_x) = (capped(set.eta_x.lo), capped(set.eta_x.hi));
        let (lo_y, hi_y) = (capped(set.eta_y.lo), capped(set.eta_y.hi));
        let bounds = Self {
            tan_y_lo: lo_y.tan(),
            tan_y_hi: hi_y.tan(),
            // eta_x <= hi < 0: -f_y <= sin(hi) ||f||, i.e. ||f|| <= f_y / |sin hi|.
            x_hi: if hi_x >= 0.0 {
                XBound::Tan(hi_x.tan())
            } else {
                XBound::Cone(-1.0 / hi_x.sin())
            },
            // eta_x >= lo > 0: -f_y >= sin(lo) ||f||, i.e. ||f|| <= -f_y / sin lo.
            x_lo: if lo_x <= 0.0 {
                XBound::Tan(lo_x.tan())
            } else {
                XBound::Cone(1.0 / lo_x.sin())
            },
            thrust_lo: to_f64(set.thrust.lo).max(0.0),
            thrust_hi: to_f64(set.thrust.hi),
        };
        let finite = [
            bounds.tan_y_lo,
            bounds.tan_y_hi,
            bounds.thrust_lo,
            bounds.thrust_hi,
            match bounds.x_hi {
                XBound::Tan(v) | XBound::Cone(v) => v,
            },
            match bounds.x_lo {
                XBound::Tan(v) | XBound::Cone(v) => v,
            },
        ]
        .iter()
        .all(|v| v.is_finite());
        finite.then_some(bounds)
    }

    fn shape(&self) -> Shape {
        Shape {
            x_hi_cone: self.x_hi.is_cone(),
            x_lo_cone: self.x_lo.is_cone(),
        }
    }

    /// Every constraint's slack at `f` (negative: violated), in the order of the rows.
    fn slacks(&self, [fx, fy, fz]: [f64; 3]) -> [f64; 6] {
        let norm = (fx * fx + fy * fy + fz * fz).sqrt();
        [
            self.tan_y_hi * fz - fx,
            fx - self.tan_y_lo * fz,
            match self.x_hi {
                XBound::Tan(t) => t * fz + fy,
                XBound::Cone(s) => s * fy - norm,
            },
            match self.x_lo {
                XBound::Tan(t) => -fy - t * fz,
                XBound::Cone(s) => -s * fy - norm,
            },
            fz - self.thrust_lo,
            self.thrust_hi - norm,
        ]
    }

    /// Whether `f` satisfies every constraint up to [`FEASIBLE_TOL`] of the maximum thrust.
    fn feasible(&self, f: [f64; 3]) -> bool {
        let tol = -FEASIBLE_TOL * self.thrust_hi;
        self.slacks(f).iter().all(|s| *s >= tol)
    }

    /// The largest `t` in `[0, limit]` with `from + t (to - from)` feasible (`from` feasible), by
    /// bisection (the set is convex, so feasibility along the segment is an interval).
    fn max_step(&self, from: [f64; 3], to: [f64; 3], limit: f64) -> f64 {
        if self.feasible(lerp(from, to, limit)) {
            return limit;
        }
        let (mut lo, mut hi) = (0.0, limit);
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if self.feasible(lerp(from, to, mid)) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        lo
    }

    /// Moves a solver solution onto the linear rows and the thrust cone (by the solver
    /// tolerance) and says whether any constraint is active within [`ACTIVE_TOL`].
    fn repair(&self, f: [f64; 3]) -> ([f64; 3], bool) {
        let [mut fx, mut fy, mut fz] = f;
        fz = fz.max(self.thrust_lo);
        fx = fx.max(self.tan_y_lo * fz).min(self.tan_y_hi * fz);
        // -f_y <= tan(hi) f_z  <=>  f_y >= -tan(hi) f_z; -f_y >= tan(lo) f_z <=> f_y <= -tan(lo) f_z.
        if let XBound::Tan(t) = self.x_hi {
            fy = fy.max(-t * fz);
        }
        if let XBound::Tan(t) = self.x_lo {
            fy = fy.min(-t * fz);
        }
        let norm = (fx * fx + fy * fy + fz * fz).sqrt();
        if norm > self.thrust_hi && norm > 0.0 {
            let scale = self.thrust_hi / norm;
            fx *= scale;
            fy *= scale;
            fz *= scale;
        }
        let f = [fx, fy, fz];
        let tol = ACTIVE_TOL * self.thrust_hi.max(f64::MIN_POSITIVE);
        (f, self.slacks(f).iter().any(|s| *s <= tol))
    }
}

/// `a + t (b - a)`.
fn lerp(a: [f64; 3], b: [f64; 3], t: f64) -> [f64; 3] {
    let [a0, a1, a2] = a;
    let [b0, b1, b2] = b;
    [a0 + t * (b0 - a0), a1 + t * (b1 - a1), a2 + t * (b2 - a2)]
}

/// The structural kind of one agent's constraints (which `eta_x` sides are cones).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Shape {
    x_hi_cone: bool,
    x_lo_cone: bool,
}

impl Shape {
    /// Rows of the nonnegative cone: two `eta_y` rows, the linear `eta_x` rows, `f_z >= T_lo`.
    fn linear_rows(self) -> usize {
        3 + usize::from(!self.x_hi_cone) + usize::from(!self.x_lo_cone)
    }

    /// Number of 4-dimensional second-order cones: thrust, plus the `eta_x` cones.
    fn cones(self) -> usize {
        1 + usize::from(self.x_hi_cone) + usize::from(self.x_lo_cone)
    }
}

/// A working agent in the problem: its capacity slot, weighted block and bounds.
#[derive(Clone, Copy, Debug)]
struct Agent {
    slot: usize,
    /// `W M_i` in `f64`.
    block: Matrix6x3<f64>,
    bounds: Bounds,
}

/// One period's problem data in `f64`.
struct Problem<const N: usize> {
    key: [Option<Shape>; N],
    agents: Vec<Agent>,
    /// `W u_d`.
    target: Vector6<f64>,
    lambda: f64,
}

impl<const N: usize> Problem<N> {
    /// `None` if any used number is not finite.
    fn new<T: Real>(
        request: &AllocationRequest<'_, T, N>,
        weights: &[f64; 6],
        lambda: f64,
    ) -> Option<Self> {
        let w = Vector6::from_iterator(weights.iter().copied());
        let target = request.wrench.map(|x| to_f64(x)).component_mul(&w);
        if target.iter().any(|x| !x.is_finite()) {
            return None;
        }
        let mut key = [None; N];
        let mut agents = Vec::with_capacity(N);
        for (slot, ((block, set), k)) in request
            .effectiveness
            .blocks()
            .iter()
            .zip(request.sets)
            .zip(key.iter_mut())
            .enumerate()
        {
            let Some(block) = block else { continue };
            let mut weighted = block.map(|x| to_f64(x));
            for (mut row, wr) in weighted.row_iter_mut().zip(weights) {
                row *= *wr;
            }
            if weighted.iter().any(|x| !x.is_finite()) {
                return None;
            }
            let bounds = Bounds::new(set)?;
            *k = Some(bounds.shape());
            agents.push(Agent {
                slot,
                block: weighted,
                bounds,
            });
        }
        Some(Self {
            key,
            agents,
            target,
            lambda,
        })
    }

    /// `sum_k ||B_k f_k - W u||^2 + lambda sum_k ||f_k||^2` (`B_k = W M_k`).
    fn objective(&self, forces: &[[f64; 3]]) -> f64 {
        let mut residual = -self.target;
        let mut norm = 0.0;
        for (agent, f) in self.agents.iter().zip(forces) {
            let f = Vector3::from(*f);
            residual += agent.block * f;
            norm += f.norm_squared();
        }
        residual.norm_squared() + self.lambda * norm
    }

    /// The regularised least-squares forces of the agents marked free, the others held at
    /// `forces`: `f_k = B_k^T (sum_free B_j B_j^T + lambda I)^-1 (W u - sum_fixed B_j f_j)`
    /// (minimum norm when the bracket is singular).
    fn least_squares(&self, free: &[bool], forces: &[[f64; 3]]) -> Vec<[f64; 3]> {
        let mut rhs = self.target;
        for ((agent, is_free), f) in self.agents.iter().zip(free).zip(forces) {
            if !*is_free {
                rhs -= agent.block * Vector3::from(*f);
            }
        }
        let gram = weighted_gram(
            Matrix6::identity() * self.lambda,
            self.agents
                .iter()
                .zip(free)
                .filter(|(_, is_free)| **is_free)
                .map(|(agent, _)| (&agent.block, 1.0)),
        );
        let y = solve_gram(&gram, &rhs);
        self.agents
            .iter()
            .zip(free)
            .zip(forces)
            .map(|((agent, is_free), f)| {
                if *is_free {
                    (agent.block.transpose() * y).into()
                } else {
                    *f
                }
            })
            .collect()
    }

    /// The unconstrained minimiser if it satisfies every constraint (then it is the optimum).
    fn unconstrained(&self) -> Option<Vec<[f64; 3]>> {
        let free = std::vec![true; self.agents.len()];
        let forces = self.least_squares(&free, &std::vec![[0.0; 3]; self.agents.len()]);
        self.agents
            .iter()
            .zip(&forces)
            .all(|(a, f)| a.bounds.feasible(*f))
            .then_some(forces)
    }

    /// Active-set polish of an interior-point answer `start` (feasible): agents with an active
    /// constraint are held; the others move along the line to their closed-form least-squares
    /// forces ([`Self::least_squares`]) as far as every one stays feasible; the agent that
    /// blocks the step is held too, and so on (at most one round per agent). The objective is
    /// convex with its minimum on each line at the end, so it never increases. `Some` if the
    /// forces changed and the objective did not grow.
    fn polish(&self, start: &[[f64; 3]]) -> Option<Vec<[f64; 3]>> {
        let mut forces = start.to_vec();
        let mut free: Vec<bool> = self
            .agents
            .iter()
            .zip(start)
            .map(|(a, f)| a.bounds.feasible(*f) && !a.bounds.repair(*f).1)
            .collect();
        let mut moved = false;
        for _ in 0..self.agents.len() {
            if !free.iter().any(|f| *f) {
                break;
            }
            let target = self.least_squares(&free, &forces);
            // The largest step in [0, 1] keeping every free agent feasible, and who blocks it.
            let mut step = 1.0;
            let mut blocking = None;
            for (k, ((agent, is_free), (from, to))) in self
                .agents
                .iter()
                .zip(&free)
                .zip(forces.iter().zip(&target))
                .enumerate()
            {
                if !*is_free {
                    continue;
                }
                let t = agent.bounds.max_step(*from, *to, step);
                if t < step {
                    step = t;
                    blocking = Some(k);
                }
            }
            for ((f, to), is_free) in forces.iter_mut().zip(&target).zip(&free) {
                if *is_free {
                    *f = lerp(*f, *to, step);
                }
            }
            moved = true;
            match blocking.and_then(|k| free.get_mut(k)) {
                Some(is_free) => *is_free = false,
                None => break,
            }
        }
        (moved && self.objective(&forces) <= self.objective(start)).then_some(forces)
    }

    /// `3 n` forces, then the 6 weighted wrench errors `r`.
    fn variables(&self) -> usize {
        3 * self.agents.len() + 6
    }

    fn linear_rows(&self) -> usize {
        self.agents
            .iter()
            .map(|a| a.bounds.shape().linear_rows())
            .sum()
    }

    /// 6 equality rows, the linear rows, the cones.
    fn rows(&self) -> usize {
        6 + self.linear_rows()
            + 4 * self
                .agents
                .iter()
                .map(|a| a.bounds.shape().cones())
                .sum::<usize>()
    }

    /// `P = diag(2 lambda (forces), 2 (errors))`.
    fn p_values(&self, out: &mut Vec<f64>) {
        out.clear();
        out.extend(core::iter::repeat_n(
            2.0 * self.lambda,
            3 * self.agents.len(),
        ));
        out.extend([2.0; 6]);
    }

    /// The diagonal structure of [`Self::p_values`].
    fn p_structure(&self) -> (Vec<usize>, Vec<usize>) {
        let n = self.variables();
        ((0..=n).collect(), (0..n).collect())
    }

    /// `q = 0`.
    fn q_values(&self, out: &mut Vec<f64>) {
        out.clear();
        out.extend(core::iter::repeat_n(0.0, self.variables()));
    }

    /// `b`: `W u` on the equality rows; `-T_lo` on the `f_z` rows; `T_hi` heading each thrust
    /// cone; zeros elsewhere.
    fn b_values(&self, out: &mut Vec<f64>) {
        out.clear();
        out.extend(self.target.iter().copied());
        for agent in &self.agents {
            let shape = agent.bounds.shape();
            out.extend(core::iter::repeat_n(0.0, shape.linear_rows() - 1));
            out.push(-agent.bounds.thrust_lo);
        }
        for agent in &self.agents {
            out.extend([agent.bounds.thrust_hi, 0.0, 0.0, 0.0]);
            let extra = agent.bounds.shape().cones() - 1;
            out.extend(core::iter::repeat_n(0.0, 4 * extra));
        }
    }

    /// `A` as `(column, row, value)` triplets sorted column-major (`A x + s = b`, `s` in the
    /// cones): the equalities `W M f - r = W u`, then per agent the linear rows (all agents),
    /// then the cones (all agents).
    fn a_triplets(&self, out: &mut Vec<(usize, usize, f64)>) {
        out.clear();
        for (k, agent) in self.agents.iter().enumerate() {
            for (c, column) in agent.block.column_iter().enumerate() {
                out.extend(column.iter().enumerate().map(|(r, v)| (3 * k + c, r, *v)));
            }
        }
        let errors = 3 * self.agents.len();
        out.extend((0..6).map(|r| (errors + r, r, -1.0)));
        let mut row = 6;
        for (k, agent) in self.agents.iter().enumerate() {
            let (x, y, z) = (3 * k, 3 * k + 1, 3 * k + 2);
            let b = &agent.bounds;
            // f_x - tan(hi_y) f_z <= 0
            out.extend([(x, row, 1.0), (z, row, -b.tan_y_hi)]);
            row += 1;
            // -f_x + tan(lo_y) f_z <= 0
            out.extend([(x, row, -1.0), (z, row, b.tan_y_lo)]);
            row += 1;
            if let XBound::Tan(t) = b.x_hi {
                // -f_y - tan(hi_x) f_z <= 0
                out.extend([(y, row, -1.0), (z, row, -t)]);
                row += 1;
            }
            if let XBound::Tan(t) = b.x_lo {
                // f_y + tan(lo_x) f_z <= 0
                out.extend([(y, row, 1.0), (z, row, t)]);
                row += 1;
            }
            // -f_z <= -T_lo
            out.push((z, row, -1.0));
            row += 1;
        }
        for (k, agent) in self.agents.iter().enumerate() {
            let (x, y, z) = (3 * k, 3 * k + 1, 3 * k + 2);
            let b = &agent.bounds;
            let heads = [
                None,
                match b.x_hi {
                    XBound::Cone(s) => Some(-s),
                    XBound::Tan(_) => None,
                },
                match b.x_lo {
                    XBound::Cone(s) => Some(s),
                    XBound::Tan(_) => None,
                },
            ];
            // Thrust cone (head row empty: s_0 = T_hi), then the eta_x cones (s_0 = +-s f_y).
            for (i, head) in heads.iter().enumerate() {
                if i > 0 && head.is_none() {
                    continue;
                }
                if let Some(h) = head {
                    out.push((y, row, *h));
                }
                out.extend([(x, row + 1, -1.0), (y, row + 2, -1.0), (z, row + 3, -1.0)]);
                row += 4;
            }
        }
        out.sort_unstable_by_key(|t| (t.0, t.1));
    }

    fn cones(&self) -> Vec<SupportedConeT<f64>> {
        let mut cones = Vec::with_capacity(2 + 3 * self.agents.len());
        cones.push(SupportedConeT::ZeroConeT(6));
        cones.push(SupportedConeT::NonnegativeConeT(self.linear_rows()));
        for agent in &self.agents {
            for _ in 0..agent.bounds.shape().cones() {
                cones.push(SupportedConeT::SecondOrderConeT(4));
            }
        }
        cones
    }
}

/// The Clarabel solver for one structure, with the buffers of its data.
struct Cache<const N: usize> {
    key: [Option<Shape>; N],
    solver: DefaultSolver<f64>,
    p: Vec<f64>,
    a_triplets: Vec<(usize, usize, f64)>,
    a: Vec<f64>,
    q: Vec<f64>,
    b: Vec<f64>,
    /// Scratch for the new `P` values, compared with `p` before updating.
    scratch: Vec<f64>,
}

impl<const N: usize> Cache<N> {
    /// A new solver for `problem` (`None` if Clarabel rejects it).
    fn build(problem: &Problem<N>, settings: &DefaultSettings<f64>) -> Option<Self> {
        let (n, m) = (problem.variables(), problem.rows());
        let mut p = Vec::new();
        problem.p_values(&mut p);
        let (colptr, rowval) = problem.p_structure();
        let p_matrix = CscMatrix::new(n, n, colptr, rowval, p.clone());

        let mut a_triplets = Vec::new();
        problem.a_triplets(&mut a_triplets);
        let mut a_colptr = Vec::with_capacity(n + 1);
        a_colptr.push(0);
        let mut a_rowval = Vec::with_capacity(a_triplets.len());
        let mut a = Vec::with_capacity(a_triplets.len());
        for col in 0..n {
            for (_, r, v) in a_triplets.iter().filter(|t| t.0 == col) {
                a_rowval.push(*r);
                a.push(*v);
            }
            a_colptr.push(a_rowval.len());
        }
        let a_matrix = CscMatrix::new(m, n, a_colptr, a_rowval, a.clone());

        let (mut q, mut b) = (Vec::new(), Vec::new());
        problem.q_values(&mut q);
        problem.b_values(&mut b);
        let cones = problem.cones();
        let solver =
            DefaultSolver::new(&p_matrix, &q, &a_matrix, &b, &cones, settings.clone()).ok()?;
        if !solver.is_data_update_allowed() {
            return None;
        }
        Some(Self {
            key: problem.key,
            solver,
            p,
            a_triplets,
            a,
            q,
            b,
            scratch: Vec::new(),
        })
    }

    /// Writes `problem`'s numbers into the solver (same structure); `P`, `A` and `q` only if
    /// changed (in normal use `b` alone changes with the wrench, `A` with the sets).
    fn update(&mut self, problem: &Problem<N>) -> Result<(), ::clarabel::solver::DataUpdateError> {
        problem.p_values(&mut self.scratch);
        if self.scratch != self.p {
            core::mem::swap(&mut self.scratch, &mut self.p);
            self.solver.update_P(&self.p)?;
        }
        problem.a_triplets(&mut self.a_triplets);
        self.scratch.clear();
        self.scratch.extend(self.a_triplets.iter().map(|t| t.2));
        if self.scratch != self.a {
            core::mem::swap(&mut self.scratch, &mut self.a);
            self.solver.update_A(&self.a)?;
        }
        problem.q_values(&mut self.scratch);
        if self.scratch != self.q {
            core::mem::swap(&mut self.scratch, &mut self.q);
            self.solver.update_q(&self.q)?;
        }
        problem.b_values(&mut self.b);
        self.solver.update_b(&self.b)?;
        Ok(())
    }
}
