//! The offset-free compensation read from the handle ([`tvmd_compensation`]): what
//! `tvmd_step` returns in `TvmdOutput.compensation_*`, for a caller that runs the stages
//! (`tvmd_law`, `tvmd_attitude`, `tvmd_allocate`) and so never receives a `TvmdOutput`.

use crate::handle::{checked_size, inner, TvmdController};
use crate::status::{TvmdStatus, TVMD_ERR_CORRUPTED, TVMD_ERR_NULL_POINTER, TVMD_OK};

/// The offset-free compensation as it stands: the wrench the offset-free state adds to the
/// next law period's request (the observer's estimate of the unmodelled wrench is its
/// negative). Zero without an offset-free action and while landed (`tvmd_set_landed`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TvmdCompensation {
    /// `sizeof(TvmdCompensation)`, set by the caller.
    pub size: u32,
    /// The offset-free force (N, inertial frame), as `TvmdOutput.compensation_force`.
    pub force: [f32; 3],
    /// The offset-free torque (N m, body frame), as `TvmdOutput.compensation_torque`.
    pub torque: [f32; 3],
}

/// Fills `out` (its `size` set by the caller) with the offset-free compensation as it stands.
/// Run by stages, it is updated by the `tvmd_allocate` that follows a `tvmd_law` (which
/// records the delivered wrench for the observer): read after that allocation, it is
/// `tvmd_step`'s `compensation_*` of the same period, bit for bit. Reads the controller,
/// changes nothing. On an error after `out` was found usable (a handle not created or
/// corrupted, `TVMD_ERR_CORRUPTED` also for a non-finite offset-free state, which only a stray
/// write leaves) the numbers are NaN.
///
/// # Safety
/// `handle` is null or points to a `TvmdController`; `out` is null or points to a
/// `TvmdCompensation`.
#[no_mangle]
pub unsafe extern "C" fn tvmd_compensation(
    handle: *const TvmdController,
    out: *mut TvmdCompensation,
) -> TvmdStatus {
    let Some(out) = out.as_mut() else {
        return TVMD_ERR_NULL_POINTER;
    };
    if let Err(status) = checked_size::<TvmdCompensation>(out.size) {
        return status;
    }
    let status = match inner(handle) {
        Ok(inner) => {
            let c = inner.controller.offset_free_compensation();
            // The offset-free state is bounded and finite by construction: anything else is a
            // stray write into the storage, refused rather than handed on.
            if c.force.iter().chain(c.torque.iter()).all(|v| v.is_finite()) {
                out.force = c.force.into();
                out.torque = c.torque.into();
                return TVMD_OK;
            }
            TVMD_ERR_CORRUPTED
        }
        Err(status) => status,
    };
    out.force = [f32::NAN; 3];
    out.torque = [f32::NAN; 3];
    status
}
