//! The control cycle: planner, projection, law, allocation and inversion composed into one
//! `step` per control period.

use nalgebra::Vector3;

/// The roll `R_x(phi)`, at its old path (now in [`crate::rotation`]).
pub use crate::rotation::roll;

use crate::admissible::{admissible_sets, AdmissibleSet, RateLimits};
use crate::afs::{AttainableForceSpace, EllipticCone, Relaxation};
use crate::allocation::{Allocation, AllocationRequest, Allocator};
use crate::command::{invert, AgentCommand};
use crate::effectiveness::Effectiveness;
use crate::error::{ConfigError, ConfigField, InputError};
use crate::hover::{hover_capability, HoverCapability};
use crate::law::{control_wrench, force_request, Gains, LawOutput, Plant, Reference, RigidState};
use crate::planner::{AttitudePlanner, PlannerOutput};
use crate::projection::{project_force_in, ForceProjection};
use crate::real::{lit, Real};
use crate::team::{FailureMask, TeamConfig};

/// Settings of a [`Controller`] besides the team and the allocator.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ControllerSettings<T: Real> {
    /// Gains of eq. (12).
    pub gains: Gains<T>,
    /// AFS relaxation `s` of the planner.
    pub relaxation: Relaxation<T>,
    /// `g` (m/s^2).
    pub gravity: T,
    /// Control period `dt` (s), used by the rate limits.
    pub period: T,
    /// Optional gimbal rate limits (the rate-constrained allocation).
    pub rate_limits: Option<RateLimits<T>>,
}

impl<T: Real> ControllerSettings<T> {
    /// The paper's settings: its gains, `s = 0.5`, `g = 9.81`, `dt = 0.01` s, no rate limits.
    pub fn paper() -> Self {
        Self {
            gains: Gains::paper(),
            relaxation: Relaxation::new(lit(0.5)).unwrap_or(Relaxation::none()),
            gravity: lit(crate::team::presets::GRAVITY),
            period: lit(0.01),
            rate_limits: None,
        }
    }

    /// Gains, relaxation and rate limits are valid by construction (private fields); only the
    /// two plain numbers are checked here.
    fn validate(&self) -> Result<(), ConfigError> {
        for (value, field) in [
            (self.gravity, ConfigField::Gravity),
            (self.period, ConfigField::Period),
        ] {
            if !value.is_finite() || value <= T::zero() {
                return Err(ConfigError::Parameter { field });
            }
        }
        Ok(())
    }
}

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
    /// The allocation: forces, allocated wrench, `e_f`, rounds, saturated agents.
    pub allocation: Allocation<T, N>,
    /// Per-agent commands inside `E_f` (idle for failed agents and unused slots).
    pub commands: [AgentCommand<T>; N],
    /// Largest clamp the inversion applied (normalized; at most
    /// [`crate::command::command_tolerance`] when the allocator keeps its contract).
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
/// failure mask and the previous command. One [`Controller::step`] per control period.
#[derive(Clone, Debug)]
pub struct Controller<T: Real, const N: usize, A: Allocator<T, N>> {
    team: TeamConfig<T, N>,
    settings: ControllerSettings<T>,
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
    hover: HoverCapability<T>,
    previous: [AgentCommand<T>; N],
}

impl<T: Real, const N: usize, A: Allocator<T, N>> Controller<T, N, A> {
    /// A controller for a validated team.
    pub fn new(
        team: TeamConfig<T, N>,
        settings: ControllerSettings<T>,
        allocator: A,
    ) -> Result<Self, ConfigError> {
        settings.validate()?;
        // Also rejects a gravity whose weight m_C g overflows.
        let plant = Plant::new(team.mass(), team.inertia(), settings.gravity)?;
        let failures = FailureMask::none();
        let afs = team.afs(&failures)?;
        let effectiveness = team.effectiveness(&failures);
        let mut allocator = allocator;
        allocator.configure(&effectiveness);
        let admissible = AdmissibleSet::from_limits(team.limits());
        let hover = hover_capability(&effectiveness, &admissible, plant.weight());
        Ok(Self {
            full_cone: afs.cone(Relaxation::none()),
            planner_cone: afs.cone(settings.relaxation),
            afs,
            plant,
            planner: AttitudePlanner::new(settings.relaxation),
            effectiveness,
            admissible,
            hover,
            team,
            settings,
            allocator,
            failures,
            previous: [AgentCommand::idle(); N],
        })
    }

