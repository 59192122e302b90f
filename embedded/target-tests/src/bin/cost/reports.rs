//! The agents' reports in the fault detector (issue 60): the f32 cycle with the recommended
//! detector reporting, each agent's report given before the step (`Controller::set_report`,
//! as a flight controller calls it per agent and period) and checked in it, against the same
//! cycle without reports; the hover and the searching cycle at capacity `N`. Fails at n = 4
//! above [`REPORTS_EXTRA_BOUND`]. The reports agree with the commands (a nominal period).

use core::hint::black_box;

use cortex_m_semihosting::hprintln;
use tvmd_core::{
    AgentReading, Controller, ControllerSettings, FaultDetection, FaultResponse,
    RedistributedPseudoInverse, Reference, RigidState,
};

use crate::{clock, cycle_case, team, REPS};

/// Issue 60's bound on the reports' extra instructions at n = 4.
pub const REPORTS_EXTRA_BOUND: u32 = 800;

type Detecting<const N: usize> = Controller<f32, N, RedistributedPseudoInverse>;

/// A measured unit's shape.
type Unit<const N: usize> =
    fn(&mut Detecting<N>, &[AgentReading<f32>; N], &RigidState<f32>, &Reference<f32>) -> f32;

/// The measured unit: the reports given, then one cycle.
#[inline(never)]
fn reported<const N: usize>(
    c: &mut Detecting<N>,
    readings: &[AgentReading<f32>; N],
    s: &RigidState<f32>,
    r: &Reference<f32>,
) -> f32 {
    for (i, reading) in readings.iter().enumerate() {
        let _ = c.set_report(i, *reading);
    }
    c.step(s, r).map(|o| o.commands[0].thrust).unwrap_or(-1.0)
}

/// The cycle alone (the same call shape).
#[inline(never)]
fn plain<const N: usize>(
    c: &mut Detecting<N>,
    _readings: &[AgentReading<f32>; N],
    s: &RigidState<f32>,
    r: &Reference<f32>,
) -> f32 {
    c.step(s, r).map(|o| o.commands[0].thrust).unwrap_or(-1.0)
}

/// Prints the two counts and the difference for the hover and the searching cycle; `false`
/// when a controller was refused or n = 4 is above the bound.
pub fn report<const N: usize>(per_tick: u32) -> bool {
    let mut ok = true;
    for searching in [false, true] {
        let name = if searching { "searching" } else { "hover" };
        let settings = ControllerSettings {
            fault_detection: Some(FaultDetection::recommended(FaultResponse::Report)),
            ..ControllerSettings::offset_free_law()
        };
        let Some(mut c) = team::<N>()
            .and_then(|t| Controller::new(t, settings, RedistributedPseudoInverse).ok())
        else {
            hprintln!("cost: n = {} reports: FAIL: controller refused", N);
            return false;
        };
        let (state, reference) = cycle_case(searching);
        let Ok(out) = c.step(&state, &reference) else {
            hprintln!("cost: n = {} reports: FAIL: the first cycle refused", N);
            return false;
        };
        // Each agent reports the command it was sent, 20 ms ago: new at every measured cycle
        // (the copy holds it one period older).
        let Ok(zero) = AgentReading::new(0.0f32, 0.0, 0.0, 0.02) else {
            return false;
        };
        let mut readings = [zero; N];
        for (r, cmd) in readings.iter_mut().zip(&out.commands) {
            if let Ok(x) = AgentReading::new(cmd.thrust, cmd.eta_x, cmd.eta_y, 0.02) {
                *r = x;
            }
        }
        let mut with = c.clone();
        for (i, r) in readings.iter().enumerate() {
            let _ = with.set_report(i, *r);
        }
        let _ = with.step(&state, &reference);
        let count = |c: &Detecting<N>, f: Unit<N>| {
            let work = clock::ticks(REPS, &mut || {
                let mut fresh = black_box(c.clone());
                black_box(f(
                    black_box(&mut fresh),
                    black_box(&readings),
                    black_box(&state),
                    black_box(&reference),
                ));
            });
            let overhead = clock::ticks(REPS, &mut || {
                let fresh = black_box(c.clone());
                black_box(&fresh);
            });
            clock::per_call(work, overhead, per_tick, REPS)
        };
        let without = count(&c, plain::<N>);
        let reports = count(&with, reported::<N>);
        let extra = reports.saturating_sub(without);
        let bounded = N != 4 || extra <= REPORTS_EXTRA_BOUND;
        ok &= bounded;
        hprintln!(
            "cost: n = {:2} {:9} cycle, fault detection: {} instructions without reports, {} with every agent's report given and checked: {} more{}",
            N,
            name,
            without,
            reports,
            extra,
            if bounded { "" } else { "  FAIL: above issue 60's 800" }
        );
    }
    ok
}
