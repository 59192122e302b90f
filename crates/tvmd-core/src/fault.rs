//! Knowing an agent failed from the vehicle's motion: detection and isolation from the wrench
//! residual (`docs/method.md`, "Beyond the paper: agent faults"); the controller's settings of
//! it are [`detection`].
//!
//! The residual `r = [r_tau; r_f]` (body frame `{C}`) is the wrench the team did not deliver as
//! commanded: the disturbance observer's estimate ([`crate::DisturbanceObserver`]) of the
//! unmodelled wrench, or any estimate of `u_measured - M f`. Each working agent `i` commanded
//! `w_i = M_i f_i` (eq. 4). A fault of agent `i` shows in `r` inside the span of its block
//! `M_i` (6x3): a loss as `r = -w_i`, a partial loss as `r = -(1 - eta) w_i`, a stuck gimbal as
//! `r = M_i (f_stuck - f_i)`. With six residual dimensions and three per agent, the agents'
//! spans differ and the faulty one can be told apart.
//!
//! Per period ([`FaultState::update`]):
//! - detection: `s = ||r||_Sigma`, the residual in units of its stated noise (force `sigma_f`,
//!   torque `sigma_tau`, from the sensor noise and the model error the caller states); a fault
//!   is suspected when `s > k` ([`FaultDetector::threshold`]);
//! - isolation: each working agent's two fault hypotheses, predicted from its own command
//!   `f_i` (weighted by `Sigma`): a loss or partial loss `r = -c W M_i f_i` (one parameter `c`
//!   in `[0, 1]`), and a stuck gimbal `r = W M_i delta_f` with `delta_f` across `f_i` (two
//!   parameters); the agent's misfit is the better hypothesis'. The agent with the smallest
//!   misfit is the candidate when that misfit is within the noise (`<= k`) and the runner-up's
//!   is not. A hypothesis tied to the agent's command separates agents whose spans are close
//!   (neighbours of a large team, agents tilted alike mid-manoeuvre) better than a free fit in
//!   the span of `M_i`;
//! - kind: the better hypothesis: a loss (`eta = 1 - c <= 0.2` delivered), a partial loss
//!   (`eta` reported) or a stuck gimbal;
//! - persistence: the same candidate for [`FaultDetector::persistence`] consecutive periods
//!   confirms it, so a gust or a payload pickup (a residual no single agent explains, or one that
//!   passes) does not. A period that does not tell the candidate from its runner-up, while the
//!   candidate is still the best explanation within the noise, holds the count.
//!
//! Proven: with exact `M_i f_i` and no noise, a loss of agent `i` gives misfit 0 for `i` (up to
//! the closed form's round-off, about `sqrt(eps) ||r||`: `fault/fit.rs`) and,
//! when `w_i` is neither along another agent's `w_j` nor in the span of its block across `f_j`,
//! a positive misfit for every other agent (linear algebra of the fits); the statistic is scale-free in the stated noise. Measured,
//! not proven: detection delays and false alarms in flight (the simulator's tables).

use nalgebra::{Matrix6x3, Vector3, Vector6};

use crate::agent::failure::FailureMask;
use crate::foundation::error::{positive, ConfigError, ConfigField};
use crate::foundation::real::{lit, sqrt, Real};
use crate::foundation::stored::Stored;

pub mod detection;
mod fit;
pub mod reading;
pub mod report_check;
pub mod reports;
mod verdict;
use fit::{fit, none, share, unsquare, Fit, WeightedResidual};
pub use reading::{AgentReading, ReportError};
pub use report_check::{ReportCheck, ReportGains};
pub use reports::ReportState;
pub use verdict::{FaultKind, FaultReport, FaultSource, FaultVerdict};

/// A fault detector's settings: the residual's stated noise, the threshold in units of it, and
/// the persistence. Validated: each finite and positive (`persistence >= 1`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FaultDetector<T: Real> {
    force_noise: T,
    torque_noise: T,
    threshold: T,
    persistence: u32,
}

