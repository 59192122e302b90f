//! The control cycle: planner, projection, law, allocation and inversion composed into one
//! `step` per control period.

use nalgebra::Vector3;

/// The roll `R_x(phi)`, at its old path (now in [`crate::rotation`]).
pub use crate::rotation::roll;

use crate::admissible::{admissible_sets, AdmissibleSet, RateLimits};
use crate::afs::{AttainableForceSpace, EllipticCone, Relaxation};
use crate::allocation::{
    Allocation, AllocationRequest, Allocator, NullSpaceReport, NullSpaceStage,
};
use crate::command::{invert, AgentCommand};
use crate::effectiveness::Effectiveness;
use crate::error::{ConfigError, ConfigField, InputError};
use crate::hover::{hover_capability, HoverCapability};
use crate::law::{control_wrench, force_request, Gains, LawOutput, Plant, Reference, RigidState};
use crate::planner::{AttitudePlanner, PlannerOutput};
use crate::projection::{project_force_in, ForceProjection};
use crate::real::{count, lit, to_f64, Real};
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
    /// Optional null-space stage run after the allocator ([`NullSpaceStage`]; `None`: the
    /// allocator's forces are used as they are, and [`ControlOutput::null_space`] is
    /// [`NullSpaceReport::off`]).
    pub null_space: Option<NullSpaceStage<T>>,
}

