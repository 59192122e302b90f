//! The opaque controller handle in caller memory, and the entry points that use it.
//!
//! `TvmdController` is plain storage of `TVMD_CONTROLLER_SIZE` bytes, 8-byte aligned, that the
//! caller owns (a `static`, a member of a C++ class, a stack variable): the library never uses
//! the heap. `tvmd_create` writes a `tvmd_core::Controller` (f32, 16 agents, the allocator
//! chosen at run time) into it; nothing needs freeing. A handle is not thread-safe: call its
//! entry points from one task (the control loop), or serialize them.

use core::mem::{align_of, size_of, MaybeUninit};

use tvmd_core::{AnyAllocator, ConfigError, Controller, FailureMask};

use crate::blueprint::Blueprint;
use crate::status::*;
use crate::types::*;
use crate::TVMD_MAX_AGENTS;

/// The controller behind the handle.
pub(crate) type FfiController =
    Controller<f32, TVMD_MAX_AGENTS, AnyAllocator<f32, TVMD_MAX_AGENTS>>;

/// Bytes of a [`TvmdController`]: at least the controller's size on every supported target
/// (checked at compile time), with room for the core to grow within one ABI version. 9,216 at
/// the 16-agent capacity (the controller keeps its allocator's working set, so no entry point
/// holds it on the stack, and the agents' reports), 4,096 at the 4-agent one.
#[cfg(not(feature = "capacity-4"))]
pub const TVMD_CONTROLLER_SIZE: usize = 9216;

/// Bytes of a [`TvmdController`] at the 4-agent capacity (feature `capacity-4`).
#[cfg(feature = "capacity-4")]
pub const TVMD_CONTROLLER_SIZE: usize = 4096;

/// `TVMD_CONTROLLER_SIZE` in 8-byte words (the storage's element type gives the alignment in C
/// without compiler extensions).
pub const TVMD_CONTROLLER_WORDS: usize = TVMD_CONTROLLER_SIZE / 8;

/// Written by a successful `tvmd_create` at the start of the storage; anything else means
/// "not initialized".
const MAGIC: u64 = 0x7476_6d64_6666_6931;

/// Written by a successful `tvmd_create` in the storage's last 8 bytes: a write running over
/// the storage from the next buffer (or from the previous one into the start) changes one of
/// the two guards, and every entry point then refuses the handle (`TVMD_ERR_CORRUPTED`).
const TAIL: u64 = 0x6474_7664_6e65_6421;

/// The byte offset of the tail guard.
const TAIL_OFFSET: usize = TVMD_CONTROLLER_SIZE - 8;

/// What the storage holds, the magic first (declaration order is layout order).
#[repr(C)]
pub(crate) struct Inner {
    magic: u64,
    pub(crate) controller: FfiController,
}

// The header's size and alignment hold the real controller and the tail guard, on the target
// that compiles this.
const _: () = assert!(size_of::<Inner>() <= TAIL_OFFSET);
const _: () = assert!(align_of::<Inner>() <= align_of::<TvmdController>());
const _: () = assert!(TVMD_CONTROLLER_SIZE % 8 == 0);

/// Caller-owned storage of one controller. Zero-initialize it (or call `tvmd_create` first):
/// a handle that was never created is refused with `TVMD_ERR_NOT_INITIALIZED`.
#[repr(C)]
pub struct TvmdController {
    /// Opaque; only the library reads or writes it.
    pub opaque: [u64; TVMD_CONTROLLER_WORDS],
}

/// The bytes of caller memory a controller needs (`sizeof(TvmdController)`).
#[no_mangle]
pub extern "C" fn tvmd_controller_size() -> usize {
    size_of::<TvmdController>()
}

/// The alignment, in bytes, caller memory for a controller needs.
#[no_mangle]
pub extern "C" fn tvmd_controller_align() -> usize {
    align_of::<TvmdController>()
}

