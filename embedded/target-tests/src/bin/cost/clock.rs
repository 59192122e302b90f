//! Instruction counting on QEMU with `-icount shift=0`: every executed instruction advances
//! QEMU's virtual clock by exactly 1 ns, and the SysTick counts that clock (QEMU 7.2 feeds its
//! processor-clock source from the board's 25 MHz `sysclk`, i.e. one tick per 40 instructions;
//! [`calibrate`] measures the ratio instead of assuming it). DWT `CYCCNT` is not used: QEMU 7.2
//! does not model the DWT (see `dwt_cyccnt_runs`).

use core::arch::asm;
use core::hint::black_box;

use cortex_m::peripheral::syst::SystClkSource;
use cortex_m::peripheral::{DWT, SYST};

/// SysTick's 24-bit reload value: the counter wraps every 2^24 ticks (0.67 s of virtual time,
/// 671 M instructions), far more than any measurement below.
const RELOAD: u32 = 0x00ff_ffff;

/// Starts the SysTick as a free-running down-counter on the processor clock.
pub fn start(syst: &mut SYST) {
    syst.disable_interrupt();
    syst.set_clock_source(SystClkSource::Core);
    syst.set_reload(RELOAD);
    syst.clear_current();
    syst.enable_counter();
}

/// The SysTick's current value (counts down).
#[inline(always)]
fn now() -> u32 {
    SYST::get_current()
}

/// SysTick ticks elapsed from `from` to `to` (down-counter, modulo 2^24).
#[inline(always)]
fn elapsed(from: u32, to: u32) -> u32 {
    from.wrapping_sub(to) & RELOAD
}

/// Ticks taken by `reps` calls of `f`.
#[inline(never)]
pub fn ticks(reps: u32, f: &mut dyn FnMut()) -> u32 {
    let t0 = now();
    for _ in 0..reps {
        f();
    }
    elapsed(t0, now())
}

/// Instructions of one call from the ticks of `reps` calls (`work`) and of as many calls of
/// the same shape with no work (`overhead`), rounded to the nearest.
pub fn per_call(work: u32, overhead: u32, per_tick: u32, reps: u32) -> u32 {
    let total = u64::from(work.saturating_sub(overhead)) * u64::from(per_tick);
    let reps = u64::from(reps.max(1));
    ((total + reps / 2) / reps) as u32
}

/// `iterations` (>= 1) passes of a loop whose body is 1,000 `nop`s plus `subs` and `bne`:
/// exactly `1,002 * iterations` instructions besides the call's own few, which cancel in
/// [`calibrate`]'s difference of two loops.
#[inline(never)]
fn nop_loop(iterations: u32) {
    // SAFETY: only nops and a register countdown; no memory, no stack.
    unsafe {
        asm!(
            "2:",
            ".rept 1000",
            "nop",
            ".endr",
            "subs {n}, {n}, #1",
            "bne 2b",
            n = inout(reg) iterations => _,
            options(nomem, nostack),
        );
    }
}

/// Instructions per SysTick tick, measured as the slope between two nop loops of known
/// length, so that the call and timer-read overheads cancel.
pub fn calibrate() -> Calibration {
    const SHORT: u32 = 1_000;
    const LONG: u32 = 11_000;
    let t0 = now();
    nop_loop(black_box(SHORT));
    let short = elapsed(t0, now());
    let t1 = now();
    nop_loop(black_box(LONG));
    let long = elapsed(t1, now());
    let extra_instructions = u64::from(LONG - SHORT) * 1_002;
    Calibration {
        short,
        long,
        extra_instructions,
    }
}

/// The outcome of [`calibrate`].
pub struct Calibration {
    /// Ticks of the 1,000-pass loop (1,002,000 instructions in the loop).
    pub short: u32,
    /// Ticks of the 11,000-pass loop.
    pub long: u32,
    /// Instructions the long loop executes beyond the short one.
    pub extra_instructions: u64,
}

impl Calibration {
    /// Instructions per tick (`extra_instructions / (long - short)`), rounded; 0 if the timer
    /// did not move.
    pub fn instructions_per_tick(&self) -> u32 {
        let dt = u64::from(self.long.saturating_sub(self.short));
        if dt == 0 {
            return 0;
        }
        ((self.extra_instructions + dt / 2) / dt) as u32
    }

    /// Whether the slope is an exact integer (the loop's instruction count divides evenly).
    pub fn is_exact(&self) -> bool {
        let dt = u64::from(self.long.saturating_sub(self.short));
        dt != 0 && self.extra_instructions.is_multiple_of(dt)
    }
}

/// Whether the DWT cycle counter advances once enabled (it does not on QEMU 7.2, whose DWT
/// registers read as zero).
pub fn dwt_cyccnt_runs(dcb: &mut cortex_m::peripheral::DCB, dwt: &mut DWT) -> bool {
    dcb.enable_trace();
    dwt.enable_cycle_counter();
    let a = DWT::cycle_count();
    nop_loop(black_box(10));
    let b = DWT::cycle_count();
    a != b
}
