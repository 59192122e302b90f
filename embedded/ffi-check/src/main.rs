//! Every entry point of the C interface, called from a Cortex-M4F program the way a flight
//! stack would (inputs read volatile, so nothing is constant-folded), linked with tvmd-ffi's
//! `link-check` panic handler, which calls an undefined symbol: if any panic path survives
//! optimization, the link fails with `undefined symbol: tvmd_ffi_can_panic`.
#![no_std]
#![no_main]

use core::ptr::{addr_of, addr_of_mut, read_volatile, write_volatile};

use tvmd_ffi::actuator::*;
use tvmd_ffi::compensation::*;
use tvmd_ffi::config::*;
use tvmd_ffi::fault_report::*;
use tvmd_ffi::handle::*;
use tvmd_ffi::reconfigure::*;
use tvmd_ffi::stages::*;
use tvmd_ffi::types::*;

static mut CONTROLLER: TvmdController = TvmdController {
    opaque: [0; TVMD_CONTROLLER_WORDS],
};
/// Inputs a flight stack would write.
static mut STATE: [f32; 18] = [0.0; 18];
static mut REFERENCE: [f32; 24] = [0.0; 24];
static mut MASK: u32 = 0;
/// Which configuration to create (0: the default, offset-free law; else the paper's) and the
/// landing detector's flag.
static mut PAPER: u32 = 0;
static mut LANDED: u32 = 0;
/// The fault detection mode (`TVMD_FAULT_*`), so the detector is linked and checked too.
static mut FAULT_MODE: u32 = 0;
static mut MAP_SHIFT: u32 = 0;
/// Outputs a flight stack would read.
static mut MOTORS: [f32; 16] = [0.0; 16];
static mut SERVOS: [f32; 16] = [0.0; 16];
static mut STATUS: [i32; 8] = [0; 8];
static mut COMPENSATION: [f32; 6] = [0.0; 6];
static mut NAME: usize = 0;
static mut FAULT_AGENT: i32 = 0;

fn copy(dst: &mut [f32], src: &[f32]) {
    for (d, s) in dst.iter_mut().zip(src) {
        *d = *s;
    }
}

