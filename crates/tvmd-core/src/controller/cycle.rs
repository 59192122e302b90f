//! One control period as stages sharing the controller's state, so that each can run at its
//! own rate (a flight stack's position, attitude and allocation loops): [`Controller::plan`]
//! (the planner alone), [`Controller::law`] (state and reference in, the body wrench out:
//! `u_fr`, the projection, the planner and eq. 12) and [`Controller::allocate`] (a body wrench
//! in, commands inside `E_f` out); [`Controller::step`] runs the law and the allocation in a
//! row.

use nalgebra::{Matrix3, Vector3, Vector6};

use super::guard::{
    check_range, first_non_finite, first_non_finite_allocation, first_non_finite_law,
};
use super::{ControlOutput, Controller, CycleError};
use crate::afs::planner::{PlannerOutput, PlannerStatus};
use crate::afs::projection::{project_force_in, ForceProjection};
use crate::agent::command::{invert, AgentCommand};
use crate::allocation::{Allocation, AllocationRequest, Allocator, NullSpaceReport};
use crate::foundation::error::InputError;
use crate::foundation::linalg::norm;
use crate::foundation::real::Real;
use crate::foundation::rotation::validate_rotation;
use crate::foundation::stored::{bool_intact, Stored};
use crate::law::anti_windup::Saturation;
use crate::law::attitude_rate::PlannedRates;
use crate::law::offset_free::CycleRecord;
use crate::law::{attitude_law, control_wrench, force_request, AttitudeLaw, LawOutput};
use crate::law::{Reference, RigidState};

/// What the law stage produces ([`Controller::law`]): the planner's `R_d`, the projection, `f_r`
/// and the law, whose `law.u_d = [u_tau_d; u_fd]` (`{C}`) is the body wrench for
/// [`Controller::allocate`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LawStage<T: Real> {
    /// The planner's result: `R_d`, `theta`, iterations, status.
    pub planner: PlannerOutput<T>,
    /// The force projection: `K_f u_fr`, `t_Tf`, `t_eta`.
    pub projection: ForceProjection<T>,
    /// `f_r = t_Tf R u_fr` (N, `{I}`), the force the planner aligns with.
    pub f_r: Vector3<T>,
    /// The law: errors, `u_r`, `u_d`, Lyapunov values (eq. 12).
    pub law: LawOutput<T>,
}

/// What the allocation stage produces ([`Controller::allocate`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AllocationStage<T: Real, const N: usize> {
    /// The allocation: forces, allocated wrench `M f`, `e_f` (the force error), the whole
    /// wrench error, rounds, and per agent whether its force was saturated onto its set.
    pub allocation: Allocation<T, N>,
    /// What the null-space stage changed ([`NullSpaceReport::off`] without one).
    pub null_space: NullSpaceReport<T>,
    /// `||u_tau_d - u_tau||` (N m), the torque the team could not deliver (`e_f` is the force's).
    pub torque_error: T,
    /// Per-agent commands inside `E_f` (idle for failed agents and unused slots).
    pub commands: [AgentCommand<T>; N],
    /// Largest clamp the inversion applied ([`crate::agent::admissible::AdmissibleSet::excess`]: rad,
    /// or relative to the largest thrust).
    pub command_clamp: T,
}

/// What the offset-free state records at the end of a period besides the state, from the law
/// stage for the allocation that delivers its wrench.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct PendingRecord<T: Real> {
    e_x: Vector3<T>,
    e_r: Vector3<T>,
    t_tf: T,
    t_eta: T,
    unreachable: bool,
    u_d_norm: T,
}

impl<T: Real, const N: usize, A: Allocator<T, N>> Controller<T, N, A> {
    /// The planner alone (eqs. 9-11): the attitude `R_d` closest to `reference_attitude` (a
    /// rotation) whose AFS holds `force` (N, `{I}`: the force the team should produce), at the
    /// controller's relaxation and failure mask. Reads nothing else of the controller's state
    /// and changes none of it.
    ///
    /// Errors: [`InputError::NonFinite`] or [`InputError::NotRotation`] naming `planner.r_r` or
    /// `planner.f_r`.
    pub fn plan(
        &self,
        reference_attitude: &Matrix3<T>,
        force: &Vector3<T>,
    ) -> Result<PlannerOutput<T>, InputError> {
        self.planner
            .plan_in(&self.planner_cone, reference_attitude, force)
    }

