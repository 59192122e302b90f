//! The cycle's stages as entry points on the same handle, so that each runs at its own rate
//! (a flight stack's position and attitude loops, then its control allocation): `tvmd_law`
//! (state and reference in, the body wrench out), `tvmd_allocate` (a body wrench in, commands
//! out: the drop-in for a flight stack's control allocation), `tvmd_attitude` (the torque
//! for a planned attitude: a faster attitude loop between law periods) and `tvmd_plan` (the
//! planner alone). `tvmd_step` is `tvmd_law` then `tvmd_allocate`, bit for bit.

use tvmd_core::nalgebra::Vector6;

use crate::handle::{checked_size, held_commands, inner as inner_ref, inner_mut};
use crate::status::*;
use crate::types::*;
use crate::TVMD_MAX_AGENTS;

/// A body wrench `[u_tau; u_f]` in the team's body frame `{C}` (z up, as the state).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TvmdWrench {
    /// `sizeof(TvmdWrench)`.
    pub size: u32,
    /// `u_tau` (N m), body frame.
    pub torque: [f32; 3],
    /// `u_f` (N), body frame.
    pub force: [f32; 3],
}

/// What `tvmd_law` returns: the body wrench for `tvmd_allocate` and the law's diagnostics. On
/// an error every number is NaN and `planner_status`/`planner_iterations` are 0.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TvmdLawOutput {
    /// `sizeof(TvmdLawOutput)`, set by the caller.
    pub size: u32,
    /// The status `tvmd_law` returned.
    pub status: i32,
    /// `u_tau_d` (N m), body frame: the torque to allocate.
    pub torque: [f32; 3],
    /// `u_fd = K_f u_fr` (N), body frame: the force to allocate.
    pub force: [f32; 3],
    /// `R_d`, the planned attitude, row-major.
    pub planned_attitude: [f32; 9],
    /// `theta*` (rad).
    pub planner_theta: f32,
    /// One of `TVMD_PLANNER_*`.
    pub planner_status: u32,
    /// The planner's search steps.
    pub planner_iterations: u32,
    /// `e_x = x - x_r` (m), inertial frame.
    pub position_error: [f32; 3],
    /// `e_R` against `R_d` (rad), body frame.
    pub attitude_error: [f32; 3],
}

/// What `tvmd_allocate` returns. On an error `commands` are the held ones (as `tvmd_step`'s)
/// and every number is NaN, `saturated` 0.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TvmdAllocationOutput {
    /// `sizeof(TvmdAllocationOutput)`, set by the caller.
    pub size: u32,
    /// The status `tvmd_allocate` returned.
    pub status: i32,
    /// `n`; commands beyond it are idle.
    pub agent_count: u32,
    /// Per-agent commands inside `E_f` (idle for failed agents).
    pub commands: [TvmdAgentCommand; TVMD_MAX_AGENTS],
    /// The allocated torque `u_tau = (M f)_tau` (N m), body frame.
    pub allocated_torque: [f32; 3],
    /// The allocated force `u_f = (M f)_f` (N), body frame.
    pub allocated_force: [f32; 3],
    /// `||u_fd - u_f||` (N), the force the team could not deliver (`e_f`).
    pub force_error: f32,
    /// `||u_tau_d - u_tau||` (N m), the torque the team could not deliver.
    pub torque_error: f32,
    /// Bit `i` set: agent `i`'s force lies on the boundary of its admissible set (a gimbal or
    /// thrust limit holds it).
    pub saturated: u32,
}

/// What `tvmd_attitude` returns. On an error the numbers are NaN.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TvmdAttitudeOutput {
    /// `sizeof(TvmdAttitudeOutput)`, set by the caller.
    pub size: u32,
    /// The status `tvmd_attitude` returned.
    pub status: i32,
    /// `u_tau_d` (N m), body frame.
    pub torque: [f32; 3],
    /// `e_R` against the planned attitude (rad), body frame.
    pub attitude_error: [f32; 3],
}