impl<T: Real> FaultDetector<T> {
    /// `force_noise` (N) and `torque_noise` (N m): one standard deviation of the residual in
    /// flight without a fault (sensor noise through the observer, and the model error the
    /// caller expects); `threshold` `k` in those units (e.g. 5); `persistence` in periods.
    ///
    /// Errors: [`ConfigError::NonFinite`] or [`ConfigError::Parameter`] naming
    /// [`ConfigField::FaultNoise`], [`ConfigField::FaultThreshold`] or
    /// [`ConfigField::FaultPersistence`].
    pub fn new(
        force_noise: T,
        torque_noise: T,
        threshold: T,
        persistence: u32,
    ) -> Result<Self, ConfigError> {
        if persistence == 0 {
            return Err(ConfigError::Parameter {
                field: ConfigField::FaultPersistence,
            });
        }
        Ok(Self {
            force_noise: positive(force_noise, ConfigField::FaultNoise)?,
            torque_noise: positive(torque_noise, ConfigField::FaultNoise)?,
            threshold: positive(threshold, ConfigField::FaultThreshold)?,
            persistence,
        })
    }

    /// The stated force noise `sigma_f` (N).
    pub fn force_noise(&self) -> T {
        self.force_noise
    }

    /// The stated torque noise `sigma_tau` (N m).
    pub fn torque_noise(&self) -> T {
        self.torque_noise
    }

    /// `k`, the threshold in units of the stated noise.
    pub fn threshold(&self) -> T {
        self.threshold
    }

    /// Consecutive periods that confirm a candidate.
    pub fn persistence(&self) -> u32 {
        self.persistence
    }

    /// `Sigma^(-1/2)`: the weight of each residual component (torque first).
    pub(crate) fn weights(&self) -> Vector6<T> {
        let (f, t) = (T::one() / self.force_noise, T::one() / self.torque_noise);
        Vector6::new(t, t, t, f, f, f)
    }
}

/// The detector's state: the candidate and how long it has held.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FaultState {
    /// The candidate agent (`u16`: a mask's slot; keeps the controller's state small).
    candidate: Stored<u16>,
    /// Its consecutive periods (`u16`, saturating: the state stays small).
    periods: u16,
}

impl FaultState {
    /// A detector with no candidate.
    pub fn new() -> Self {
        Self::default()
    }

    /// The candidate held (through ambiguous periods too), if any.
    pub fn candidate(&self) -> Option<usize> {
        self.candidate.get().map(usize::from)
    }

    /// Forgets the candidate.
    pub fn reset(&mut self) {
        *self = Self::default();
    }

    /// One period: `residual` (`[r_tau; r_f]`, body frame), the agents' blocks `M_i` and their
    /// forces `f_i` of the period the residual measures, the failure mask in force (masked
    /// agents are not candidates). The blocks are [`crate::Effectiveness::blocks`]': each
    /// `[[p_i]x R_i; R_i]` with `R_i` a rotation, which the fits' closed form relies on
    /// (another matrix gives meaningless misfits). A non-finite input gives `Nominal` with a NaN statistic and
    /// forgets the candidate (never a confirmation from garbage).
    pub fn update<T: Real, const N: usize>(
        &mut self,
        detector: &FaultDetector<T>,
        residual: &Vector6<T>,
        blocks: &[Stored<Matrix6x3<T>>; N],
        forces: &[Vector3<T>; N],
        failures: &FailureMask<N>,
    ) -> FaultReport<T> {
        let force_of = |i: usize| forces.get(i).copied().unwrap_or_else(Vector3::zeros);
        self.update_with(detector, residual, blocks, force_of, failures)
    }

