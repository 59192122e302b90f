//! The control cycle: planner, projection, law, allocation and inversion composed into one
//! `step` per control period.

use nalgebra::Vector3;

/// The roll `R_x(phi)`, at its old path (now in [`crate::foundation::rotation`]).
pub use crate::foundation::rotation::roll;

mod build;
mod cycle;
mod detection;
mod guard;
mod reconfigure;
mod reports;
mod settings;
mod storage;

pub use crate::fault::detection::{
    FaultDetection, FaultResponse, FAULT_BASELINE_BANDWIDTH, FAULT_MODEL_ERROR, FAULT_PERSISTENCE,
    FAULT_THRESHOLD,
};
pub use cycle::{AllocationStage, LawStage};
pub use detection::FaultMasking;

pub use settings::{
    ControllerSettings, ATTITUDE_DAMPING, ATTITUDE_FREQUENCY, ATTITUDE_RATE_BANDWIDTH,
    ATTITUDE_RATE_MAX, DAMPING_RATIO, MAX_PERIOD, MIN_PERIOD, OBSERVER_BANDWIDTH,
    OFFSET_FREE_MAX_TORQUE, POSITION_FREQUENCY,
};

use crate::afs::hover::{hover_capability, HoverCapability, StoredHover};
use crate::afs::planner::{AttitudePlanner, PlannerOutput};
use crate::afs::projection::ForceProjection;
use crate::afs::{AttainableForceSpace, EllipticCone, Relaxation};
use crate::agent::admissible::{admissible_sets, AdmissibleSet};
use crate::agent::command::AgentCommand;
use crate::agent::effectiveness::Effectiveness;
use crate::allocation::{Allocation, Allocator, NullSpaceReport};
use crate::fault::ReportState;
use crate::foundation::error::{ConfigError, InputError};
use crate::foundation::real::Real;
use crate::foundation::stored::Stored;
use crate::law::attitude_rate::{AttitudeRateState, PlannedRates};
use crate::law::offset_free::{Compensation, OffsetFreeState};
use crate::law::{Gains, LawOutput, Plant, RigidState};
use crate::team::{FailureMask, TeamConfig};

/// Every quantity of one control period.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ControlOutput<T: Real, const N: usize> {
    /// The planner's result: `R_d`, `theta`, iterations, status.
    pub planner: PlannerOutput<T>,
    /// The force projection: `K_f u_fr`, `t_Tf`, `t_eta`.
    pub projection: ForceProjection<T>,
    /// `f_r = t_Tf R u_fr`, the inertial force the planner aligns with.
    pub f_r: Vector3<T>,
    /// The law: `e_x`, `e_R`, `e_xi`, `u_r`, `u_d`, `V_R`, `V_x`.
    pub law: LawOutput<T>,
    /// The allocation: forces, allocated wrench, `e_f`, rounds, saturated agents (after the
    /// null-space stage when one is set).
    pub allocation: Allocation<T, N>,
    /// What the null-space stage changed ([`NullSpaceReport::off`] without one).
    pub null_space: NullSpaceReport<T>,
    /// Per-agent commands inside `E_f` (idle for failed agents and unused slots).
    pub commands: [AgentCommand<T>; N],
    /// Largest clamp the inversion applied ([`crate::agent::admissible::AdmissibleSet::excess`]: rad,
    /// or relative to the largest thrust; at most
    /// [`crate::agent::command::command_tolerance`] when the allocator keeps its contract).
    pub command_clamp: T,
}

/// A cycle that could not run: why, and the safe commands to send instead (the previous
/// period's commands held, which are inside `E_f`; idle before the first period).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CycleError<T: Real, const N: usize> {
    /// The offending input.
    pub error: InputError,
    /// Commands to hold.
    pub commands: [AgentCommand<T>; N],
}

impl<T: Real, const N: usize> core::fmt::Display for CycleError<T, N> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(
            f,
            "control cycle skipped, holding the previous command: {}",
            self.error
        )
    }
}

#[cfg(feature = "std")]
impl<T: Real, const N: usize> std::error::Error for CycleError<T, N> {}

