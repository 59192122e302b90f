//! Agent fault detection inside the controller ([`ControllerSettings::fault_detection`]): each
//! period the disturbance observer's raw measurement of the last period, rotated into the body
//! frame and low-passed at the observer's bandwidths (the same first-order filter, but not
//! held by the anti-windup, which freezes the observer's estimate exactly when a lost agent
//! saturates the others), is the residual that [`crate::fault`] reads against the working
//! agents' blocks and the forces allocated for the period it measures. On a confirmed loss the controller either reports it
//! ([`FaultResponse::Report`]: the caller decides) or masks the agent itself
//! ([`FaultResponse::Mask`]: [`Controller::set_failures`], whose hover-capability certificate
//! [`Controller::fault_masking`] reports). `docs/method.md`, "Beyond the paper: agent faults".
//!
//! The settings ([`crate::FaultDetection`]) and how their noise is resolved for the team are in
//! [`crate::fault::detection`].

use core::ptr::addr_of;

use nalgebra::{Vector3, Vector6};

use super::{Controller, ControllerSettings};
use crate::afs::hover::HoverCapability;
use crate::agent::command::AgentCommand;
use crate::allocation::{Allocation, Allocator};
use crate::fault::detection::{
    FaultResponse, FAULT_ACTUATOR_LAG, FAULT_BASELINE_BANDWIDTH, FAULT_JUMP_SHARE,
};
use crate::fault::{
    loss_kind, lost_share, FaultDetector, FaultKind, FaultReport, FaultSource, FaultState,
    FaultVerdict, ReportCheck, ReportGains,
};
use crate::foundation::error::{ConfigError, ConfigField};
use crate::foundation::linalg::{wrench_parts, EuclideanNorm};
use crate::foundation::real::{lit, sin_cos, Real};
use crate::foundation::stored::{bool_intact, tag_below, Stored};
use crate::law::offset_free::OffsetFree;
use crate::law::RigidState;
use crate::team::TeamConfig;

/// A mask the controller set itself on a confirmed loss ([`FaultResponse::Mask`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FaultMasking<T: Real> {
    /// The agent masked.
    pub agent: usize,
    /// The hover-capability certificate of the mask in force
    /// ([`Controller::hover_capability`]); `None` when the mask was refused (the remaining
    /// team cannot produce every wrench: the old mask kept, not tried again for this agent).
    pub hover: Option<HoverCapability<T>>,
}

/// What the monitor keeps of a masking (the certificate is the controller's own).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Masked {
    agent: u16,
    refused: bool,
}

/// The detector's state inside a controller.
#[derive(Clone, Copy, Debug, PartialEq)]
// `repr(C)`: fields in declaration order, which the C interface's flash build copies and
// initializes in 144 B less code than Rust's reordering.
#[repr(C)]
pub(super) struct FaultMonitor<T: Real, const N: usize> {
    response: FaultResponse,
    detector: FaultDetector<T>,
    state: FaultState,
    /// The filtered residual `[r_tau; r_f]` (`{C}`).
    residual: Vector6<T>,
    /// Its slow baseline ([`FAULT_BASELINE_BANDWIDTH`]): the model error's persistent part,
    /// held while the statistic is above half the threshold.
    baseline: Vector6<T>,
    /// The wrench `M f` allocated for the coming period.
    wrench: Vector6<T>,
    /// The agent-frame forces `f_i` of the held commands, which the next residual measures:
    /// the allocation's when its commands are sent (their inversion moves them by round-off
    /// only), else the commands' own ([`command_force`]). Kept so that isolating a fault needs
    /// no trigonometry per agent and period.
    forces: [Vector3<T>; N],
    /// The wrench the actuators delivered at the end of the last period, modelled as a
    /// first-order lag ([`FAULT_ACTUATOR_LAG`]) of the allocated one.
    delivered: Vector6<T>,
    /// The candidate's lost share `c` from the unfiltered measurements (a running mean over
    /// its periods, [`crate::fault`]'s loss hypothesis).
    raw_share: T,
    /// The periods in that mean: every period the candidate is held, the ambiguous ones too.
    /// A mean over the periods that named it only (those whose residual leaned its way) read a
    /// half-thrust agent hard to tell from its neighbours as a loss. A `u8` (the C handle has
    /// no room for more): saturated, the mean becomes a running average over about 255 periods.
    share_periods: u8,
    /// The share of a gap the actuators' lag closes in a period, `1 - e^(-dt/tau)`, and the
    /// share of it they leave undelivered on average over the period,
    /// `tau / dt (1 - e^(-dt/tau))` ([`FAULT_ACTUATOR_LAG`]); the period is fixed for the
    /// monitor's life (a reconfiguration builds a new one), so they are computed once.
    closed: T,
    undelivered: T,
    /// The last report, valid while `reported` is set (a value and a flag, not a [`Stored`]:
    /// as one, writing it each period cost the cycle about 480 Cortex-M4F instructions more).
    report: FaultReport<T>,
    reported: bool,
    masked: Stored<Masked>,
    /// The agents' reports' check ([`crate::fault::reports`]; the reports themselves are the
    /// controller's, outside the monitor, so that building a monitor on the stack stays small).
    pub(super) check: ReportCheck<T>,
    /// The check's per-period gains at the controller's period ([`FAULT_ACTUATOR_LAG`]) and
    /// the team's maximum thrust.
    pub(super) gains: ReportGains<T>,
}

