//! The C handle's per-call storage check (issue 57, item 7): `Controller::storage_intact`,
//! which every `tvmd-ffi` entry point runs on its handle before using it (the counts, flags and
//! enum tags the cycle reads, checked raw), at capacity `N`, counted as the cycle. On the
//! controller the cycle cases measure (the paper's allocator): a second controller type here
//! (the C handle's `AnyAllocator`) changes what LTO inlines into the measured cycles. The C
//! handle's check reads one more byte (the allocator's tag).

use core::hint::black_box;

use cortex_m_semihosting::hprintln;
use tvmd_core::{Controller, ControllerSettings, RedistributedPseudoInverse};

use crate::{clock, team, REPS};

type Handle<const N: usize> = Controller<f32, N, RedistributedPseudoInverse>;

#[inline(never)]
fn check<const N: usize>(c: *const Handle<N>) -> bool {
    // SAFETY: `c` points to a live controller.
    unsafe { Handle::<N>::storage_intact(c) }
}

/// The same call shape with no work: its cost is subtracted.
#[inline(never)]
fn empty<const N: usize>(c: *const Handle<N>) -> bool {
    !c.is_null()
}

/// Prints the check's instructions per call at capacity `N`; `false` when the controller was
/// refused or the check refuses an intact controller.
pub fn report<const N: usize>(per_tick: u32) -> bool {
    let Some(c) = team::<N>().and_then(|t| {
        Controller::new(
            t,
            ControllerSettings::offset_free_law(),
            RedistributedPseudoInverse,
        )
        .ok()
    }) else {
        hprintln!("cost: n = {} storage check: FAIL: controller refused", N);
        return false;
    };
    let at: *const Handle<N> = &c;
    let intact = check(at);
    let work = clock::ticks(REPS, &mut || {
        black_box(check(black_box(at)));
    });
    let overhead = clock::ticks(REPS, &mut || {
        black_box(empty(black_box(at)));
    });
    let instructions = clock::per_call(work, overhead, per_tick, REPS);
    hprintln!(
        "cost: n = {:2} storage check of a C handle (Controller::storage_intact, per entry point call): {} instructions{}",
        N,
        instructions,
        if intact { "" } else { "  FAIL: an intact controller refused" }
    );
    intact
}