    /// As [`Self::update`], with agent `i`'s force given by `force_of(i)`, called once per
    /// working agent and only in a period whose statistic is above the threshold: a caller
    /// that holds commands, not forces, pays their trigonometry only then.
    pub fn update_with<T: Real, const N: usize>(
        &mut self,
        detector: &FaultDetector<T>,
        residual: &Vector6<T>,
        blocks: &[Stored<Matrix6x3<T>>; N],
        force_of: impl Fn(usize) -> Vector3<T>,
        failures: &FailureMask<N>,
    ) -> FaultReport<T> {
        let w = detector.weights();
        let r = residual.component_mul(&w);
        let rr = r.norm_squared();
        let statistic = sqrt(rr);
        let mut report = FaultReport {
            verdict: FaultVerdict::Nominal,
            source: FaultSource::Residual,
            statistic,
            threshold: detector.threshold,
            best_misfit: none(),
            runner_up_misfit: none(),
        };
        if !statistic.is_finite() || statistic <= detector.threshold {
            self.reset();
            return report;
        }
        let weighted = WeightedResidual::new(&r, rr, &w);
        let mut best: Option<(usize, Fit<T>)> = None;
        // The runner-up's squared misfit.
        let mut runner_up: T = none();
        for (i, block) in blocks.iter().enumerate() {
            let (Some(m), false) = (block.as_ref(), failures.is_failed(i)) else {
                continue;
            };
            let Some(fit) = fit(&weighted, m, &force_of(i)) else {
                continue;
            };
            match &best {
                Some((_, b)) if fit.misfit2 >= b.misfit2 => {
                    // Finite squares: a comparison, not `min` (a `libm` call on a Cortex-M4F).
                    if fit.misfit2 < runner_up {
                        runner_up = fit.misfit2;
                    }
                }
                _ => {
                    if let Some((_, b)) = &best {
                        runner_up = b.misfit2;
                    }
                    best = Some((i, fit));
                }
            }
        }
        report.runner_up_misfit = unsquare(runner_up);
        if let Some((_, b)) = &best {
            report.best_misfit = unsquare(b.misfit2);
        }
        // The runner-up is rejected against the best by the likelihood ratio of the two
        // hypotheses (`runner_up^2 - best^2`) at half the detection's `k^2`.
        let k2 = detector.threshold * detector.threshold;
        let explained = best
            .as_ref()
            .filter(|(_, b)| b.misfit2 <= k2 && runner_up - b.misfit2 > k2 * lit(0.5));
        let Some((agent, b)) = explained else {
            // A period that does not tell the candidate from its runner-up, while the candidate
            // is still the best explanation, holds the count; anything else forgets it.
            let still_best = best.as_ref().is_some_and(|(i, b)| {
                b.misfit2 <= k2 && self.candidate.get() == u16::try_from(*i).ok()
            });
            if !still_best {
                self.reset();
            }
            report.verdict = FaultVerdict::Unexplained;
            return report;
        };
        let (agent, kind) = (*agent, b.kind);
        let slot = u16::try_from(agent).ok();
        self.periods = if self.candidate.is_some() && self.candidate.get() == slot {
            self.periods.saturating_add(1)
        } else {
            1
        };
        self.candidate = slot.into();
        report.verdict = if u32::from(self.periods) >= detector.persistence {
            FaultVerdict::Confirmed { agent, kind }
        } else {
            FaultVerdict::Suspected {
                agent,
                kind,
                periods: u32::from(self.periods),
            }
        };
        report
    }
}

/// The share `c` of agent `i`'s commanded wrench `M_i f` that `residual` lacks (`residual = -c
/// M_i f` in least squares, weighted by the detector's stated noise): the loss hypothesis' one
/// parameter, not clamped to `[0, 1]` (a mean of shares is). `None` for an agent with no
/// command to lose. `m` is a block of [`crate::Effectiveness::blocks`] (the structure
/// [`FaultState::update_with`] relies on).
pub(crate) fn lost_share<T: Real>(
    detector: &FaultDetector<T>,
    residual: &Vector6<T>,
    m: &Matrix6x3<T>,
    f: &Vector3<T>,
) -> Option<T> {
    let w = detector.weights();
    // `r.r` is for the misfits, not read by the share.
    share(
        &WeightedResidual::new(&residual.component_mul(&w), T::zero(), &w),
        m,
        f,
    )
}

/// The kind of a loss of share `c` of the command: a loss when the efficiency `1 - c` is at
/// most 0.2, otherwise a partial loss.
pub(crate) fn loss_kind<T: Real>(c: T) -> FaultKind<T> {
    let efficiency = T::one() - c;
    if efficiency <= lit(0.2) {
        FaultKind::Loss
    } else {
        FaultKind::PartialLoss { efficiency }
    }
}