/// The full-pose controller of a team: configuration, gains, planner relaxation, allocator,
/// failure mask, the previous command and, when configured, the offset-free state and the
/// planned-rate filter. One [`Controller::step`] per control period.
#[derive(Clone, Debug)]
// `repr(C)`: fields in declaration order, which the C interface's flash build writes and checks
// in 80 B less code than Rust's reordering.
#[repr(C)]
pub struct Controller<T: Real, const N: usize, A: Allocator<T, N>> {
    team: TeamConfig<T, N>,
    /// The settings, their optional parts in [`Stored`]s ([`settings::StoredSettings`]).
    settings: settings::StoredSettings<T>,
    /// The law's gains: `settings.gains` resolved by `settings.gain_schedule` for the team.
    gains: Gains<T>,
    /// The offset-free state (inert when `settings.offset_free` is `None`).
    offset_free: OffsetFreeState<T>,
    /// The planned-rate filter (`None` when `settings.attitude_rate` is).
    attitude_rate: Stored<AttitudeRateState<T>>,
    /// The fault detector (`None` when `settings.fault_detection` is).
    fault: Stored<detection::FaultMonitor<T, N>>,
    /// The agents' reports ([`Self::set_report`]; taken only while `fault` runs).
    reports: ReportState<T, N>,
    /// What the offset-free state records once the law stage's wrench is allocated.
    pending: Stored<(RigidState<T>, cycle::PendingRecord<T>)>,
    plant: Plant<T>,
    planner: AttitudePlanner<T>,
    allocator: A,
    failures: FailureMask<N>,
    afs: AttainableForceSpace<T>,
    /// `afs` at `s = 1` (projection) and at the planner's `s`, kept between periods.
    full_cone: EllipticCone<T>,
    planner_cone: EllipticCone<T>,
    effectiveness: Effectiveness<T, N>,
    admissible: AdmissibleSet<T>,
    /// The classification of the working agents, computed when the mask is set.
    hover: StoredHover<T>,
    previous: [AgentCommand<T>; N],
    /// The bound on every input component ([`Self::input_limit`]).
    input_limit: T,
}

impl<T: Real, const N: usize, A: Allocator<T, N>> Controller<T, N, A> {
    /// A controller for a validated team.
    pub fn new(
        team: TeamConfig<T, N>,
        settings: ControllerSettings<T>,
        allocator: A,
    ) -> Result<Self, ConfigError> {
        let mut slot = core::mem::MaybeUninit::uninit();
        Self::init_in(&mut slot, &team, &settings, move || allocator)?;
        // SAFETY: `init_in` returned `Ok`, so it initialized every field.
        Ok(unsafe { slot.assume_init() })
    }

    /// Tells the controller which agents failed, and classifies the working agents: whether
    /// they can hold hover with a margin ([`crate::afs::hover`]), so a caller can decide to land.
    /// The classification is computed here, once per mask, and kept
    /// ([`Self::hover_capability`]). Errors (and keeps the old mask) if the remaining team
    /// cannot produce every wrench.
    ///
    /// ```
    /// use tvmd_core::{team::presets, Controller, ControllerSettings, FailureMask};
    /// use tvmd_core::RedistributedPseudoInverse;
    /// let team = presets::a4_inc::<f32, 4>()?;
    /// let mut controller =
    ///     Controller::new(team, ControllerSettings::paper(), RedistributedPseudoInverse)?;
    /// assert!(controller.hover_capability().capable);
    /// // Rank 6 is kept, but three agents at z = 0 cannot hold hover with a margin.
    /// let hover = controller.set_failures(FailureMask::with_failed(&[2])?)?;
    /// assert!(!hover.capable);
    /// assert_eq!(controller.hover_capability(), hover);
    /// # Ok::<(), tvmd_core::ConfigError>(())
    /// ```
    pub fn set_failures(
        &mut self,
        failures: FailureMask<N>,
    ) -> Result<HoverCapability<T>, ConfigError> {
        self.team.validate_failures(&failures)?;
        self.afs = self.team.afs(&failures)?;
        self.full_cone = self.afs.cone(Relaxation::none());
        self.planner_cone = self.afs.cone(self.settings.relaxation);
        self.team
            .effectiveness_into(&failures, &mut self.effectiveness);
        self.allocator.configure(&self.effectiveness);
        let hover = hover_capability(&self.effectiveness, &self.admissible, self.plant.weight());
        self.hover = hover.into();
        self.failures = failures;
        self.offset_free.set_force_bound(self.afs.max_force());
        Ok(hover)
    }

    /// Whether the working agents can hold hover with a margin, as classified when the
    /// failure mask was last set (or at [`Self::new`] for the full team). A copy: the
    /// controller keeps it in a form whose every tag [`Self::storage_intact`] can check.
    pub fn hover_capability(&self) -> HoverCapability<T> {
        self.hover.into()
    }

    /// Replaces the planner (e.g. another tolerance); its relaxation becomes the controller's.
    pub fn set_planner(&mut self, planner: AttitudePlanner<T>) {
        self.settings.relaxation = planner.relaxation();
        self.planner_cone = self.afs.cone(planner.relaxation());
        self.planner = planner;
    }