/// The attitude stage alone: eq. (12)'s torque for `planned_attitude` (9 floats, row-major:
/// the last `tvmd_law`'s `planned_attitude`) from this `state`, with `reference`'s angular
/// velocity and acceleration (the planned ones with the law's rate filter) and the offset-free
/// torque. Pair it with the last law period's force rotated into this state's body frame
/// (`R^T R_law u_fd`) and call `tvmd_allocate`: an attitude and allocation loop faster than the
/// law's. Changes nothing.
///
/// # Safety
/// Each pointer is null or points to its struct (`planned_attitude` to 9 floats); `handle` as
/// for `tvmd_create`.
#[no_mangle]
pub unsafe extern "C" fn tvmd_attitude(
    handle: *const crate::handle::TvmdController,
    state: *const TvmdState,
    planned_attitude: *const f32,
    reference: *const TvmdReference,
    out: *mut TvmdAttitudeOutput,
) -> TvmdStatus {
    let Some(out) = out.as_mut() else {
        return TVMD_ERR_NULL_POINTER;
    };
    if let Err(status) = checked_size::<TvmdAttitudeOutput>(out.size) {
        return status;
    }
    let status = attitude_into(handle, state, planned_attitude, reference, out);
    if status != TVMD_OK {
        out.status = status;
        out.torque = [f32::NAN; 3];
        out.attitude_error = [f32::NAN; 3];
    }
    status
}

unsafe fn attitude_into(
    handle: *const crate::handle::TvmdController,
    state: *const TvmdState,
    planned_attitude: *const f32,
    reference: *const TvmdReference,
    out: &mut TvmdAttitudeOutput,
) -> TvmdStatus {
    let controller = match inner_ref(handle) {
        Ok(inner) => &inner.controller,
        Err(status) => return status,
    };
    let (Some(state), Some(r_d), Some(reference)) = (
        state.as_ref(),
        planned_attitude.cast::<[f32; 9]>().as_ref(),
        reference.as_ref(),
    ) else {
        return TVMD_ERR_NULL_POINTER;
    };
    if let Err(status) = checked_size::<TvmdState>(state.size)
        .and_then(|()| checked_size::<TvmdReference>(reference.size))
    {
        return status;
    }
    match controller.attitude(&state.to_core(), &matrix(r_d), &reference.to_core()) {
        Ok(law) => {
            out.status = TVMD_OK;
            out.torque = law.u_tau.into();
            out.attitude_error = law.e_r.into();
            TVMD_OK
        }
        Err(e) => input_status(&e),
    }
}

/// What `tvmd_plan` returns. On an error the numbers are NaN and the counts 0.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TvmdPlanOutput {
    /// `sizeof(TvmdPlanOutput)`, set by the caller.
    pub size: u32,
    /// The status `tvmd_plan` returned.
    pub status: i32,
    /// `R_d`, the planned attitude, row-major.
    pub planned_attitude: [f32; 9],
    /// `theta*` (rad).
    pub theta: f32,
    /// One of `TVMD_PLANNER_*`.
    pub planner_status: u32,
    /// The planner's search steps.
    pub iterations: u32,
}

/// The law stage of a period: fills `out` with the body wrench to allocate (its `size` set by
/// the caller). With an offset-free action the next `tvmd_allocate` records the delivered
/// wrench for the observer (run the allocation after each law period). Errors: as
/// `tvmd_step`'s input checks; nothing is held (the law sends no commands).
///
/// # Safety
/// Each pointer is null or points to its struct; `handle` as for `tvmd_create`.
#[no_mangle]
pub unsafe extern "C" fn tvmd_law(
    handle: *mut crate::handle::TvmdController,
    state: *const TvmdState,
    reference: *const TvmdReference,
    out: *mut TvmdLawOutput,
) -> TvmdStatus {
    let Some(out) = out.as_mut() else {
        return TVMD_ERR_NULL_POINTER;
    };
    if let Err(status) = checked_size::<TvmdLawOutput>(out.size) {
        return status;
    }
    let status = law_into(handle, state, reference, out);
    if status != TVMD_OK {
        *out = TvmdLawOutput::failed(status);
    }
    status
}