pub(crate) fn checked_size<T>(size: u32) -> Result<(), TvmdStatus> {
    if usize::try_from(size).ok() == Some(size_of::<T>()) {
        Ok(())
    } else {
        Err(TVMD_ERR_SIZE)
    }
}

/// The created controller behind `handle`, or the status that refuses it.
///
/// # Safety
/// `handle` is null or points to a `TvmdController` (possibly never created).
pub(crate) unsafe fn inner<'a>(handle: *const TvmdController) -> Result<&'a Inner, TvmdStatus> {
    if handle.is_null() {
        return Err(TVMD_ERR_NULL_POINTER);
    }
    if handle as usize % align_of::<Inner>() != 0 {
        return Err(TVMD_ERR_ALIGNMENT);
    }
    // Raw reads until the storage is known to hold valid counts and tags: a reference to a
    // controller with an invalid enum tag would already be undefined behaviour.
    let storage = handle.cast::<Inner>();
    if core::ptr::addr_of!((*storage).magic).read() != MAGIC {
        return Err(TVMD_ERR_NOT_INITIALIZED);
    }
    // In bounds: the storage is TVMD_CONTROLLER_SIZE bytes and 8-byte aligned.
    let tail = handle.cast::<u8>().add(TAIL_OFFSET).cast::<u64>().read();
    if tail != TAIL || !FfiController::storage_intact(core::ptr::addr_of!((*storage).controller)) {
        return Err(TVMD_ERR_CORRUPTED);
    }
    Ok(&*storage)
}

/// As [`inner`], mutable.
///
/// # Safety
/// As [`inner`], and no other reference to the handle is alive.
pub(crate) unsafe fn inner_mut<'a>(
    handle: *mut TvmdController,
) -> Result<&'a mut Inner, TvmdStatus> {
    inner(handle)?;
    Ok(&mut *handle.cast::<Inner>())
}

/// The created controller behind a handle (for the actuator mapping).
///
/// # Safety
/// As [`inner`].
pub(crate) unsafe fn controller<'a>(
    handle: *const TvmdController,
) -> Result<&'a FfiController, TvmdStatus> {
    inner(handle).map(|i| &i.controller)
}

/// The commands a refused period holds: the controller's previous ones.
pub(crate) fn held_commands(controller: &FfiController) -> [TvmdAgentCommand; TVMD_MAX_AGENTS] {
    let mut held = [TvmdAgentCommand::default(); TVMD_MAX_AGENTS];
    for (slot, c) in held.iter_mut().zip(controller.previous_commands()) {
        *slot = c.into();
    }
    held
}

/// Creates a controller from `config` in `storage` (`storage_size` = `sizeof(TvmdController)`).
/// On an error the storage is marked not initialized, and every other entry point refuses it.
/// Calling it again on a created handle replaces the controller.
///
/// # Safety
/// `storage` is null or points to writable memory of `storage_size` bytes not used otherwise;
/// `config` is null or points to a `TvmdConfig`.
#[no_mangle]
pub unsafe extern "C" fn tvmd_create(
    storage: *mut TvmdController,
    storage_size: usize,
    config: *const TvmdConfig,
) -> TvmdStatus {
    if storage.is_null() || config.is_null() {
        return TVMD_ERR_NULL_POINTER;
    }
    if storage_size != size_of::<TvmdController>() {
        return TVMD_ERR_SIZE;
    }
    if storage as usize % align_of::<TvmdController>() != 0 {
        return TVMD_ERR_ALIGNMENT;
    }
    let inner = storage.cast::<Inner>();
    // Not initialized until the controller is in place.
    core::ptr::addr_of_mut!((*inner).magic).write(0);
    let config = &*config;
    if let Err(status) = checked_size::<TvmdConfig>(config.size) {
        return status;
    }
    let mut blueprint = MaybeUninit::uninit();
    let blueprint = match Blueprint::write_in(&mut blueprint, config) {
        Ok(b) => b,
        Err(e) => return e.status(),
    };
    // Built in place: a controller on the stack would cost a small-stack caller its size again.
    let slot =
        &mut *core::ptr::addr_of_mut!((*inner).controller).cast::<MaybeUninit<FfiController>>();
    match Controller::init_in(slot, &blueprint.team, &blueprint.settings, || {
        AnyAllocator::from_choice(blueprint.allocator.clone())
    }) {
        Ok(_) => {
            core::ptr::addr_of_mut!((*inner).magic).write(MAGIC);
            storage
                .cast::<u8>()
                .add(TAIL_OFFSET)
                .cast::<u64>()
                .write(TAIL);
            TVMD_OK
        }
        Err(e) => config_status(&e),
    }
}