impl FaultState {
    /// Whether the state at `this` holds a valid candidate tag (its values are numbers).
    ///
    /// # Safety
    /// `this` is aligned and points to `size_of::<Self>()` readable bytes.
    pub(crate) unsafe fn storage_intact(this: *const Self) -> bool {
        Stored::tag_intact(core::ptr::addr_of!((*this).candidate))
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::indexing_slicing, clippy::panic)]
    use super::*;
    use crate::team::presets;

    fn setup() -> ([Stored<Matrix6x3<f64>>; 4], [Vector3<f64>; 4]) {
        let team = presets::a4_inc::<f64, 4>().unwrap();
        let m = team.effectiveness(&FailureMask::none());
        // Hover: each agent straight up with a quarter of the weight.
        let f = [Vector3::new(0.0, 0.0, 2.8 * 9.81 / 4.0); 4];
        (*m.blocks(), f)
    }

    fn detector() -> FaultDetector<f64> {
        FaultDetector::new(0.2, 0.02, 5.0, 3).unwrap()
    }

    #[test]
    fn a_lost_agent_is_isolated_and_confirmed_after_the_persistence() {
        let (blocks, f) = setup();
        let d = detector();
        for lost in 0..4 {
            let mut s = FaultState::new();
            let r = -(blocks[lost].get().unwrap() * f[lost]);
            for k in 1..=3u32 {
                let rep = s.update(&d, &r, &blocks, &f, &FailureMask::none());
                // The closed-form misfit of an exact fit is round-off: about sqrt(eps) ||r||.
                assert!(rep.statistic > d.threshold() && rep.best_misfit < 1e-6 * rep.statistic);
                match rep.verdict {
                    FaultVerdict::Suspected {
                        agent,
                        kind,
                        periods,
                    } if k < 3 => {
                        assert_eq!((agent, kind, periods), (lost, FaultKind::Loss, k));
                    }
                    FaultVerdict::Confirmed { agent, kind } if k == 3 => {
                        assert_eq!((agent, kind), (lost, FaultKind::Loss));
                    }
                    v => panic!("agent {lost}, period {k}: {v:?}"),
                }
            }
        }
    }

    #[test]
    fn partial_loss_and_stuck_gimbal_are_told_apart() {
        let (blocks, f) = setup();
        let d = detector();
        let mut s = FaultState::new();
        let r = -(blocks[2].get().unwrap() * (f[2] * 0.5));
        let rep = s.update(&d, &r, &blocks, &f, &FailureMask::none());
        match rep.verdict {
            FaultVerdict::Suspected {
                agent: 2,
                kind: FaultKind::PartialLoss { efficiency },
                ..
            } => assert!((efficiency - 0.5).abs() < 1e-9),
            v => panic!("{v:?}"),
        }
        // Agent 1's force tilted by 0.1 rad about its y axis, the same thrust (the stuck
        // hypothesis is the small-angle one: the force change across the command).
        let t = f[1].norm();
        let stuck = Vector3::new(t * 0.1f64.sin(), 0.0, t * 0.1f64.cos());
        let r = blocks[1].get().unwrap() * (stuck - f[1]);
        let rep = FaultState::new().update(&d, &r, &blocks, &f, &FailureMask::none());
        // At hover every agent's force is vertical, so a slip across it (a horizontal force and
        // a yaw torque) is explained by the stuck hypothesis within the noise, but another
        // agent's slip explains it as well: not isolated, never another agent named.
        assert!(rep.statistic > d.threshold() && rep.best_misfit <= d.threshold());
        assert!(
            matches!(
                rep.verdict,
                FaultVerdict::Unexplained
                    | FaultVerdict::Suspected {
                        agent: 1,
                        kind: FaultKind::StuckGimbal,
                        ..
                    }
            ),
            "{rep:?}"
        );
    }

    #[test]
    fn noise_and_an_unexplained_wrench_do_not_confirm() {
        let (blocks, f) = setup();
        let d = detector();
        let mut s = FaultState::new();
        // Within the noise: nominal.
        let small = Vector6::new(0.01, -0.02, 0.01, 0.3, -0.2, 0.4);
        let rep = s.update(&d, &small, &blocks, &f, &FailureMask::none());
        assert_eq!(rep.verdict, FaultVerdict::Nominal);
        // A side gust: a pure lateral force at the CoM, which no single agent's span holds.
        let gust = Vector6::new(0.0, 0.0, 0.0, 3.0, 0.0, 0.0);
        for _ in 0..10 {
            let rep = s.update(&d, &gust, &blocks, &f, &FailureMask::none());
            assert!(
                !matches!(rep.verdict, FaultVerdict::Confirmed { .. }),
                "{rep:?}"
            );
        }
        // A masked agent is not a candidate, and garbage forgets the candidate.
        let r = -(blocks[0].get().unwrap() * f[0]);
        let masked = FailureMask::with_failed(&[0]).unwrap();
        let rep = s.update(&d, &r, &blocks, &f, &masked);
        assert!(!matches!(
            rep.verdict,
            FaultVerdict::Suspected { agent: 0, .. }
        ));
        let nan = Vector6::new(f64::NAN, 0.0, 0.0, 0.0, 0.0, 0.0);
        let rep = s.update(&d, &nan, &blocks, &f, &FailureMask::none());
        assert_eq!(rep.verdict, FaultVerdict::Nominal);
        assert!(rep.statistic.is_nan());
        assert_eq!(s, FaultState::new());
    }

    #[test]
    fn an_ambiguous_period_holds_the_count_and_a_nominal_one_forgets_it() {
        let (blocks, f) = setup();
        let d = detector();
        let none = FailureMask::none();
        let full = -(blocks[0].get().unwrap() * f[0]);
        // The same loss read with the torque's noise so large that only the force counts: the
        // agents' losses push alike, so no runner-up is rejected while agent 0 stays the best.
        let blind = FaultDetector::new(0.2, 1e6, 5.0, 3).unwrap();
        let mut s = FaultState::new();
        let periods = |rep: FaultReport<f64>| match rep.verdict {
            FaultVerdict::Suspected {
                agent: 0, periods, ..
            } => Some(periods),
            _ => None,
        };
        assert_eq!(periods(s.update(&d, &full, &blocks, &f, &none)), Some(1));
        let rep = s.update(&blind, &full, &blocks, &f, &none);
        assert_eq!(rep.verdict, FaultVerdict::Unexplained, "{rep:?}");
        assert!(rep.best_misfit <= rep.threshold && rep.runner_up_misfit <= rep.threshold);
        // The ambiguous period holds the candidate (the controller's loss share reads it).
        assert_eq!(s.candidate(), Some(0));
        assert_eq!(periods(s.update(&d, &full, &blocks, &f, &none)), Some(2));
        let quiet = Vector6::zeros();
        assert_eq!(
            s.update(&d, &quiet, &blocks, &f, &none).verdict,
            FaultVerdict::Nominal
        );
        assert_eq!(s.candidate(), None);
        assert_eq!(periods(s.update(&d, &full, &blocks, &f, &none)), Some(1));
    }

    #[test]
    fn settings_are_validated() {
        assert!(FaultDetector::new(0.0, 0.1, 5.0, 3).is_err());
        assert!(FaultDetector::new(0.1, f64::NAN, 5.0, 3).is_err());
        assert!(FaultDetector::new(0.1, 0.1, -1.0, 3).is_err());
        assert_eq!(
            FaultDetector::new(0.1, 0.1, 5.0, 0),
            Err(ConfigError::Parameter {
                field: ConfigField::FaultPersistence
            })
        );
    }
}

#[cfg(test)]
mod storage_tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use crate::foundation::stored::{accepts, refuses};
    use core::ptr::addr_of_mut;

    #[test]
    fn an_invalid_candidate_tag_is_refused() {
        let check = FaultState::storage_intact;
        let s = FaultState {
            candidate: Stored::Present(2),
            periods: 1,
        };
        assert!(accepts(&s, check) && accepts(&FaultState::new(), check));
        let candidate = |p: *mut FaultState| unsafe { addr_of_mut!((*p).candidate).cast() };
        assert!(refuses(&s, 2, candidate, check));
    }
}
