//! The n = 4 whole-cycle estimate over the allocation set: the searching cycle around an
//! allocator that hands back a given allocation ([`around`]; the allocation's own
//! `Allocation::from_forces` is part of every allocation measured, so not counted here again),
//! plus each allocation; and its check on one cycle that can be measured whole ([`report`]):
//! the default allocator's own searching cycle against the cycle around a given allocation plus
//! the default's allocation of that cycle's request by a reset allocator (as over the set).

use core::hint::black_box;

use cortex_m_semihosting::hprintln;
use tvmd_core::controller::roll;
use tvmd_core::nalgebra::{convert, Vector3, Vector6};
use tvmd_core::{
    Allocation, AllocationRequest, Allocator, Controller, ControllerSettings,
    ExactBoundaryRedistribution, PseudoInverse, Reference, RigidState,
};

use crate::{clock, measure, team};

/// Allocations per count (each count within `4 * 40 / REPS` instructions).
const REPS: u32 = 20;

/// An allocator that hands back a given allocation (forces, wrench and errors computed before).
#[derive(Clone)]
struct GivenAllocation<const N: usize>(Allocation<f32, N>);

impl<const N: usize> Allocator<f32, N> for GivenAllocation<N> {
    fn allocate(&mut self, _: &AllocationRequest<'_, f32, N>) -> Allocation<f32, N> {
        self.0
    }

    fn name(&self) -> &'static str {
        "given allocation"
    }
}

/// The paper law's first searching cycle of `crate::measure` with the pseudo-inverse: the
/// controller after it, that cycle's allocation and its request `u_d`.
#[allow(clippy::type_complexity)]
fn searching() -> Option<(
    Controller<f32, 4, PseudoInverse>,
    Allocation<f32, 4>,
    Vector6<f32>,
)> {
    let settings = ControllerSettings::paper();
    let mut c = Controller::new(team::<4>()?, settings, PseudoInverse).ok()?;
    let state = RigidState::at_rest(Vector3::new(0.2f32, 0.0, 1.5));
    let mut reference = Reference::hover(Vector3::new(0.0, 0.0, 1.5));
    reference.attitude = roll(convert::<f64, f32>(core::f64::consts::FRAC_PI_3));
    let out = c.step(&state, &reference).ok()?;
    Some((c, out.allocation, out.law.u_d))
}

/// The n = 4 searching cycle (paper's law) around a given allocation (instructions).
pub fn around(per_tick: u32) -> Option<u32> {
    let (_, given, _) = searching()?;
    let settings = ControllerSettings::paper();
    measure::<4, _>(true, settings, GivenAllocation(given), per_tick).map(|m| m.instructions)
}

/// Prints the measured cycle, the estimate and their difference; `None` if refused.
pub fn report(per_tick: u32) -> Option<()> {
    let settings = ControllerSettings::paper();
    let default = ExactBoundaryRedistribution::<f32, 4>::new();
    let whole = measure::<4, _>(true, settings, default, per_tick)?.instructions;
    let around = around(per_tick)?;
    // The request of that cycle (the law's `u_d` of the first searching cycle).
    let (c, _, wrench) = searching()?;
    let sets = c.admissible_sets();
    let request = AllocationRequest {
        effectiveness: c.effectiveness(),
        sets: &sets,
        wrench,
    };
    let mut a = default;
    let work = clock::ticks(REPS, &mut || {
        let a = black_box(&mut a);
        a.reset();
        black_box(a.allocate(black_box(&request)).e_f);
    });
    let idle = clock::ticks(REPS, &mut || {
        black_box(black_box(&request).wrench.x);
    });
    let per = u64::from(work.saturating_sub(idle)) * u64::from(per_tick);
    let allocation = ((per + u64::from(REPS) / 2) / u64::from(REPS)) as u32;
    let estimate = around + allocation;
    hprintln!(
        "cost: n =  4 whole-cycle estimate checked on the searching cycle: around a given allocation {} + the default's allocation of its request {} = {}, measured {} ({:+} instructions)",
        around,
        allocation,
        estimate,
        whole,
        i64::from(estimate) - i64::from(whole)
    );
    Some(())
}