unsafe fn law_into(
    handle: *mut crate::handle::TvmdController,
    state: *const TvmdState,
    reference: *const TvmdReference,
    out: &mut TvmdLawOutput,
) -> TvmdStatus {
    let inner = match inner_mut(handle) {
        Ok(inner) => inner,
        Err(status) => return status,
    };
    let (Some(state), Some(reference)) = (state.as_ref(), reference.as_ref()) else {
        return TVMD_ERR_NULL_POINTER;
    };
    if let Err(status) = checked_size::<TvmdState>(state.size)
        .and_then(|()| checked_size::<TvmdReference>(reference.size))
    {
        return status;
    }
    match inner.controller.law(&state.to_core(), &reference.to_core()) {
        Ok(stage) => {
            let u_d = &stage.law.u_d;
            *out = TvmdLawOutput {
                size: out.size,
                status: TVMD_OK,
                torque: [u_d[0], u_d[1], u_d[2]],
                force: [u_d[3], u_d[4], u_d[5]],
                planned_attitude: row_major(&stage.planner.r_d),
                planner_theta: stage.planner.theta,
                planner_status: planner_status_code(stage.planner.status),
                planner_iterations: stage.planner.iterations,
                position_error: stage.law.e_x.into(),
                attitude_error: stage.law.e_r.into(),
            };
            TVMD_OK
        }
        Err(e) => input_status(&e.error),
    }
}

impl TvmdLawOutput {
    fn failed(status: TvmdStatus) -> Self {
        Self {
            size: core::mem::size_of::<Self>() as u32,
            status,
            torque: [f32::NAN; 3],
            force: [f32::NAN; 3],
            planned_attitude: [f32::NAN; 9],
            planner_theta: f32::NAN,
            planner_status: 0,
            planner_iterations: 0,
            position_error: [f32::NAN; 3],
            attitude_error: [f32::NAN; 3],
        }
    }
}

/// The allocation stage: the body wrench `wrench` to per-agent commands inside `E_f`, which
/// become the held commands (the drop-in for a flight stack's control allocation, e.g. at the
/// rate loop's rate). Fills `out` (its `size` set by the caller). On an error after `out` was
/// found usable, `out.commands` are the held ones: a null or wrongly sized `wrench`, a
/// non-finite wrench (`TVMD_ERR_INPUT_NON_FINITE`), zero thrust on every agent for a non-zero force.
///
/// # Safety
/// Each pointer is null or points to its struct; `handle` as for `tvmd_create`.
#[no_mangle]
pub unsafe extern "C" fn tvmd_allocate(
    handle: *mut crate::handle::TvmdController,
    wrench: *const TvmdWrench,
    out: *mut TvmdAllocationOutput,
) -> TvmdStatus {
    let Some(out) = out.as_mut() else {
        return TVMD_ERR_NULL_POINTER;
    };
    if let Err(status) = checked_size::<TvmdAllocationOutput>(out.size) {
        return status;
    }
    let inner = match inner_mut(handle) {
        Ok(inner) => inner,
        Err(status) => {
            out.held(status, 0, &[]);
            return status;
        }
    };
    let controller = &mut inner.controller;
    let n = controller.team().len();
    let held = held_commands(controller);
    let Some(wrench) = wrench.as_ref() else {
        out.held(TVMD_ERR_NULL_POINTER, n, &held);
        return TVMD_ERR_NULL_POINTER;
    };
    if let Err(status) = checked_size::<TvmdWrench>(wrench.size) {
        out.held(status, n, &held);
        return status;
    }
    let [tx, ty, tz] = wrench.torque;
    let [fx, fy, fz] = wrench.force;
    match controller.allocate(&Vector6::new(tx, ty, tz, fx, fy, fz)) {
        Ok(stage) => {
            out.status = TVMD_OK;
            out.agent_count = u32::try_from(n).unwrap_or(0);
            for (slot, c) in out.commands.iter_mut().zip(&stage.commands) {
                *slot = c.into();
            }
            let u = &stage.allocation.wrench;
            out.allocated_torque = [u[0], u[1], u[2]];
            out.allocated_force = [u[3], u[4], u[5]];
            out.force_error = stage.allocation.e_f;
            out.torque_error = stage.torque_error;
            out.saturated = stage
                .allocation
                .saturated
                .iter()
                .take(n)
                .enumerate()
                .fold(0, |m, (i, s)| m | (u32::from(*s) << i));
            TVMD_OK
        }
        Err(e) => {
            let status = input_status(&e.error);
            out.held(status, n, &held);
            status
        }
    }
}

