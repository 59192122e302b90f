//! Worst-case certificates of the whole control cycle (issue 59): the cycle around the
//! allocation (law, planner, command inversion, checks) measured with an allocator that hands
//! back given forces, its planner search bounded by the planner's own loop limit, plus the
//! allocation's certificate (`certificate.rs`).
//!
//! The planner's bisection (`afs/planner.rs`) halves the bracket `[0, theta_max]`,
//! `theta_max <= pi`, until it is narrower than the tolerance, and takes at most 4 secant steps
//! more: at most `k + 4` iterations where `pi / 2^k <= tolerance`, and never more than its cap.
//! Per iteration: the searching cycle's cost above the hover cycle's, divided by its iterations
//! (the search's set-up counted in, so an over-estimate), for the iterations beyond the measured
//! search's. The fault detector is certified with its isolation running (every working agent's
//! fits each period, its most expensive period) and `FaultResponse::Report`; a `Mask` response's
//! masking is a reconfiguration (`Controller::set_failures`), a set-up cost not certified here.

use cortex_m_semihosting::hprintln;
use tvmd_core::controller::roll;
use tvmd_core::nalgebra::{convert, Vector3};
use tvmd_core::{
    Allocation, AllocationRequest, Allocator, AttitudePlanner, Controller, ControllerSettings,
    FaultDetection, FaultResponse, PseudoInverse, Reference, Relaxation, RigidState,
};

use crate::certificate::{Certificates, Certified};

/// An allocator that hands back given forces (with their wrench and errors), for the cycle
/// around the allocation.
#[derive(Clone)]
pub struct Given<const N: usize>(pub [Vector3<f32>; N]);

impl<const N: usize> Allocator<f32, N> for Given<N> {
    fn allocate(&mut self, r: &AllocationRequest<'_, f32, N>) -> Allocation<f32, N> {
        Allocation::from_forces(r, self.0, 1, [false; N])
    }

    fn name(&self) -> &'static str {
        "given"
    }
}

/// The pseudo-inverse's forces in the first searching cycle of `crate::measure` under
/// `settings`.
pub fn searching_forces<const N: usize>(
    settings: ControllerSettings<f32>,
) -> Option<[Vector3<f32>; N]> {
    let mut c = Controller::new(crate::team::<N>()?, settings, PseudoInverse).ok()?;
    let state = RigidState::at_rest(Vector3::new(0.2f32, 0.0, 1.5));
    let mut reference = Reference::hover(Vector3::new(0.0, 0.0, 1.5));
    reference.attitude = roll(convert::<f64, f32>(core::f64::consts::FRAC_PI_3));
    Some(c.step(&state, &reference).ok()?.allocation.forces)
}

/// The laws certified: the paper's, the offset-free law, the offset-free law with fault
/// detection (isolating).
pub const LAWS: [&str; 3] = ["paper", "offset-free", "fault detection"];

/// The settings of law `k` of [`LAWS`].
pub fn settings(k: usize) -> ControllerSettings<f32> {
    match k {
        0 => ControllerSettings::paper(),
        1 => ControllerSettings::offset_free_law(),
        // A model error so small that every residual is above the threshold: the isolation
        // runs each period.
        _ => ControllerSettings {
            fault_detection: FaultDetection::new(1e-6, 5.0, 5, FaultResponse::Report).ok(),
            ..ControllerSettings::offset_free_law()
        },
    }
}

/// The certified law of a measured case's name (`main.rs`'s four).
pub fn law_of(name: &str) -> usize {
    match name {
        "paper" => 0,
        "offset-free" => 1,
        _ => 2,
    }
}

/// The most planner iterations of a cycle (see the module's docs).
pub fn planner_iteration_bound() -> u32 {
    let planner = AttitudePlanner::<f32>::new(Relaxation::none());
    let mut width = core::f32::consts::PI;
    let mut bisection = 0u32;
    while width > planner.tolerance() && bisection < 64 {
        width *= 0.5;
        bisection += 1;
    }
    (bisection + 4).min(planner.max_iterations())
}

/// The cycle around the allocation of each law of [`LAWS`] for a team of `N`.
#[derive(Clone, Copy, Debug, Default)]
pub struct Around {
    certified: [u32; 3],
}

impl Around {
    /// Measures the hover and searching cycles around given forces; `None` if refused.
    pub fn measure<const N: usize>(per_tick: u32) -> Option<Self> {
        let bound = planner_iteration_bound();
        let mut certified = [0; 3];
        for (k, slot) in certified.iter_mut().enumerate() {
            let s = settings(k);
            let given = Given(searching_forces::<N>(s)?);
            let hover = crate::measure::<N, _>(false, s, given.clone(), per_tick)?;
            let search = crate::measure::<N, _>(true, s, given, per_tick)?;
            let iterations = search.iterations.max(1);
            let per = search
                .instructions
                .saturating_sub(hover.instructions)
                .div_ceil(iterations);
            *slot = search.instructions + bound.saturating_sub(iterations) * per;
            hprintln!(
                "certificate: cycle n = {:2} {:15} law around the allocation: hover {}, searching {} ({} planner iterations), {} per iteration, at most {} iterations: certified {}",
                N, LAWS[k], hover.instructions, search.instructions, search.iterations, per, bound, slot
            );
        }
        Some(Self { certified })
    }

    /// The whole cycle's certificate with law `law` and `allocator`.
    pub fn cycle(&self, law: usize, allocator: Certified, c: &Certificates) -> u32 {
        self.certified.get(law).copied().unwrap_or(u32::MAX) + c.allocation(allocator)
    }

    /// Checks a measured cycle (`what`) against its certificate; prints the pair.
    pub fn check(
        &self,
        (what, case): (&str, &str),
        law: usize,
        allocator: Certified,
        c: &Certificates,
        measured: u32,
    ) -> bool {
        let certified = self.cycle(law, allocator, c);
        let within = measured <= certified;
        hprintln!(
            "certificate: cycle n = {:2} {} {} ({} law certified, {}): measured {}, certified {}{}",
            c.n,
            what,
            case,
            LAWS.get(law).copied().unwrap_or("?"),
            allocator.name(),
            measured,
            certified,
            if within {
                ""
            } else {
                "  FAIL: above its certificate"
            }
        );
        within
    }
}