impl<T: Real, const N: usize> FaultMonitor<T, N> {
    /// The monitor of `settings` for `team` (`None` when detection is off). Errors when
    /// detection is on without the disturbance observer ([`ConfigField::FaultResidual`]) or
    /// the team's noise cannot be resolved.
    pub(super) fn new(
        settings: &ControllerSettings<T>,
        team: &TeamConfig<T, N>,
        weight: T,
    ) -> Result<Stored<Self>, ConfigError> {
        let Some(detection) = settings.fault_detection else {
            return Ok(Stored::Absent);
        };
        let Some(OffsetFree::Observer(_)) = settings.offset_free else {
            return Err(ConfigError::Parameter {
                field: ConfigField::FaultResidual,
            });
        };
        let arm = team
            .agents()
            .iter()
            .fold(T::zero(), |a, s| a.max(s.position.euclidean_norm()));
        let period = settings.period;
        let closed = T::one() - (-(period / lit(FAULT_ACTUATOR_LAG))).exp();
        Ok(Stored::Present(Self {
            response: detection.response(),
            detector: detection.detector(weight, arm)?,
            state: FaultState::new(),
            residual: Vector6::zeros(),
            baseline: Vector6::zeros(),
            wrench: Vector6::zeros(),
            forces: [Vector3::zeros(); N],
            delivered: Vector6::zeros(),
            raw_share: T::zero(),
            share_periods: 0,
            closed,
            undelivered: lit::<T>(FAULT_ACTUATOR_LAG) / period * closed,
            // Never shown while `reported` is unset. A threshold of 1, not 0: a run of zero
            // bytes here and around became one unaligned `__aeabi_memclr` call, which cost the C
            // interface's flash build 208 B.
            report: FaultReport {
                verdict: FaultVerdict::Nominal,
                source: FaultSource::Residual,
                statistic: T::zero(),
                threshold: T::one(),
                best_misfit: T::zero(),
                runner_up_misfit: T::zero(),
            },
            reported: false,
            masked: Stored::Absent,
            check: *detection.report_check(),
            gains: detection.report_check().gains(
                period,
                lit(FAULT_ACTUATOR_LAG),
                team.limits().max_thrust(),
            ),
        }))
    }

    /// Forgets the candidate, the residual and the report (a controller reset, a landing; the
    /// caller forgets the report check's models).
    pub(super) fn reset(&mut self) {
        self.state.reset();
        self.residual = Vector6::zeros();
        self.baseline = Vector6::zeros();
        self.wrench = Vector6::zeros();
        self.forces = [Vector3::zeros(); N];
        self.delivered = Vector6::zeros();
        self.raw_share = T::zero();
        self.share_periods = 0;
        self.reported = false;
    }

    /// Filters this period's measurement (`{I}` force, `{C}` torque) into the residual;
    /// returns the measurement (`{C}`, the lag added back) unfiltered.
    fn filter(
        &mut self,
        attitude_t: &nalgebra::Matrix3<T>,
        d_f: &Vector3<T>,
        d_tau: &Vector3<T>,
        lag: &Vector6<T>,
        gains: (T, T),
    ) -> Vector6<T> {
        let f = attitude_t * d_f;
        let measured = Vector6::new(d_tau.x, d_tau.y, d_tau.z, f.x, f.y, f.z) + lag;
        let (g_f, g_tau) = gains;
        for (k, (r, m)) in self.residual.iter_mut().zip(measured.iter()).enumerate() {
            let g = if k < 3 { g_tau } else { g_f };
            *r += (*m - *r) * g;
        }
        measured
    }
}