    /// The law stage of a period: `u_fr` (with the offset-free compensation when configured),
    /// the projection, the planner, the planned rates when configured, and eq. 12; the body
    /// wrench `law.u_d` for [`Self::allocate`]. Errors as [`Self::step`]'s input checks, with
    /// the previous commands to hold. With an offset-free action, the allocation that follows
    /// (`allocate` or the rest of `step`) records the delivered wrench for the next period.
    pub fn law(
        &mut self,
        state: &RigidState<T>,
        reference: &Reference<T>,
    ) -> Result<LawStage<T>, CycleError<T, N>> {
        let (stage, _, pending) = self.law_stage(state, reference)?;
        // The safety net `step` has: a non-finite law is never handed on as a wrench.
        if let Some(field) =
            first_non_finite_law(&stage.planner, &stage.projection, &stage.f_r, &stage.law)
        {
            return Err(self.reject(InputError::Overflow { field }));
        }
        // Kept for the allocation that delivers this wrench (`allocate`).
        self.pending = pending.map(|p| (*state, p)).into();
        Ok(stage)
    }

    /// The attitude stage alone (a flight stack's attitude loop, run faster than the law stage
    /// that planned `r_d`): eq. (12)'s torque for the planned attitude `r_d` from this
    /// `state`, with `reference`'s `Omega_d`, `Omega_d_dot` (the planned ones of the last law
    /// stage when the rate filter is on) and the offset-free torque. The body force to pair it
    /// with is the law stage's inertial force rotated into this state's body frame. Changes
    /// nothing.
    ///
    /// Errors: a non-finite or non-rotation `state` or `r_d`, non-finite reference rates.
    pub fn attitude(
        &self,
        state: &RigidState<T>,
        r_d: &Matrix3<T>,
        reference: &Reference<T>,
    ) -> Result<AttitudeLaw<T>, InputError> {
        state.validate()?;
        validate_rotation(r_d, "planner.r_d")?;
        reference.validate()?;
        let rates = match self.planned_rates() {
            Some(p) => with_rates(reference, &p),
            None => *reference,
        };
        let mut law = attitude_law(&self.plant, &self.gains, state, &rates, r_d);
        if self.offset_free.is_on() {
            law.u_tau += self.offset_free.compensation().torque;
        }
        Ok(law)
    }

    /// The allocation stage of a period: `wrench = [u_tau; u_f]` (N m, N; `{C}`) to per-agent
    /// commands inside `E_f` (eq. 6), the drop-in for a flight stack's control allocation. The
    /// commands become the held ones (and the rate limits' centre).
    ///
    /// Errors, with the previous commands to hold: a non-finite wrench
    /// ([`InputError::NonFinite`] naming `wrench`), zero thrust on every agent for a non-zero
    /// force ([`InputError::Unattainable`]), a non-finite result ([`InputError::Overflow`]).
    pub fn allocate(
        &mut self,
        wrench: &Vector6<T>,
    ) -> Result<AllocationStage<T, N>, CycleError<T, N>> {
        if !wrench.iter().all(|x| x.is_finite()) {
            return Err(self.reject(InputError::NonFinite { field: "wrench" }));
        }
        let stage = self.allocation_stage(wrench);
        let force = wrench.fixed_rows::<3>(3);
        if force.iter().any(|x| *x != T::zero()) && all_idle(&stage.commands) {
            return Err(self.reject(InputError::Unattainable { field: "wrench" }));
        }
        let checked = first_non_finite_allocation(&stage.commands, &stage.allocation)
            .or((!stage.torque_error.is_finite()).then_some("output.allocation"));
        if let Some(field) = checked {
            return Err(self.reject(InputError::Overflow { field }));
        }
        self.note_allocation(&stage.allocation);
        self.previous = stage.commands;
        if let Some((state, pending)) = self.pending.take() {
            self.finish_offset_free(&state, pending, &stage.allocation);
        }
        Ok(stage)
    }

