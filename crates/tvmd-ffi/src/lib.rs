//! C ABI over the f32 tvmd controller (issue 15; work in progress).
//!
//! This first step exposes the version queries and the size and alignment of the
//! controller the handle will hold (16 agents, f32, redistributed pseudo-inverse), so the
//! caller-provided storage of the next step can be checked against them. No heap is used.
#![no_std]
#![deny(missing_docs)]

#[cfg(feature = "std")]
extern crate std;

use tvmd_core::{Controller, RedistributedPseudoInverse};

/// The capacity of the handle: the largest team it controls.
pub const TVMD_MAX_AGENTS: usize = 16;

/// The ABI version; raised on every incompatible change of a struct or function.
pub const TVMD_ABI_VERSION: u32 = 1;

/// The controller behind the opaque handle.
type FfiController = Controller<f32, TVMD_MAX_AGENTS, RedistributedPseudoInverse>;

/// The ABI version of the library (compare with the header's `TVMD_ABI_VERSION`).
#[no_mangle]
pub extern "C" fn tvmd_abi_version() -> u32 {
    TVMD_ABI_VERSION
}

/// The crate version as a NUL-terminated static string (never null, never freed).
#[no_mangle]
pub extern "C" fn tvmd_version() -> *const core::ffi::c_char {
    concat!(env!("CARGO_PKG_VERSION"), "\0").as_ptr().cast()
}

/// The bytes of caller memory a controller needs.
#[no_mangle]
pub extern "C" fn tvmd_controller_size() -> usize {
    core::mem::size_of::<FfiController>()
}

/// The alignment, in bytes, that caller memory for a controller needs.
#[no_mangle]
pub extern "C" fn tvmd_controller_align() -> usize {
    core::mem::align_of::<FfiController>()
}

/// Bare-metal builds need a handler; none of this crate's entry points can panic yet (the
/// f32 cycle itself is proven panic-free by `embedded/cycle-check`; a link check of this
/// crate comes with its controller entry points).
#[cfg(target_os = "none")]
#[panic_handler]
fn panic(_info: &core::panic::PanicInfo) -> ! {
    loop {}
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn version_is_the_crate_version_nul_terminated() {
        // SAFETY: tvmd_version returns a static NUL-terminated string.
        let version = unsafe { core::ffi::CStr::from_ptr(tvmd_version()) };
        assert_eq!(version.to_str(), Ok(env!("CARGO_PKG_VERSION")));
        assert_eq!(tvmd_abi_version(), TVMD_ABI_VERSION);
    }

    #[test]
    fn controller_storage_is_nonzero_and_aligned() {
        assert!(tvmd_controller_size() > 0);
        assert!(tvmd_controller_align().is_power_of_two());
        assert_eq!(tvmd_controller_size() % tvmd_controller_align(), 0);
    }
}