impl<T: Real, const N: usize, A: Allocator<T, N>> Controller<T, N, A> {
    /// This period's detection, after the observer measured the last period: the filtered
    /// residual `[r_tau; r_f]` against the working agents; with [`FaultResponse::Mask`], a
    /// confirmed loss masks the agent now (this period's projection and allocation already
    /// fly without it) and sets the observer's estimate and the residual back to the baseline
    /// (the persistent model error): the part of them above it held that
    /// agent's wrench.
    pub(super) fn detect_faults(&mut self, state: &RigidState<T>) {
        let measurement = self.offset_free.observer_measurement();
        let gains = self.offset_free.observer_gains();
        let period = self.settings.period;
        let landed = self.offset_free.landed();
        let Some(monitor) = self.fault.as_mut() else {
            return;
        };
        if landed {
            // On the ground: nothing to read, and nothing carried into the next flight.
            monitor.reset();
            self.reports.forget();
            return;
        }
        // The actuators' first-order lag over the period the residual measures: the share of
        // the gap to the commanded wrench they did not deliver on average over the period
        // (`tau / dt (1 - e^(-dt/tau))`), added back to the measurement, and the gap they close.
        let gap = monitor.wrench - monitor.delivered;
        let (closed, undelivered) = (monitor.closed, monitor.undelivered);
        let lag = gap * undelivered;
        let raw = match (measurement, gains) {
            (Some((d_f, d_tau)), Some(gains)) => {
                Some(monitor.filter(&state.attitude.transpose(), &d_f, &d_tau, &lag, gains))
            }
            _ => None,
        };
        monitor.delivered += gap * closed;
        let change = monitor.residual - monitor.baseline;
        // The stated noise, grown by a share of the gap the lag model read (what it misses
        // of a changing command: rate limits, the servos' own dynamics).
        let d = &monitor.detector;
        let share = lit::<T>(FAULT_JUMP_SHARE);
        let (j_tau, j_f) = (
            gap.fixed_rows::<3>(0).euclidean_norm() * share,
            gap.fixed_rows::<3>(3).euclidean_norm() * share,
        );
        let detector = FaultDetector::new(
            d.force_noise() + j_f,
            d.torque_noise() + j_tau,
            d.threshold(),
            d.persistence(),
        )
        .unwrap_or(*d);
        // The forces of the commands held over the period the residual measures.
        let forces = &monitor.forces;
        let force_of = |i: usize| forces.get(i).copied().unwrap_or_else(Vector3::zeros);
        let blocks = self.effectiveness.blocks();
        let mut report =
            monitor
                .state
                .update_with(&detector, &change, blocks, force_of, &self.failures);
        // A loss's share from the unfiltered measurements since the candidate appeared: the
        // filtered residual reaches a step's full size only after the filter's ramp, the
        // unfiltered measurement at once (noisier: averaged over the candidate's periods).
        // The candidacy goes on unless this period named the candidate for the first time;
        // an ambiguous period that holds it adds to a mean already started.
        let fresh = matches!(report.verdict, FaultVerdict::Suspected { periods: 1, .. });
        let continuing = !fresh && monitor.share_periods > 0;
        let kind = match &mut report.verdict {
            FaultVerdict::Suspected { kind, .. } | FaultVerdict::Confirmed { kind, .. } => {
                Some(kind)
            }
            _ => None,
        };
        let candidate = monitor.state.candidate();
        let stuck = matches!(kind, Some(FaultKind::StuckGimbal));
        let share = match (candidate, raw) {
            (Some(i), Some(raw)) if !stuck => blocks.get(i).and_then(|m| {
                let c = monitor.forces.get(i)?;
                lost_share(&detector, &(raw - monitor.baseline), m.as_ref()?, c)
            }),
            _ => None,
        };
        let periods = match share {
            Some(_) if continuing => monitor.share_periods.saturating_add(1),
            Some(_) if kind.is_some() => 1,
            _ => 0,
        };
        if let Some(share) = share.filter(|_| periods > 0) {
            let n = T::from_u8(periods).unwrap_or_else(T::one);
            monitor.raw_share = if periods <= 1 {
                share
            } else {
                monitor.raw_share + (share - monitor.raw_share) / n
            };
        }
        monitor.share_periods = periods;
        if let Some(kind) = kind.filter(|_| periods > 0) {
            // The mean is clamped, not each period's share: clamped shares of a loss (about 1,
            // half of them above) average under 1 and read as a partial loss.
            *kind = loss_kind(monitor.raw_share.max(T::zero()).min(T::one()));
        }
        self.check_reports(&mut report);
        let Some(monitor) = self.fault.as_mut() else {
            return;
        };
        monitor.report = report;
        monitor.reported = true;
        // The baseline follows the slow model error, not a fault: held above half the threshold.
        if report.statistic <= report.threshold * lit(0.5) {
            // `L_b dt`, the baseline's gain (first order in `L_b dt`, which is small).
            let slow = lit::<T>(FAULT_BASELINE_BANDWIDTH) * period;
            monitor.baseline += (monitor.residual - monitor.baseline) * slow;
        }
        let FaultVerdict::Confirmed {
            agent,
            kind: FaultKind::Loss | FaultKind::LinkLoss,
        } = report.verdict
        else {
            return;
        };
        let refused_before = monitor
            .masked
            .as_ref()
            .is_some_and(|m| m.agent as usize == agent && m.refused);
        if monitor.response != FaultResponse::Mask || refused_before {
            return;
        }
        // The persistent model error the baseline holds stays; the fault's part leaves with
        // the agent.
        let baseline = monitor.baseline;
        let mut mask = self.failures;
        let hover = mask.set(agent, true).and_then(|()| self.set_failures(mask));
        if hover.is_ok() {
            let (torque, force) = wrench_parts(&baseline);
            let force = state.attitude * force;
            self.offset_free.reseed(force, torque);
        }
        if let Some(monitor) = self.fault.as_mut() {
            monitor.state.reset();
            if hover.is_ok() {
                monitor.residual = baseline;
            }
            monitor.masked = Stored::Present(Masked {
                // agent < N, a slot of the mask.
                agent: u16::try_from(agent).unwrap_or(u16::MAX),
                refused: hover.is_err(),
            });
        }
    }