    /// Tells the controller which agents failed, and classifies the working agents: whether
    /// they can hold hover with a margin ([`crate::hover`]), so a caller can decide to land.
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
    /// assert_eq!(controller.hover_capability(), &hover);
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
        self.effectiveness = self.team.effectiveness(&failures);
        self.allocator.configure(&self.effectiveness);
        self.hover = hover_capability(&self.effectiveness, &self.admissible, self.plant.weight());
        self.failures = failures;
        Ok(self.hover)
    }

    /// Whether the working agents can hold hover with a margin, as classified when the
    /// failure mask was last set (or at [`Self::new`] for the full team).
    pub fn hover_capability(&self) -> &HoverCapability<T> {
        &self.hover
    }

    /// Replaces the planner (e.g. another tolerance); its relaxation becomes the controller's.
    pub fn set_planner(&mut self, planner: AttitudePlanner<T>) {
        self.settings.relaxation = planner.relaxation();
        self.planner_cone = self.afs.cone(planner.relaxation());
        self.planner = planner;
    }

    /// Forgets the previous command (rate limits restart from a centred gimbal).
    pub fn reset(&mut self) {
        self.previous = [AgentCommand::idle(); N];
    }

    /// The team.
    pub fn team(&self) -> &TeamConfig<T, N> {
        &self.team
    }

    /// The settings.
    pub fn settings(&self) -> &ControllerSettings<T> {
        &self.settings
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

    /// One control period: `u_fr`, projection `t_Tf`, planner (`R_d`), `K_f` and the torque part,
    /// allocation, and inversion to commands inside `E_f`.
    ///
    /// A non-finite or non-rotation input is rejected with a [`CycleError`] that carries the
    /// previous commands to hold.
    ///
    /// ```
    /// use tvmd_core::nalgebra::Vector3;
    /// use tvmd_core::rotation::roll;
    /// use tvmd_core::{team::presets, Controller, ControllerSettings, RedistributedPseudoInverse};
    /// use tvmd_core::{PlannerStatus, Reference, RigidState};
    /// let team = presets::a4_inc::<f32, 4>()?;
    /// let mut controller =
    ///     Controller::new(team, ControllerSettings::paper(), RedistributedPseudoInverse)?;
    /// let mut reference = Reference::hover(Vector3::new(0.0, 0.0, 1.5));
    /// reference.attitude = roll(1.0); // beyond what the team can hold
    /// let state = RigidState::at_rest(Vector3::new(0.2, 0.0, 1.5));
    /// let out = controller.step(&state, &reference).unwrap();
    /// assert_eq!(out.planner.status, PlannerStatus::Planned);
    /// assert!(out.command_clamp <= tvmd_core::command::command_tolerance());
    /// // A NaN state is refused; the previous (admissible) commands are held.
    /// let mut bad = state;
    /// bad.position.x = f32::NAN;
    /// let held = controller.step(&bad, &reference).unwrap_err();
    /// assert_eq!(held.commands, out.commands);
    /// # Ok::<(), tvmd_core::ConfigError>(())
    /// ```
    pub fn step(
        &mut self,
        state: &RigidState<T>,
        reference: &Reference<T>,
    ) -> Result<ControlOutput<T, N>, CycleError<T, N>> {
        let reject = |error| CycleError {
            error,
            commands: self.previous,
        };
        state.validate().map_err(reject)?;
        reference.validate().map_err(reject)?;
        let gains = &self.settings.gains;
        let u_fr = force_request(&self.plant, gains, state, reference);
        let projection = project_force_in(&self.full_cone, &u_fr);
        let f_r = state.attitude * u_fr * projection.t_tf;
        let planner = self
            .planner
            .plan_in(&self.planner_cone, &reference.attitude, &f_r)
            .map_err(reject)?;
        let law = control_wrench(
            &self.plant,
            gains,
            state,
            reference,
            &planner.r_d,
            &u_fr,
            &projection.gain(),
        );
        let sets = self.admissible_sets();
        let allocation = self.allocator.allocate(&AllocationRequest {
            effectiveness: &self.effectiveness,
            sets: &sets,
            wrench: law.u_d,
        });
        let mut commands = [AgentCommand::idle(); N];
        let mut command_clamp = T::zero();
        for (i, ((cmd, force), set)) in commands
            .iter_mut()
            .zip(&allocation.forces)
            .zip(&sets)
            .enumerate()
        {
            if self.effectiveness.block(i).is_some() {
                let (c, clamp) = invert(force, set, self.team.limits());
                *cmd = c;
                command_clamp = command_clamp.max(clamp);
            }
        }
        self.previous = commands;
        Ok(ControlOutput {
            planner,
            projection,
            f_r,
            law,
            allocation,
            commands,
            command_clamp,
        })
    }
}