    /// One control period: `u_fr`, projection `t_Tf`, planner (`R_d`), `K_f` and the torque part,
    /// allocation, and inversion to commands inside `E_f` ([`Self::law`] then
    /// [`Self::allocate`]).
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
        let (law, u_fr, pending) = self.law_stage(state, reference)?;
        // A law stage run on its own before this step is superseded.
        self.pending = Stored::Absent;
        let stage = self.allocation_stage(&law.law.u_d);
        let output = ControlOutput {
            planner: law.planner,
            projection: law.projection,
            f_r: law.f_r,
            law: law.law,
            allocation: stage.allocation,
            null_space: stage.null_space,
            commands: stage.commands,
            command_clamp: stage.command_clamp,
        };
        // Never a silent free fall: zero thrust everywhere for a finite, non-zero request.
        let error = if u_fr != Vector3::zeros() && all_idle(&output.commands) {
            Some(InputError::Unattainable {
                field: "force_request",
            })
        } else {
            first_non_finite(&output).map(|field| InputError::Overflow { field })
        };
        if let Some(error) = error {
            return Err(self.reject(error));
        }
        self.note_allocation(&output.allocation);
        self.previous = output.commands;
        if let Some(pending) = pending {
            self.finish_offset_free(state, pending, &output.allocation);
        }
        Ok(output)
    }

    /// The law stage, `u_fr` (for `step`'s zero-thrust check) and, with an offset-free action,
    /// what its record needs once the wrench is allocated.
    #[allow(clippy::type_complexity)]
    fn law_stage(
        &mut self,
        state: &RigidState<T>,
        reference: &Reference<T>,
    ) -> Result<(LawStage<T>, Vector3<T>, Option<PendingRecord<T>>), CycleError<T, N>> {
        let checked = state
            .validate()
            .and_then(|()| reference.validate())
            .and_then(|()| check_range(self.input_limit, state, reference));
        if let Err(error) = checked {
            return Err(self.reject(error));
        }
        let mut u_fr = force_request(&self.plant, &self.gains, state, reference);
        // Offset-free: the compensation joins the request before the projection and the
        // planner (skipped entirely when off, so the paper's cycle is bit for bit unchanged).
        let compensation = if self.offset_free.is_on() {
            self.offset_free.begin(&self.plant, state);
            // The detector reads the estimate just measured (and may mask an agent now).
            self.detect_faults(state);
            let c = self.offset_free.compensation();
            u_fr += state.attitude.transpose() * c.force;
            Some(c)
        } else {
            None
        };
        let gains = &self.gains;
        let projection = project_force_in(&self.full_cone, &u_fr);
        let f_r = state.attitude * u_fr * projection.t_tf;
        // `reference.attitude` passed `reference.validate()` above.
        let planner =
            match self
                .planner
                .plan_in_valid_attitude(&self.planner_cone, &reference.attitude, &f_r)
            {
                Ok(planner) => planner,
                Err(error) => return Err(self.reject(error)),
            };
        // The planned attitude's rates replace the reference's when the filter is on.
        let planned = self.attitude_rate.as_mut().map(|f| f.update(&planner.r_d));
        // One call per case: a `Reference` copied only when the planned rates replace the
        // reference's (about 140 instructions and 90 B of stack less on the Cortex-M4F).
        let law_of = |law_reference: &Reference<T>| {
            control_wrench(
                &self.plant,
                gains,
                state,
                law_reference,
                &planner.r_d,
                &u_fr,
                &projection.gain(),
            )
        };
        let mut law = match planned {
            Some(rates) => law_of(&with_rates(reference, &rates)),
            None => law_of(reference),
        };
        let pending = match compensation {
            Some(c) => {
                add_torque(&mut law, &c.torque);
                Some(PendingRecord {
                    e_x: law.e_x,
                    e_r: law.e_r,
                    t_tf: projection.t_tf,
                    t_eta: projection.t_eta,
                    unreachable: planner.status == PlannerStatus::Unreachable,
                    u_d_norm: norm(&law.u_d),
                })
            }
            None => None,
        };
        let stage = LawStage {
            planner,
            projection,
            f_r,
            law,
        };
        Ok((stage, u_fr, pending))
    }

    /// The allocation of `wrench`, the null-space stage and the inversion, without the checks
    /// and without committing the commands.
    fn allocation_stage(&mut self, wrench: &Vector6<T>) -> AllocationStage<T, N> {
        let sets = self.admissible_sets();
        let request = AllocationRequest {
            effectiveness: &self.effectiveness,
            sets: &sets,
            wrench: *wrench,
        };
        let allocation = self.allocator.allocate(&request);
        // Without the feature `validate` refuses a stage, so `None` is the only case left.
        let (allocation, null_space) = match self.settings.null_space.as_ref() {
            #[cfg(feature = "null-space")]
            Some(stage) => stage.refine(&request, &allocation),
            _ => (allocation, NullSpaceReport::off()),
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
        let torque_error =
            norm(&(wrench.fixed_rows::<3>(0) - allocation.wrench.fixed_rows::<3>(0)));
        AllocationStage {
            allocation,
            null_space,
            torque_error,
            commands,
            command_clamp,
        }
    }

    /// End of a period whose commands were sent: the offset-free state records, for the
    /// period's `state`, the wrench delivered (`allocation.wrench`) and what was short.
    fn finish_offset_free(
        &mut self,
        state: &RigidState<T>,
        p: PendingRecord<T>,
        allocation: &Allocation<T, N>,
    ) {
        let saturation = Saturation::from_cycle(
            p.t_tf,
            p.t_eta,
            p.unreachable,
            allocation.wrench_error,
            p.u_d_norm,
        );
        let record = CycleRecord {
            e_x: p.e_x,
            e_r: p.e_r,
            wrench: allocation.wrench,
            saturation,
        };
        self.offset_free.end(&self.plant, state, &record);
    }

    /// A refused period: why, and the previous commands to hold.
    fn reject(&self, error: InputError) -> CycleError<T, N> {
        CycleError {
            error,
            commands: self.previous,
        }
    }
}

