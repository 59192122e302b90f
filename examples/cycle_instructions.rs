//! One full control cycle (n = 4, the paper's team) in f32 and in f64 inside named,
//! non-inlined functions, for deterministic instruction counts with callgrind:
//! `bash benches/callgrind.sh` (which runs this under
//! `valgrind --tool=callgrind --toggle-collect=...`). Without valgrind it just runs the cycles.

use std::hint::black_box;

use tvmd::core::controller::roll;
use tvmd::core::nalgebra::Vector3;
use tvmd::core::team::presets;
use tvmd::core::{
    Controller, ControllerSettings, Real, RedistributedPseudoInverse, Reference, RigidState,
};

type Cycle<T> = Controller<T, 4, RedistributedPseudoInverse>;
/// A controller with its inputs.
type Setup<T> = (Cycle<T>, RigidState<T>, Reference<T>);

fn setup<T: Real>() -> Result<Setup<T>, tvmd::core::ConfigError> {
    let lit = |x: f64| -> T { tvmd::core::nalgebra::convert(x) };
    let controller = Controller::new(
        presets::a4_inc::<T, 4>()?,
        ControllerSettings::paper(),
        RedistributedPseudoInverse,
    )?;
    let state = RigidState::at_rest(Vector3::new(lit(0.2), T::zero(), lit(1.5)));
    let mut reference = Reference::hover(Vector3::new(T::zero(), T::zero(), lit(1.5)));
    reference.attitude = roll(lit(std::f64::consts::FRAC_PI_3));
    Ok((controller, state, reference))
}

/// The measured f32 cycle (planner bisection included: the reference roll is infeasible).
#[inline(never)]
#[no_mangle]
pub fn tvmd_cycle_f32(c: &mut Cycle<f32>, s: &RigidState<f32>, r: &Reference<f32>) -> f32 {
    c.step(s, r).map(|o| o.commands[0].thrust).unwrap_or(-1.0)
}

/// The measured f64 cycle.
#[inline(never)]
#[no_mangle]
pub fn tvmd_cycle_f64(c: &mut Cycle<f64>, s: &RigidState<f64>, r: &Reference<f64>) -> f64 {
    c.step(s, r).map(|o| o.commands[0].thrust).unwrap_or(-1.0)
}

/// A hover cycle (no bisection): the common case in flight.
#[inline(never)]
#[no_mangle]
pub fn tvmd_cycle_hover_f32(c: &mut Cycle<f32>, s: &RigidState<f32>) -> f32 {
    c.step(s, &Reference::hover(s.position))
        .map(|o| o.commands[0].thrust)
        .unwrap_or(-1.0)
}

fn main() -> Result<(), tvmd::core::ConfigError> {
    let (mut c32, s32, r32) = setup::<f32>()?;
    let (mut c64, s64, r64) = setup::<f64>()?;
    let a = tvmd_cycle_f32(black_box(&mut c32), black_box(&s32), black_box(&r32));
    let b = tvmd_cycle_f64(black_box(&mut c64), black_box(&s64), black_box(&r64));
    let h = tvmd_cycle_hover_f32(black_box(&mut c32), black_box(&s32));
    println!("agent 0 thrust: f32 {a:.4} N, f64 {b:.4} N, hover f32 {h:.4} N");
    Ok(())
}