    /// The allocation whose commands are sent for the coming period (its wrench `M f` and
    /// forces), for the next period's detection (nothing without detection).
    pub(super) fn note_allocation(&mut self, allocation: &Allocation<T, N>) {
        if let Some(monitor) = self.fault.as_mut() {
            let wrench = &allocation.wrench;
            // A non-finite wrench (refused before it is sent) is not recorded.
            if wrench.iter().all(|x| x.is_finite()) {
                if monitor.wrench == Vector6::zeros() {
                    // The first wrench after a reset: the actuators are taken to deliver it.
                    monitor.delivered = *wrench;
                }
                monitor.wrench = *wrench;
                monitor.forces = allocation.forces;
            }
        }
    }

    /// The held commands changed without an allocation (seeded, or kept across a
    /// reconfiguration): the detector reads their forces from now on.
    pub(super) fn note_held_commands(&mut self) {
        if let Some(monitor) = self.fault.as_mut() {
            for (f, c) in monitor.forces.iter_mut().zip(&self.previous) {
                *f = command_force(c);
            }
        }
    }

    /// The detector's report of the last law stage: verdict, statistic, threshold, misfits
    /// (`None` when detection is off, before the first period, or while landed).
    pub fn fault_report(&self) -> Option<&FaultReport<T>> {
        self.fault
            .as_ref()
            .and_then(|m| m.reported.then_some(&m.report))
    }

    /// The last mask the controller set itself on a confirmed loss (`None` if it never did),
    /// with the hover certificate of the mask in force.
    pub fn fault_masking(&self) -> Option<FaultMasking<T>> {
        let m = self.fault.as_ref()?.masked.get()?;
        Some(FaultMasking {
            agent: m.agent as usize,
            hover: (!m.refused).then_some(self.hover.into()),
        })
    }
}

/// The agent-frame force `T a_hat(eta_x, eta_y)` of a command, with [`sin_cos`] (in `f32`
/// arithmetic for `f32`: no software double precision on a single-precision FPU).
fn command_force<T: Real>(c: &AgentCommand<T>) -> Vector3<T> {
    let (sx, cx) = sin_cos(c.eta_x);
    let (sy, cy) = sin_cos(c.eta_y);
    Vector3::new(cx * sy, -sx, cx * cy) * c.thrust
}