/// `reference` with the planned attitude's rates in place of its `Omega_d`, `Omega_d_dot`.
fn with_rates<T: Real>(reference: &Reference<T>, rates: &PlannedRates<T>) -> Reference<T> {
    Reference {
        angular_velocity: rates.omega_d,
        angular_acceleration: rates.omega_d_dot,
        ..*reference
    }
}

fn all_idle<T: Real, const N: usize>(commands: &[AgentCommand<T>; N]) -> bool {
    commands.iter().all(|c| c.thrust == T::zero())
}

/// Adds the offset-free torque to `u_tau_r` in `u_r` and `u_d` (`K_f` leaves the torque part
/// as it is, eq. 12).
fn add_torque<T: Real>(law: &mut LawOutput<T>, torque: &Vector3<T>) {
    for (k, t) in torque.iter().enumerate() {
        if let (Some(r), Some(d)) = (law.u_r.get_mut(k), law.u_d.get_mut(k)) {
            *r += *t;
            *d += *t;
        }
    }
}

impl<T: Real> PendingRecord<T> {
    /// Whether the record at `this` holds a valid flag (its other fields are numbers).
    ///
    /// # Safety
    /// `this` is aligned and points to `size_of::<Self>()` readable bytes.
    pub(super) unsafe fn storage_intact(this: *const Self) -> bool {
        bool_intact(core::ptr::addr_of!((*this).unreachable))
    }
}

#[cfg(test)]
mod storage_tests {
    use super::*;
    use crate::foundation::stored::{accepts, refuses};

    #[test]
    fn an_invalid_flag_is_refused() {
        let check = PendingRecord::<f32>::storage_intact;
        let r = PendingRecord {
            e_x: Vector3::zeros(),
            e_r: Vector3::zeros(),
            t_tf: 1.0_f32,
            t_eta: 1.0,
            unreachable: true,
            u_d_norm: 1.0,
        };
        assert!(accepts(&r, check));
        let flag = |p: *mut PendingRecord<f32>| unsafe {
            core::ptr::addr_of_mut!((*p).unreachable).cast()
        };
        assert!(refuses(&r, 2, flag, check));
    }
}
