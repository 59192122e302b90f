//! Issue 59's n = 16 saturating cycle: the offset-free law's searching cycle (a request that
//! loads most agents to their limits: 12 rounds of the redistributed pseudo-inverse) with the
//! redistribution capped (`CappedRedistribution`), against the paper's law and allocator on
//! the same state and reference (target: at most twice), and the error the cap leaves.

use cortex_m_semihosting::hprintln;
use tvmd_core::controller::roll;
use tvmd_core::nalgebra::{convert, Vector3, Vector6};
use tvmd_core::{
    AllocationRequest, Allocator, CappedRedistribution, Controller, ControllerSettings,
    ExactBoundaryRedistribution, RedistributedPseudoInverse, Reference, RigidState, RoundCap,
};

use crate::certificate::{Certificates, Certified};
use crate::cycle_certificate::Around;
use crate::{measure, team};

/// Issue 59: the n = 16 offset-free searching cycle at most twice the paper law's.
const RATIO_BOUND: u32 = 2;

/// Prints the capped cycles (each cap in `caps`) beside the paper's, each checked against its
/// certificate (`around`, `certificates`: the team's of `N`); `false` if one was refused, is
/// above its certificate, or the default cap is above the bound.
pub fn report<const N: usize>(
    per_tick: u32,
    caps: &[u32],
    certificates: &Certificates,
    around: &Around,
) -> bool {
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
        let (Some(m), Some((torque, missed, attainable))) = (
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
        if checked {
            let certified = Certified::Capped(cap);
            let case = ("searching", "capped");
            ok &= around.check(case, 1, certified, certificates, m.instructions);
        }
        ok &= within || !checked;
        hprintln!(
            "cost: n = {:2} searching cycle, offset-free law, capped-redistribution ({} rounds): {:6} instructions, peak stack {:5} B ({:.2} x the paper law's {}; issue 59: <= {}{}); torque requested {:.1} N m (attainable along it with its force: {:.1} N m), missed {:.2} N m",
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
            attainable,
            missed
        );
    }
    ok
}

/// The largest torque along `u_d`'s that the team delivers with `u_d`'s force (N m): the
/// uncapped exact-boundary walk meeting the scaled request, by bisection on the scale.
fn attainable_torque<const N: usize, A: Allocator<f32, N>>(
    c: &Controller<f32, N, A>,
    u_d: &Vector6<f32>,
) -> f32 {
    let sets = c.admissible_sets();
    let met = |scale: f32| {
        let mut wrench = *u_d;
        for t in wrench.iter_mut().take(3) {
            *t *= scale;
        }
        let mut a = ExactBoundaryRedistribution::<f32, N>::new().with_round_cap(RoundCap::Uncapped);
        let out = a.allocate(&AllocationRequest {
            effectiveness: c.effectiveness(),
            sets: &sets,
            wrench,
        });
        out.wrench_error <= 1e-3 * (1.0 + wrench.norm())
    };
    let (mut lo, mut hi) = (0.0f32, 4.0f32);
    for _ in 0..20 {
        let mid = 0.5 * (lo + hi);
        if met(mid) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    lo * u_d.fixed_rows::<3>(0).norm()
}

/// The offset-free law's first searching cycle with `allocator`: `||u_tau_d||`, the torque the
/// allocation misses and the torque attainable along it (N m).
fn torque_error<const N: usize>(allocator: CappedRedistribution) -> Option<(f32, f32, f32)> {
    let settings = ControllerSettings::offset_free_law();
    let mut c = Controller::new(team::<N>()?, settings, allocator).ok()?;
    let state = RigidState::at_rest(Vector3::new(0.2f32, 0.0, 1.5));
    let mut reference = Reference::hover(Vector3::new(0.0, 0.0, 1.5));
    reference.attitude = roll(convert::<f64, f32>(core::f64::consts::FRAC_PI_3));
    let out = c.step(&state, &reference).ok()?;
    let attainable = attainable_torque(&c, &out.law.u_d);
    let requested = out.law.u_d.fixed_rows::<3>(0).norm();
    let delivered = out.allocation.wrench.fixed_rows::<3>(0);
    Some((
        requested,
        (out.law.u_d.fixed_rows::<3>(0) - delivered).norm(),
        attainable,
    ))
}