impl<T: Real, const N: usize> FaultMonitor<T, N> {
    /// Whether the monitor at `this` holds valid tags: the response's, the candidate's, the
    /// report's (and its verdict's, kind's and source's) and the masking's (and its flag).
    /// Reads only.
    ///
    /// # Safety
    /// `this` is aligned and points to `size_of::<Self>()` readable bytes.
    pub(super) unsafe fn storage_intact(this: *const Self) -> bool {
        tag_below(addr_of!((*this).response), 2)
            && FaultState::storage_intact(addr_of!((*this).state))
            && bool_intact(addr_of!((*this).reported))
            && FaultReport::storage_intact(addr_of!((*this).report))
            && Stored::storage_intact(addr_of!((*this).masked), |m| {
                bool_intact(addr_of!((*m).refused))
            })
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::indexing_slicing)]
    use super::*;
    use nalgebra::Matrix6x3;

    #[test]
    fn the_detector_reads_the_forces_of_the_held_commands() {
        use crate::team::presets;
        use crate::{FaultDetection, RedistributedPseudoInverse, Reference};
        type C = Controller<f64, 4, RedistributedPseudoInverse>;
        let team = presets::a4_inc::<f64, 4>().unwrap();
        let settings = ControllerSettings {
            fault_detection: Some(FaultDetection::recommended(FaultResponse::Report)),
            ..ControllerSettings::offset_free_law()
        };
        let mut c = C::new(team, settings, RedistributedPseudoInverse).unwrap();
        let forces = |c: &C| c.fault.as_ref().unwrap().forces;
        let of_commands = |c: &C| c.previous.map(|cmd| command_force(&cmd));
        let close = |a: [Vector3<f64>; 4], b: [Vector3<f64>; 4]| {
            a.iter()
                .zip(&b)
                .all(|(a, b)| (a - b).norm() <= 1e-6 * b.norm().max(1.0))
        };
        assert_eq!(forces(&c), [Vector3::zeros(); 4]);
        let at = Vector3::new(0.0, 0.0, 1.5);
        let mut reference = Reference::hover(at);
        reference.attitude = crate::foundation::rotation::roll(0.3);
        let out = c.step(&RigidState::at_rest(at), &reference).unwrap();
        // The allocation's forces, which the sent commands carry up to the inversion's
        // round-off.
        assert_eq!(forces(&c), out.allocation.forces);
        assert!(forces(&c).iter().any(|f| f.norm() > 1.0));
        assert!(close(forces(&c), of_commands(&c)));
        // A reset forgets them with the commands; seeded commands bring their own.
        c.reset();
        assert_eq!(forces(&c), [Vector3::zeros(); 4]);
        c.seed_commands(&out.commands).unwrap();
        assert_eq!(forces(&c), of_commands(&c));
        assert!(close(forces(&c), out.allocation.forces));
        // A reconfiguration keeps the held commands, and the detector their forces.
        c.reconfigure(&team, &settings, || RedistributedPseudoInverse)
            .unwrap();
        assert_eq!(c.previous, out.commands);
        assert_eq!(forces(&c), of_commands(&c));
    }

    #[test]
    fn a_period_share_is_not_clamped_so_a_mean_of_a_loss_stays_at_one() {
        let d = FaultDetector::<f64>::new(0.2, 0.02, 5.0, 5).unwrap();
        let mut m = Matrix6x3::<f64>::zeros();
        m.fixed_view_mut::<3, 3>(3, 0).fill_with_identity();
        let f = Vector3::new(0.0, 0.0, 7.0);
        let lost = -(m * f);
        // A loss read with noise either way: 1.6 and 0.4 of the lost wrench.
        let (hi, lo) = (
            lost_share(&d, &(lost * 1.6), &m, &f).unwrap(),
            lost_share(&d, &(lost * 0.4), &m, &f).unwrap(),
        );
        assert!((hi - 1.6).abs() < 1e-12 && (lo - 0.4).abs() < 1e-12);
        // Their mean is a loss; the mean of the clamped shares (0.7) was a partial loss.
        let mean: f64 = (hi + lo) / 2.0;
        assert_eq!(loss_kind(mean.min(1.0)), FaultKind::Loss);
        assert!(matches!(
            loss_kind((hi.min(1.0) + lo) / 2.0),
            FaultKind::PartialLoss { .. }
        ));
        // No command, no share.
        assert!(lost_share(&d, &lost, &m, &Vector3::zeros()).is_none());
    }
}

#[cfg(test)]
#[path = "detection_storage_tests.rs"]
mod storage_tests;