impl TvmdAllocationOutput {
    fn held(&mut self, status: TvmdStatus, agent_count: usize, commands: &[TvmdAgentCommand]) {
        self.status = status;
        self.agent_count = u32::try_from(agent_count).unwrap_or(0);
        self.commands = [TvmdAgentCommand::default(); TVMD_MAX_AGENTS];
        for (slot, c) in self.commands.iter_mut().zip(commands) {
            *slot = *c;
        }
        self.allocated_torque = [f32::NAN; 3];
        self.allocated_force = [f32::NAN; 3];
        self.force_error = f32::NAN;
        self.torque_error = f32::NAN;
        self.saturated = 0;
    }
}

/// The planner alone: the attitude `R_d` closest to `reference_attitude` (9 floats, row-major,
/// a rotation) whose attainable force space holds `force` (3 floats, N, inertial frame), at
/// the controller's relaxation and failure mask. Reads the controller, changes nothing.
///
/// # Safety
/// `reference_attitude` is null or points to 9 floats, `force` to 3; `handle` as for
/// `tvmd_create`; `out` is null or points to a `TvmdPlanOutput`.
#[no_mangle]
pub unsafe extern "C" fn tvmd_plan(
    handle: *const crate::handle::TvmdController,
    reference_attitude: *const f32,
    force: *const f32,
    out: *mut TvmdPlanOutput,
) -> TvmdStatus {
    let Some(out) = out.as_mut() else {
        return TVMD_ERR_NULL_POINTER;
    };
    if let Err(status) = checked_size::<TvmdPlanOutput>(out.size) {
        return status;
    }
    let status = plan_into(handle, reference_attitude, force, out);
    if status != TVMD_OK {
        *out = TvmdPlanOutput {
            size: out.size,
            status,
            planned_attitude: [f32::NAN; 9],
            theta: f32::NAN,
            planner_status: 0,
            iterations: 0,
        };
    }
    status
}

unsafe fn plan_into(
    handle: *const crate::handle::TvmdController,
    reference_attitude: *const f32,
    force: *const f32,
    out: &mut TvmdPlanOutput,
) -> TvmdStatus {
    let controller = match inner_ref(handle) {
        Ok(inner) => &inner.controller,
        Err(status) => return status,
    };
    let (Some(attitude), Some(force)) = (
        reference_attitude.cast::<[f32; 9]>().as_ref(),
        force.cast::<[f32; 3]>().as_ref(),
    ) else {
        return TVMD_ERR_NULL_POINTER;
    };
    match controller.plan(&matrix(attitude), &vector(force)) {
        Ok(p) => {
            out.status = TVMD_OK;
            out.planned_attitude = row_major(&p.r_d);
            out.theta = p.theta;
            out.planner_status = planner_status_code(p.status);
            out.iterations = p.iterations;
            TVMD_OK
        }
        Err(e) => input_status(&e),
    }
}