/// One control period. Fills `out` (whose `size` the caller sets) and returns its status.
///
/// On any error after `out` was found usable, `out` holds the previous good commands (see
/// [`TvmdOutput`]): null `state`/`reference`, a wrong `size`, a non-finite, non-rotation or
/// out-of-range input, an unattainable request. A null or wrongly sized `out` is not written.
///
/// # Safety
/// Each pointer is null or points to its struct; `handle` as for [`tvmd_create`].
#[no_mangle]
pub unsafe extern "C" fn tvmd_step(
    handle: *mut TvmdController,
    state: *const TvmdState,
    reference: *const TvmdReference,
    out: *mut TvmdOutput,
) -> TvmdStatus {
    let Some(out) = out.as_mut() else {
        return TVMD_ERR_NULL_POINTER;
    };
    if let Err(status) = checked_size::<TvmdOutput>(out.size) {
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
    let hold = |out: &mut TvmdOutput, status, controller: &FfiController| {
        out.held(status, n, &held_commands(controller));
        status
    };
    let (Some(state), Some(reference)) = (state.as_ref(), reference.as_ref()) else {
        return hold(out, TVMD_ERR_NULL_POINTER, controller);
    };
    if let Err(status) = checked_size::<TvmdState>(state.size)
        .and_then(|()| checked_size::<TvmdReference>(reference.size))
    {
        return hold(out, status, controller);
    }
    match controller.step(&state.to_core(), &reference.to_core()) {
        Ok(o) => {
            out.status = TVMD_OK;
            out.agent_count = u32::try_from(n).unwrap_or(0);
            for (slot, c) in out.commands.iter_mut().zip(&o.commands) {
                *slot = c.into();
            }
            out.e_f = o.allocation.e_f;
            out.planned_attitude = row_major(&o.planner.r_d);
            out.planner_theta = o.planner.theta;
            out.planner_status = planner_status_code(o.planner.status);
            out.planner_iterations = o.planner.iterations;
            let compensation = controller.offset_free_compensation();
            out.compensation_force = compensation.force.into();
            out.compensation_torque = compensation.torque.into();
            TVMD_OK
        }
        // The core's error carries the previous commands, the same as `previous_commands`.
        Err(e) => hold(out, input_status(&e.error), controller),
    }
}

/// Marks the agents whose bit is set in `failed_mask` (bit `i` = agent `i`) as failed and
/// classifies whether the working agents can hold hover; fills `hover` unless it is null.
/// On an error (a bit at or beyond the team's size, no working agent, a rank-deficient
/// remaining team) the previous mask stays in force.
///
/// # Safety
/// `handle` as for [`tvmd_step`]; `hover` is null or points to a `TvmdHover`.
#[no_mangle]
pub unsafe extern "C" fn tvmd_set_failures(
    handle: *mut TvmdController,
    failed_mask: u32,
    hover: *mut TvmdHover,
) -> TvmdStatus {
    let hover = hover.as_mut();
    if let Some(h) = &hover {
        if let Err(status) = checked_size::<TvmdHover>(h.size) {
            return status;
        }
    }
    let inner = match inner_mut(handle) {
        Ok(inner) => inner,
        Err(status) => return status,
    };
    let mut mask = FailureMask::none();
    for bit in 0..u32::BITS {
        if failed_mask & (1 << bit) != 0 {
            if let Err(e) = usize::try_from(bit)
                .map_err(|_| ConfigError::FailureIndex { agent: usize::MAX })
                .and_then(|agent| mask.set(agent, true))
            {
                return config_status(&e);
            }
        }
    }
    match inner.controller.set_failures(mask) {
        Ok(capability) => {
            if let Some(h) = hover {
                h.fill(&capability);
            }
            TVMD_OK
        }
        Err(e) => config_status(&e),
    }
}

/// The hover classification of the mask in force (the full team's after `tvmd_create`).
///
/// # Safety
/// `handle` as for [`tvmd_step`]; `hover` is null or points to a `TvmdHover`.
#[no_mangle]
pub unsafe extern "C" fn tvmd_hover_capability(
    handle: *const TvmdController,
    hover: *mut TvmdHover,
) -> TvmdStatus {
    let Some(hover) = hover.as_mut() else {
        return TVMD_ERR_NULL_POINTER;
    };
    if let Err(status) = checked_size::<TvmdHover>(hover.size) {
        return status;
    }
    match inner(handle) {
        Ok(inner) => {
            hover.fill(&inner.controller.hover_capability());
            TVMD_OK
        }
        Err(status) => status,
    }
}

/// Forgets the previous command: the next held command is idle, and rate limits restart from
/// a centred gimbal; the offset-free state restarts from zero and the planned-rate filter at
/// rest. Configuration, failure mask and the landed flag (`tvmd_set_landed`) are kept.
///
/// # Safety
/// `handle` as for [`tvmd_step`].
#[no_mangle]
pub unsafe extern "C" fn tvmd_reset(handle: *mut TvmdController) -> TvmdStatus {
    match inner_mut(handle) {
        Ok(inner) => {
            inner.controller.reset();
            TVMD_OK
        }
        Err(status) => status,
    }
}

/// The preflight integrity check: `TVMD_OK` when the handle was created, both guards around
/// the storage are intact and the controller's counts and enum tags hold valid values (the
/// agent count against the working count and the effectiveness's count of blocks, the
/// failure mask, the hover classification, the allocator's variant, the admissible set
/// against the team's limits), `TVMD_ERR_NOT_INITIALIZED` or
/// `TVMD_ERR_CORRUPTED` otherwise. Every other entry point makes the same check first;
/// whatever else a stray write leaves in the storage, every loop stays bounded by the
/// capacity and constant caps, and no entry point hangs or crashes.
///
/// # Safety
/// `handle` as for [`tvmd_step`].
#[no_mangle]
pub unsafe extern "C" fn tvmd_check(handle: *const TvmdController) -> TvmdStatus {
    match inner(handle) {
        Ok(_) => TVMD_OK,
        Err(status) => status,
    }
}

/// Tells the controller whether the team stands on the ground (`landed` non-zero) or flies
/// (zero), from the caller's contact or landing detector. While landed the offset-free state
/// is cleared and held at zero (`TvmdOutput.compensation_*` are zero): the ground's reaction is
/// not a disturbance to compensate, and nothing winds up against it. Call it with 1 on the
/// ground before take-off and again after touch-down, and with 0 at take-off, from which the
/// offset-free state starts again from zero. Nothing else changes, and it has no effect
/// without an offset-free action (`law.offset_free`). A created handle starts not landed.
///
/// # Safety
/// `handle` as for [`tvmd_step`].
#[no_mangle]
pub unsafe extern "C" fn tvmd_set_landed(handle: *mut TvmdController, landed: u32) -> TvmdStatus {
    match inner_mut(handle) {
        Ok(inner) => {
            inner.controller.set_landed(landed != 0);
            TVMD_OK
        }
        Err(status) => status,
    }
}
