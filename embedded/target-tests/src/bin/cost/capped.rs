//! Issue 59's n = 16 saturating cycle: the offset-free law's searching cycle (a request that
//! loads most agents to their limits: 12 rounds of the redistributed pseudo-inverse) with the
//! redistribution capped (`CappedRedistribution`), against the paper's law and allocator on
//! the same state and reference (target: at most twice), and the error the cap leaves.

use cortex_m_semihosting::hprintln;
use tvmd_core::controller::roll;
use tvmd_core::nalgebra::{convert, Vector3};
use tvmd_core::{
    CappedRedistribution, Controller, ControllerSettings, RedistributedPseudoInverse, Reference,
    RigidState,
};

use crate::{measure, team};

/// Issue 59: the n = 16 offset-free searching cycle at most twice the paper law's.
const RATIO_BOUND: u32 = 2;

/// Prints the capped cycles (each cap in `caps`) beside the paper's; `false` if one was
/// refused or the default cap is above the bound.
pub fn report<const N: usize>(per_tick: u32, caps: &[u32]) -> bool {
    let paper = measure::<N, _>(
        true,
        ControllerSettings::paper(),
        RedistributedPseudoInverse,
        per_tick,
    );
    let Some(paper) = paper else {
        hprintln!("cost: n = {} capped redistribution: FAIL: refused", N);
        return false;
    };
    let mut ok = true;
    for &cap in caps {
        let Ok(allocator) = CappedRedistribution::new(cap) else {
            return false;
        };
        let settings = ControllerSettings::offset_free_law();
        let (Some(m), Some((torque, missed))) = (
            measure::<N, _>(true, settings, allocator, per_tick),
            torque_error::<N>(allocator),
        ) else {
            hprintln!(
                "cost: n = {} capped redistribution {}: FAIL: refused",
                N,
                cap
            );
            ok = false;
            continue;
        };
        let within = m.instructions <= RATIO_BOUND * paper.instructions;
        let checked = cap == CappedRedistribution::DEFAULT_MAX_ROUNDS;
        ok &= within || !checked;
        hprintln!(
            "cost: n = {:2} searching cycle, offset-free law, capped-redistribution ({} rounds): {:6} instructions, peak stack {:5} B ({:.2} x the paper law's {}; issue 59: <= {}{}); torque requested {:.1} N m, missed {:.2} N m",
            N,
            cap,
            m.instructions,
            m.stack,
            m.instructions as f32 / paper.instructions as f32,
            paper.instructions,
            RATIO_BOUND,
            match (within, checked) {
                (true, _) => "",
                (false, true) => "  FAIL: above",
                (false, false) => "  (above; not the default cap)",
            },
            torque,
            missed
        );
    }
    ok
}

/// The offset-free law's first searching cycle with `allocator`: `||u_tau_d||` and the
/// torque the allocation misses (N m).
fn torque_error<const N: usize>(allocator: CappedRedistribution) -> Option<(f32, f32)> {
    let settings = ControllerSettings::offset_free_law();
    let mut c = Controller::new(team::<N>()?, settings, allocator).ok()?;
    let state = RigidState::at_rest(Vector3::new(0.2f32, 0.0, 1.5));
    let mut reference = Reference::hover(Vector3::new(0.0, 0.0, 1.5));
    reference.attitude = roll(convert::<f64, f32>(core::f64::consts::FRAC_PI_3));
    let out = c.step(&state, &reference).ok()?;
    let requested = out.law.u_d.fixed_rows::<3>(0).norm();
    let delivered = out.allocation.wrench.fixed_rows::<3>(0);
    Some((
        requested,
        (out.law.u_d.fixed_rows::<3>(0) - delivered).norm(),
    ))
}
