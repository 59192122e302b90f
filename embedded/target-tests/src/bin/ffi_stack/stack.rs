//! Measured peak stack: paint the free stack below the caller with a pattern, run the code,
//! and find the lowest word that no longer holds the pattern (the high-water mark).

use core::arch::asm;
use core::ptr;

/// The paint. A word of the cycle's stack that happens to equal it would hide at most the
/// words below it that were also left untouched, i.e. the estimate could only be low by the
/// depth of such a coincidence; with a pattern that is neither a small integer, a pointer into
/// RAM nor a usual float, none is expected.
const PAINT: u32 = 0xA5C3_5A3C;

/// Room left unpainted just below the painter's own stack pointer (its own frame and the
/// return into the caller).
const MARGIN: usize = 64;

extern "C" {
    /// cortex-m-rt: the lowest address the stack may grow to (end of `.bss`/`.uninit`).
    static _stack_end: u32;
}

/// The current stack pointer.
#[inline(always)]
pub fn sp() -> usize {
    let sp: usize;
    // SAFETY: reads a register.
    unsafe { asm!("mov {}, sp", out(reg) sp, options(nomem, nostack, preserves_flags)) };
    sp
}

fn bottom() -> usize {
    // Only the symbol's address is taken (safe since Rust 2024's addr_of of an extern static).
    ptr::addr_of!(_stack_end) as usize
}

/// Paints every word from the bottom of the stack up to just below this function's frame.
#[inline(never)]
fn paint() {
    let top = (sp() - MARGIN) & !3;
    let mut at = (bottom() + 3) & !3;
    while at < top {
        // SAFETY: `[_stack_end, sp - MARGIN)` is free stack: nothing live is below sp.
        unsafe { ptr::write_volatile(at as *mut u32, PAINT) };
        at += 4;
    }
}

/// The lowest address whose word no longer holds the paint (the deepest write since
/// [`paint`]).
#[inline(never)]
fn high_water() -> usize {
    let mut at = (bottom() + 3) & !3;
    let top = sp();
    while at < top {
        // SAFETY: reading free stack below our own frame.
        if unsafe { ptr::read_volatile(at as *const u32) } != PAINT {
            return at;
        }
        at += 4;
    }
    top
}

/// Bytes of stack that `f` used below the caller's stack pointer (its frames and those of
/// everything it called), by painting.
#[inline(never)]
pub fn peak(f: &mut dyn FnMut()) -> usize {
    let base = sp();
    paint();
    f();
    base.saturating_sub(high_water())
}