/// Entry point: configure once, then run the cycle and the actuator mapping forever.
#[no_mangle]
pub extern "C" fn _start() -> ! {
    // SAFETY: single-threaded bare-metal program; every pointer is to a live local or static.
    unsafe {
        let handle = addr_of_mut!(CONTROLLER);
        let mut config: TvmdConfig = core::mem::zeroed();
        config.size = core::mem::size_of::<TvmdConfig>() as u32;
        let mut status = [0i32; 8];
        status[0] = if read_volatile(addr_of!(PAPER)) != 0 {
            tvmd_config_paper(&mut config)
        } else {
            tvmd_config_default(&mut config)
        };
        config.fault.mode = read_volatile(addr_of!(FAULT_MODE));
        status[1] = tvmd_create(handle, core::mem::size_of::<TvmdController>(), &config);
        let mut map: TvmdActuatorMap = core::mem::zeroed();
        map.size = core::mem::size_of::<TvmdActuatorMap>() as u32;
        status[2] = tvmd_actuator_map_default(handle, &mut map);
        let mut hover: TvmdHover = core::mem::zeroed();
        hover.size = core::mem::size_of::<TvmdHover>() as u32;
        status[3] = tvmd_hover_capability(handle, &mut hover);
        status[3] += tvmd_validate_config(&config) + tvmd_check(handle);
        let mut compensation: TvmdCompensation = core::mem::zeroed();
        compensation.size = core::mem::size_of::<TvmdCompensation>() as u32;
        status[3] += tvmd_compensation(handle, &mut compensation);
        write_volatile(
            addr_of_mut!(NAME),
            tvmd_ffi::status::tvmd_status_name(status[1]) as usize
                + tvmd_ffi::tvmd_version() as usize
                + tvmd_ffi::tvmd_abi_version() as usize
                + tvmd_controller_size()
                + tvmd_controller_align(),
        );
        loop {
            let s = read_volatile(addr_of!(STATE));
            let r = read_volatile(addr_of!(REFERENCE));
            let mut state: TvmdState = core::mem::zeroed();
            state.size = core::mem::size_of::<TvmdState>() as u32;
            copy(&mut state.position, &s[0..3]);
            copy(&mut state.attitude, &s[3..12]);
            copy(&mut state.angular_velocity, &s[12..15]);
            copy(&mut state.velocity, &s[15..18]);
            let mut reference: TvmdReference = core::mem::zeroed();
            reference.size = core::mem::size_of::<TvmdReference>() as u32;
            copy(&mut reference.position, &r[0..3]);
            copy(&mut reference.velocity, &r[3..6]);
            copy(&mut reference.acceleration, &r[6..9]);
            copy(&mut reference.attitude, &r[9..18]);
            copy(&mut reference.angular_velocity, &r[18..21]);
            copy(&mut reference.angular_acceleration, &r[21..24]);
            let mut out: TvmdOutput = core::mem::zeroed();
            out.size = core::mem::size_of::<TvmdOutput>() as u32;
            status[4] = tvmd_set_landed(handle, read_volatile(addr_of!(LANDED)));
            status[4] += tvmd_step(handle, &state, &reference, &mut out);
            // The stages, as a flight stack's loops would call them.
            let mut law: TvmdLawOutput = core::mem::zeroed();
            law.size = core::mem::size_of::<TvmdLawOutput>() as u32;
            status[4] += tvmd_law(handle, &state, &reference, &mut law);
            let wrench = TvmdWrench {
                size: core::mem::size_of::<TvmdWrench>() as u32,
                torque: law.torque,
                force: law.force,
            };
            let mut alloc: TvmdAllocationOutput = core::mem::zeroed();
            alloc.size = core::mem::size_of::<TvmdAllocationOutput>() as u32;
            status[4] += tvmd_allocate(handle, &wrench, &mut alloc);
            let mut att: TvmdAttitudeOutput = core::mem::zeroed();
            att.size = core::mem::size_of::<TvmdAttitudeOutput>() as u32;
            status[4] += tvmd_attitude(
                handle,
                &state,
                law.planned_attitude.as_ptr(),
                &reference,
                &mut att,
            );
            let mut plan: TvmdPlanOutput = core::mem::zeroed();
            plan.size = core::mem::size_of::<TvmdPlanOutput>() as u32;
            status[4] += tvmd_plan(
                handle,
                reference.attitude.as_ptr(),
                law.force.as_ptr(),
                &mut plan,
            );
            let mut fault: TvmdFaultReport = core::mem::zeroed();
            fault.size = core::mem::size_of::<TvmdFaultReport>() as u32;
            status[4] += tvmd_fault_report(handle, &mut fault);
            write_volatile(addr_of_mut!(FAULT_AGENT), fault.agent + fault.masked_agent);
            let [f0, f1, f2] = out.compensation_force;
            let [t0, t1, t2] = out.compensation_torque;
            write_volatile(addr_of_mut!(COMPENSATION), [f0, f1, f2, t0, t1, t2]);
            let mask = read_volatile(addr_of!(MASK));
            if mask != 0 {
                status[5] = tvmd_set_failures(handle, mask, &mut hover);
                status[5] += tvmd_reset(handle);
                status[5] += tvmd_reconfigure(handle, &config);
                status[5] += tvmd_set_relaxation(handle, reference.position[0]);
                status[5] += tvmd_set_rate_limits(handle, mask & 1, reference.velocity.as_ptr());
                status[5] += tvmd_set_gains(handle, &config.gains);
                status[5] += tvmd_seed_commands(handle, out.commands.as_ptr(), out.agent_count);
            }
            map.agents[0].motor[1] = read_volatile(addr_of!(MAP_SHIFT));
            status[6] = tvmd_actuator_map_validate(handle, &map);
            let mut act: TvmdActuatorOutputs = core::mem::zeroed();
            act.size = core::mem::size_of::<TvmdActuatorOutputs>() as u32;
            status[7] = tvmd_actuator_outputs(handle, &map, out.commands.as_ptr(), 16, &mut act);
            let mut back = [TvmdAgentCommand::default(); 16];
            status[7] += tvmd_actuator_commands(handle, &map, &act, back.as_mut_ptr(), 16);
            act.motors[15] = back[0].thrust;
            write_volatile(addr_of_mut!(MOTORS), act.motors);
            write_volatile(addr_of_mut!(SERVOS), act.servos);
            write_volatile(addr_of_mut!(STATUS), status);
        }
    }
}