impl<T: Real> ControllerSettings<T> {
    /// The paper's settings: its gains, `s = 0.5`, `g = 9.81`, `dt = 0.01` s, no rate limits,
    /// no null-space stage.
    pub fn paper() -> Self {
        Self {
            gains: Gains::paper(),
            relaxation: Relaxation::new(lit(0.5)).unwrap_or(Relaxation::none()),
            gravity: lit(crate::team::presets::GRAVITY),
            period: lit(0.01),
            rate_limits: None,
            null_space: None,
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
    /// The allocation: forces, allocated wrench, `e_f`, rounds, saturated agents (after the
    /// null-space stage when one is set).
    pub allocation: Allocation<T, N>,
    /// What the null-space stage changed ([`NullSpaceReport::off`] without one).
    pub null_space: NullSpaceReport<T>,
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
        settings.validate()?;
        // Also rejects a gravity whose weight m_C g overflows.
        let plant = Plant::new(team.mass(), team.inertia(), settings.gravity)?;
        let failures = FailureMask::none();
        let afs = team.afs(&failures)?;
        let effectiveness = team.effectiveness(&failures);
        let mut allocator = allocator;
        allocator.configure(&effectiveness);
        let input_limit = input_limit(&team, &settings);
        let admissible = AdmissibleSet::from_limits(team.limits());
        let hover = hover_capability(&effectiveness, &admissible, plant.weight());
        Ok(Self {
            input_limit,
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

    /// Forgets the previous command (rate limits restart from a centred gimbal) and whatever the
    /// allocator kept from earlier periods ([`Allocator::reset`]).
    pub fn reset(&mut self) {
        self.previous = [AgentCommand::idle(); N];
        self.allocator.reset();
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

    /// One control period: `u_fr`, projection `t_Tf`, planner (`R_d`), `K_f` and the torque part,
    /// allocation, and inversion to commands inside `E_f`.
    ///
    /// A non-finite or non-rotation input, or a component beyond [`Self::input_limit`]
    /// ([`InputError::OutOfRange`]), is rejected with a [`CycleError`] that carries the previous
    /// commands to hold. So is a period whose only answer to a finite, non-zero force request
    /// `u_fr` is zero thrust on every agent ([`InputError::Unattainable`]: never a silent free
    /// fall), and, as a safety net, one with a non-finite output ([`InputError::Overflow`]).
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
        self.check_range(state, reference).map_err(reject)?;
        let gains = &self.settings.gains;
        let u_fr = force_request(&self.plant, gains, state, reference);
        let projection = project_force_in(&self.full_cone, &u_fr);
        let f_r = state.attitude * u_fr * projection.t_tf;
        // `reference.attitude` passed `reference.validate()` above.
        let planner = self
            .planner
            .plan_in_valid_attitude(&self.planner_cone, &reference.attitude, &f_r)
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
        let request = AllocationRequest {
            effectiveness: &self.effectiveness,
            sets: &sets,
            wrench: law.u_d,
        };
        let allocation = self.allocator.allocate(&request);
        let (allocation, null_space) = match &self.settings.null_space {
            Some(stage) => stage.refine(&request, &allocation),
            None => (allocation, NullSpaceReport::off()),
        };
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
        let output = ControlOutput {
            planner,
            projection,
            f_r,
            law,
            allocation,
            null_space,
            commands,
            command_clamp,
        };
        // Never a silent free fall: zero thrust everywhere for a finite, non-zero request.
        if u_fr != Vector3::zeros() && commands.iter().all(|c| c.thrust == T::zero()) {
            return Err(reject(InputError::Unattainable {
                field: "force_request",
            }));
        }
        if let Some(field) = first_non_finite(&output) {
            return Err(reject(InputError::Overflow { field }));
        }
        self.previous = commands;
        Ok(output)
    }

    /// [`InputError::OutOfRange`] for the first vector input with a component beyond
    /// [`Self::input_limit`].
    fn check_range(
        &self,
        state: &RigidState<T>,
        reference: &Reference<T>,
    ) -> Result<(), InputError> {
        for (v, field) in [
            (&state.position, "state.position"),
            (&state.angular_velocity, "state.angular_velocity"),
            (&state.velocity, "state.velocity"),
            (&reference.position, "reference.position"),
            (&reference.velocity, "reference.velocity"),
            (&reference.acceleration, "reference.acceleration"),
            (&reference.angular_velocity, "reference.angular_velocity"),
            (
                &reference.angular_acceleration,
                "reference.angular_acceleration",
            ),
        ] {
            if v.iter().any(|x| x.abs() > self.input_limit) {
                return Err(InputError::OutOfRange {
                    field,
                    limit: to_f64(self.input_limit),
                });
            }
        }
        Ok(())
    }
}

/// `B` of [`Controller::input_limit`].
fn input_limit<T: Real, const N: usize>(
    team: &TeamConfig<T, N>,
    settings: &ControllerSettings<T>,
) -> T {
    let row = |k: &nalgebra::Matrix3<T>| k.amax() * lit(3.0);
    let gains = &settings.gains;
    let mass = team.mass();
    let quadratic = [
        row(&team.inertia()),
        row(&gains.k_x()),
        row(&gains.k_omega()),
        row(&gains.k_v()),
        mass,
    ]
    .iter()
    .fold(T::one(), |m, x| m.max(*x));
    let linear = [
        quadratic,
        row(&gains.k_r()),
        mass * settings.gravity,
        count::<T>(team.len()) * team.limits().max_thrust(),
    ]
    .iter()
    .fold(T::one(), |m, x| m.max(*x));
    let max = T::max_value().unwrap_or_else(T::one);
    (max / linear).min((max / quadratic).sqrt()) / lit(64.0)
}

/// The first output field with a non-finite number (the cycle's safety net). Cheap: each part
/// sums `x * 0`, which is NaN exactly when some `x` is not finite (one multiply-add per number).
fn first_non_finite<T: Real, const N: usize>(out: &ControlOutput<T, N>) -> Option<&'static str> {
    let zero = T::zero();
    let probe = |values: &[T]| values.iter().fold(zero, |acc, x| acc + *x * zero) == zero;
    let commands = out.commands.iter().fold(zero, |acc, c| {
        acc + (c.eta_x + c.eta_y + c.thrust + c.omega) * zero
    }) == zero;
    let forces = out
        .allocation
        .forces
        .iter()
        .fold(zero, |acc, f| acc + (f.x + f.y + f.z) * zero)
        == zero;
    let law = &out.law;
    if !commands {
        return Some("output.commands");
    }
    if !forces
        || !probe(out.allocation.wrench.as_slice())
        || !probe(&[out.allocation.e_f, out.allocation.wrench_error])
    {
        return Some("output.allocation");
    }
    if !probe(out.planner.r_d.as_slice()) || !probe(&[out.planner.theta]) {
        return Some("output.planner");
    }
    if !probe(out.projection.force.as_slice()) || !probe(out.f_r.as_slice()) {
        return Some("output.projection");
    }
    if !probe(law.u_r.as_slice())
        || !probe(law.u_d.as_slice())
        || !probe(law.e_xi.as_slice())
        || !probe(law.e_r.as_slice())
        || !probe(law.e_x.as_slice())
        || !probe(&[law.v_r, law.v_x])
    {
        return Some("output.law");
    }
    None
}