    /// Forgets the previous command (rate limits restart from a centred gimbal), whatever the
    /// allocator kept from earlier periods ([`Allocator::reset`]), the offset-free state (zero
    /// estimate or integral), the fault detector's candidate, report and the agents' reports
    /// ([`Self::set_report`]; a mask it set stays)
    /// and the planned-rate filter (at rest). The landed flag
    /// ([`Self::set_landed`]) is the caller's input and is kept.
    pub fn reset(&mut self) {
        self.previous = [AgentCommand::idle(); N];
        self.allocator.reset();
        self.offset_free.reset();
        self.pending = Stored::Absent;
        if let Some(fault) = self.fault.as_mut() {
            fault.reset();
        }
        self.reports.clear();
        if let Some(rates) = self.attitude_rate.as_mut() {
            rates.reset();
        }
    }

    /// Tells the controller whether the team stands on the ground (the caller's contact or
    /// landing detector). While landed the offset-free state is cleared and held at zero: the
    /// ground's reaction is not a disturbance to compensate, and nothing integrates against
    /// it; after take-off (`false`) it starts again from zero. No effect on anything else, and
    /// none without [`ControllerSettings::offset_free`].
    pub fn set_landed(&mut self, landed: bool) {
        self.offset_free.set_landed(landed);
    }

    /// Whether the landed hold is on ([`Self::set_landed`]).
    pub fn landed(&self) -> bool {
        self.offset_free.landed()
    }

    /// The wrench the offset-free state adds to the next period's request (before it measures
    /// that period): force in `{I}`, torque in `{C}`; zero when off or landed. The observer's
    /// estimate of the disturbance is its negative.
    pub fn offset_free_compensation(&self) -> Compensation<T> {
        self.offset_free.compensation()
    }

    /// The planned attitude's rates of the last period (`None` without
    /// [`ControllerSettings::attitude_rate`]).
    pub fn planned_rates(&self) -> Option<PlannedRates<T>> {
        self.attitude_rate.as_ref().map(AttitudeRateState::rates)
    }

    /// The law's gains: [`ControllerSettings::gains`] resolved for the team by
    /// [`ControllerSettings::gain_schedule`].
    pub fn gains(&self) -> &Gains<T> {
        &self.gains
    }

    /// The team.
    pub fn team(&self) -> &TeamConfig<T, N> {
        &self.team
    }

    /// The settings (a copy: the controller keeps them in a form whose every tag
    /// [`Self::storage_intact`] can check).
    pub fn settings(&self) -> ControllerSettings<T> {
        self.settings.into()
    }

    /// The failure mask in use.
    pub fn failures(&self) -> &FailureMask<N> {
        &self.failures
    }

    /// The AFS of the working agents.
    pub fn afs(&self) -> &AttainableForceSpace<T> {
        &self.afs
    }

    /// `M(Xi)` of the working agents.
    pub fn effectiveness(&self) -> &Effectiveness<T, N> {
        &self.effectiveness
    }

    /// The allocator.
    pub fn allocator(&self) -> &A {
        &self.allocator
    }

    /// The bound `B` on `|component|` of every vector input of [`Self::step`] (positions,
    /// velocities, accelerations, angular velocities and accelerations of state and reference):
    /// beyond it the cycle returns [`InputError::OutOfRange`]. Derived once in [`Self::new`]
    /// from the team's own scales so that every product of the cycle stays finite:
    /// `B = (1/64) min(MAX / S1, sqrt(MAX / S2))`, with `S1` the largest linear coefficient
    /// (`1`, `m_C`, `m_C g`, `n sigma_Tf` and `3 max|.|` of `J_C`, `K_x`, `K_R`, `K_Omega`,
    /// `K_v`) and `S2` the largest quadratic one (`1`, `m_C` and `3 max|.|` of `J_C`, `K_x`,
    /// `K_Omega`, `K_v`: `[J Omega]x Omega_d` and the Lyapunov values). The allocators take any
    /// finite wrench (they scale a huge one, `docs/method.md`), so the Gram matrix's
    /// conditioning does not enter. For the paper's A4-Inc with the paper's settings:
    /// `5.9e16` in `f32` and `4.3e151` in `f64` (`S2 = 24`, from `K_Omega`).
    pub fn input_limit(&self) -> T {
        self.input_limit
    }

    /// The previous period's commands.
    pub fn previous_commands(&self) -> &[AgentCommand<T>; N] {
        &self.previous
    }

    /// Each agent's admissible set this period (rate-limited around the previous command when
    /// rate limits are set).
    pub fn admissible_sets(&self) -> [AdmissibleSet<T>; N] {
        admissible_sets(
            &self.admissible,
            self.settings
                .rate_limits
                .as_ref()
                .map(|r| (r, self.settings.period)),
            self.previous.iter().map(AgentCommand::gimbal),
        )
    }
}
