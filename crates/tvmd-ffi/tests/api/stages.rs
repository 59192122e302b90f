//! `tvmd_law`, `tvmd_allocate` and `tvmd_plan` on one handle against `tvmd_step` on another:
//! the law then the allocation is the step bit for bit; the planner alone plans what the step
//! planned; bad inputs give clean statuses with the held commands.

use std::mem::size_of;

use tvmd_ffi::compensation::*;
use tvmd_ffi::handle::*;
use tvmd_ffi::stages::*;
use tvmd_ffi::status::*;
use tvmd_ffi::types::*;

use super::{created_with, identity};

fn inputs(x: f32, roll: f32) -> (TvmdState, TvmdReference) {
    let state = TvmdState {
        size: size_of::<TvmdState>() as u32,
        position: [x, 0.0, 1.5],
        attitude: identity(),
        ..TvmdState::default()
    };
    let (s, c) = roll.sin_cos();
    let reference = TvmdReference {
        size: size_of::<TvmdReference>() as u32,
        position: [0.0, 0.0, 1.5],
        attitude: [1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c],
        ..TvmdReference::default()
    };
    (state, reference)
}

fn law_output() -> TvmdLawOutput {
    let mut out: TvmdLawOutput = unsafe { std::mem::zeroed() };
    out.size = size_of::<TvmdLawOutput>() as u32;
    out
}

fn allocation_output() -> TvmdAllocationOutput {
    let mut out: TvmdAllocationOutput = unsafe { std::mem::zeroed() };
    out.size = size_of::<TvmdAllocationOutput>() as u32;
    out
}

fn wrench_of(law: &TvmdLawOutput) -> TvmdWrench {
    TvmdWrench {
        size: size_of::<TvmdWrench>() as u32,
        torque: law.torque,
        force: law.force,
    }
}

/// One period on two handles: `tvmd_step` on `whole`, `tvmd_law` then `tvmd_allocate` on
/// `staged`; each must succeed.
fn step_and_stages(
    whole: &mut TvmdController,
    staged: &mut TvmdController,
    state: &TvmdState,
    reference: &TvmdReference,
) -> (TvmdOutput, TvmdLawOutput, TvmdAllocationOutput) {
    let mut out: TvmdOutput = unsafe { std::mem::zeroed() };
    out.size = size_of::<TvmdOutput>() as u32;
    let mut law = law_output();
    let mut alloc = allocation_output();
    // SAFETY: valid pointers to live values.
    unsafe {
        assert_eq!(tvmd_step(whole, state, reference, &mut out), TVMD_OK);
        assert_eq!(tvmd_law(staged, state, reference, &mut law), TVMD_OK);
        assert_eq!(tvmd_allocate(staged, &wrench_of(&law), &mut alloc), TVMD_OK);
    }
    (out, law, alloc)
}

#[test]
fn law_then_allocate_is_the_step_and_plan_is_its_planner() {
    for allocator in [
        TVMD_ALLOCATOR_EXACT_BOUNDARY_REDISTRIBUTION,
        TVMD_ALLOCATOR_REDISTRIBUTED_PSEUDO_INVERSE,
    ] {
        let mut whole = created_with(allocator);
        let mut staged = created_with(allocator);
        for k in 0..40 {
            let (state, reference) = inputs(0.2 - 0.005 * k as f32, 0.03 * k as f32);
            let (out, law, alloc) = step_and_stages(&mut whole, &mut staged, &state, &reference);
            assert_eq!(alloc.commands, out.commands, "period {k}");
            assert_eq!(alloc.force_error, out.e_f);
            assert_eq!(law.planned_attitude, out.planned_attitude);
            assert_eq!(law.planner_status, out.planner_status);
            assert!(alloc.torque_error >= 0.0 && alloc.torque_error < 1e-3);
            let mut plan: TvmdPlanOutput = unsafe { std::mem::zeroed() };
            plan.size = size_of::<TvmdPlanOutput>() as u32;
            // The step's f_r is the inertial force R u_fd / t_Tf's direction: with R = I and
            // no trimming, the law's force.
            // SAFETY: valid pointers to live values.
            let status = unsafe {
                tvmd_plan(
                    &*staged,
                    reference.attitude.as_ptr(),
                    law.force.as_ptr(),
                    &mut plan,
                )
            };
            assert_eq!(status, TVMD_OK);
            if out.planner_status == TVMD_PLANNER_ALREADY_FEASIBLE {
                assert_eq!(plan.planned_attitude, reference.attitude);
            }
        }
    }
}

