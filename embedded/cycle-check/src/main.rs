//! One control cycle of the paper's team in `f32` on a Cortex-M4F, linked with a panic handler
//! that calls an undefined symbol: if any panic path survives optimization, the link fails with
//! `undefined symbol: tvmd_core_cycle_can_panic`. The same binary gives the footprint
//! (`.text`, `.data`, `.bss`) and, through `-Z emit-stack-sizes`-free static analysis, nothing
//! else: it has no runtime, no allocator and no startup code beyond `_start`.
#![no_std]
#![no_main]

use core::panic::PanicInfo;
use core::ptr::{addr_of, addr_of_mut, read_volatile, write_volatile};

use tvmd_core::nalgebra::Vector3;
use tvmd_core::team::presets;
use tvmd_core::{AgentCommand, Controller, ControllerSettings, Reference, RigidState};

extern "Rust" {
    /// Deliberately never defined.
    fn tvmd_core_cycle_can_panic() -> !;
}

/// The allocator of the checked cycle: the paper's, or with `--features default-allocator`
/// the default one.
#[cfg(not(feature = "default-allocator"))]
fn allocator() -> tvmd_core::RedistributedPseudoInverse {
    tvmd_core::RedistributedPseudoInverse
}

/// The allocator of the checked cycle: the default one.
#[cfg(feature = "default-allocator")]
fn allocator() -> tvmd_core::ExactBoundaryRedistribution<f32, 4> {
    tvmd_core::ExactBoundaryRedistribution::new()
}

#[panic_handler]
fn panic(_: &PanicInfo<'_>) -> ! {
    // SAFETY: never defined, so any reachable call makes the link fail; it is never executed.
    unsafe { tvmd_core_cycle_can_panic() }
}

/// Inputs a flight stack would write (volatile so the cycle is not constant-folded).
static mut STATE: [f32; 18] = [0.0; 18];
/// Outputs a flight stack would read.
static mut COMMANDS: [[f32; 4]; 4] = [[0.0; 4]; 4];
static mut STATUS: u32 = 0;

fn read_inputs() -> (RigidState<f32>, Reference<f32>) {
    // SAFETY: single-threaded bare-metal program; volatile reads of a plain array.
    let s = unsafe { read_volatile(addr_of!(STATE)) };
    let v = |i: usize| Vector3::new(s[i], s[i + 1], s[i + 2]);
    let mut state = RigidState::at_rest(v(0));
    state.angular_velocity = v(3);
    state.velocity = v(6);
    state.attitude = tvmd_core::controller::roll(s[9]);
    let mut reference = Reference::hover(v(10));
    reference.acceleration = v(13);
    reference.attitude = tvmd_core::controller::roll(s[16]);
    (state, reference)
}

fn write_outputs(commands: &[AgentCommand<f32>; 4], status: u32) {
    let mut out = [[0.0f32; 4]; 4];
    for (o, c) in out.iter_mut().zip(commands) {
        *o = [c.eta_x, c.eta_y, c.thrust, c.omega];
    }
    // SAFETY: as in `read_inputs`.
    unsafe {
        write_volatile(addr_of_mut!(COMMANDS), out);
        write_volatile(addr_of_mut!(STATUS), status);
    }
}

/// Entry point: configure once, then run the cycle forever.
#[no_mangle]
pub extern "C" fn _start() -> ! {
    let controller = presets::a4_inc::<f32, 4>()
        .and_then(|team| Controller::new(team, ControllerSettings::paper(), allocator()));
    let Ok(mut controller) = controller else {
        write_outputs(&[AgentCommand::idle(); 4], 2);
        loop {}
    };
    loop {
        let (state, reference) = read_inputs();
        match controller.step(&state, &reference) {
            Ok(out) => write_outputs(&out.commands, out.allocation.rounds),
            Err(held) => write_outputs(&held.commands, 1),
        }
    }
}