#[test]
fn stages_refuse_bad_inputs_cleanly() {
    let mut handle = created_with(TVMD_ALLOCATOR_EXACT_BOUNDARY_REDISTRIBUTION);
    let (state, reference) = inputs(0.1, 0.0);
    let mut law = law_output();
    let mut alloc = allocation_output();
    // SAFETY: valid pointers to live values, or null where the test says so.
    unsafe {
        assert_eq!(
            tvmd_law(&mut *handle, &state, &reference, &mut law),
            TVMD_OK
        );
        assert_eq!(
            tvmd_allocate(&mut *handle, &wrench_of(&law), &mut alloc),
            TVMD_OK
        );
        let good = alloc.commands;
        assert!(alloc.commands.iter().take(4).all(|c| c.thrust > 0.0));
        let mut bad = wrench_of(&law);
        bad.force[1] = f32::NAN;
        assert_eq!(
            tvmd_allocate(&mut *handle, &bad, &mut alloc),
            TVMD_ERR_INPUT_NON_FINITE
        );
        assert_eq!(alloc.commands, good, "held");
        assert!(alloc.force_error.is_nan() && alloc.saturated == 0);
        bad.size = 3;
        assert_eq!(tvmd_allocate(&mut *handle, &bad, &mut alloc), TVMD_ERR_SIZE);
        assert_eq!(alloc.commands, good);
        assert_eq!(
            tvmd_allocate(&mut *handle, std::ptr::null(), &mut alloc),
            TVMD_ERR_NULL_POINTER
        );
        assert_eq!(
            tvmd_allocate(&mut *handle, &wrench_of(&law), std::ptr::null_mut()),
            TVMD_ERR_NULL_POINTER
        );
        let mut bad_state = state;
        bad_state.position[0] = f32::INFINITY;
        assert_eq!(
            tvmd_law(&mut *handle, &bad_state, &reference, &mut law),
            TVMD_ERR_INPUT_NON_FINITE
        );
        assert!(law.torque[0].is_nan() && law.planner_status == 0);
        assert_eq!(
            tvmd_law(&mut *handle, std::ptr::null(), &reference, &mut law),
            TVMD_ERR_NULL_POINTER
        );
        let mut plan: TvmdPlanOutput = std::mem::zeroed();
        plan.size = size_of::<TvmdPlanOutput>() as u32;
        let scaled = [2.0f32, 0.0, 0.0, 0.0, 2.0, 0.0, 0.0, 0.0, 2.0];
        let force = [0.0f32, 0.0, 27.0];
        assert_eq!(
            tvmd_plan(&*handle, scaled.as_ptr(), force.as_ptr(), &mut plan),
            TVMD_ERR_INPUT_NOT_ROTATION
        );
        assert!(plan.theta.is_nan());
        assert_eq!(
            tvmd_plan(&*handle, std::ptr::null(), force.as_ptr(), &mut plan),
            TVMD_ERR_NULL_POINTER
        );
        let mut never: TvmdController = std::mem::zeroed();
        assert_eq!(
            tvmd_plan(&never, identity().as_ptr(), force.as_ptr(), &mut plan),
            TVMD_ERR_NOT_INITIALIZED
        );
        assert_eq!(
            tvmd_allocate(&mut never, &wrench_of(&law), &mut alloc),
            TVMD_ERR_NOT_INITIALIZED
        );
    }
}

fn compensation_of(handle: &TvmdController) -> (TvmdStatus, TvmdCompensation) {
    let mut c = TvmdCompensation {
        size: size_of::<TvmdCompensation>() as u32,
        ..TvmdCompensation::default()
    };
    // SAFETY: valid pointers to live values.
    let status = unsafe { tvmd_compensation(handle, &mut c) };
    (status, c)
}

/// A caller running the stages reads the offset-free compensation from the handle: after each
/// period's allocation it is `tvmd_step`'s `compensation_*` of the same period, bit for bit.
#[test]
fn the_compensation_read_between_stages_is_the_steps() {
    let config = super::config_from(tvmd_ffi::config::tvmd_config_default);
    let ((s1, mut whole), (s2, mut staged)) = (super::create(&config), super::create(&config));
    assert_eq!((s1, s2), (TVMD_OK, TVMD_OK));
    let mut moved = 0;
    for k in 0..60 {
        // A state that does not follow the law's request: the observer sees a disturbance.
        let (state, reference) = inputs(0.2 - 0.002 * k as f32, 0.0);
        let (out, _, _) = step_and_stages(&mut whole, &mut staged, &state, &reference);
        let (status, c) = compensation_of(&staged);
        assert_eq!(status, TVMD_OK);
        assert_eq!(c.force, out.compensation_force, "period {k}");
        assert_eq!(c.torque, out.compensation_torque, "period {k}");
        moved += usize::from(c.force != [0.0; 3]);
    }
    assert!(moved > 50, "the observer's force moved in {moved} periods");
    // Landed: zero at once.
    // SAFETY: a created handle.
    assert_eq!(unsafe { tvmd_set_landed(&mut *staged, 1) }, TVMD_OK);
    assert_eq!(compensation_of(&staged).1.force, [0.0; 3]);
}

#[test]
fn the_compensation_getter_refuses_bad_arguments() {
    let handle = created_with(TVMD_ALLOCATOR_EXACT_BOUNDARY_REDISTRIBUTION);
    // The paper's law has no offset-free action: zero.
    let (status, c) = compensation_of(&handle);
    assert_eq!(status, TVMD_OK);
    assert_eq!((c.force, c.torque), ([0.0; 3], [0.0; 3]));
    let never: TvmdController = unsafe { std::mem::zeroed() };
    let (status, c) = compensation_of(&never);
    assert_eq!(status, TVMD_ERR_NOT_INITIALIZED);
    assert!(c.force.iter().chain(&c.torque).all(|v| v.is_nan()));
    let mut c = TvmdCompensation {
        size: 3,
        ..TvmdCompensation::default()
    };
    // SAFETY: valid pointers to live values, or null where the test says so.
    unsafe {
        assert_eq!(tvmd_compensation(&*handle, &mut c), TVMD_ERR_SIZE);
        assert_eq!(c.force, [0.0; 3], "a wrongly sized struct is not written");
        c.size = size_of::<TvmdCompensation>() as u32;
        assert_eq!(
            tvmd_compensation(std::ptr::null(), &mut c),
            TVMD_ERR_NULL_POINTER
        );
        assert_eq!(
            tvmd_compensation(&*handle, std::ptr::null_mut()),
            TVMD_ERR_NULL_POINTER
        );
    }
}
