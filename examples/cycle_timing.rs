//! Native timing of the control cycle on the inputs of `benches/compare_numpy.py` (paper team,
//! 0.2 m off a hover reference rolled to pi/3, plain pseudo-inverse allocation), printed as
//! `ns_per_cycle <median>` for the script to read. Criterion (`cargo bench`) is the careful
//! measurement; this is the same cycle timed the simple way for the cross-language comparison.

use std::time::Instant;

use tvmd::core::controller::roll;
use tvmd::core::nalgebra::Vector3;
use tvmd::core::team::presets;
use tvmd::core::{Controller, ControllerSettings, PseudoInverse, Reference, RigidState};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut controller = Controller::new(
        presets::a4_inc::<f64, 4>()?,
        ControllerSettings::paper(),
        PseudoInverse,
    )?;
    let state = RigidState::at_rest(Vector3::new(0.2, 0.0, 1.5));
    let mut reference = Reference::hover(Vector3::new(0.0, 0.0, 1.5));
    reference.attitude = roll(std::f64::consts::FRAC_PI_3);
    let per_batch = 10_000;
    let mut samples = Vec::with_capacity(31);
    for _ in 0..31 {
        let start = Instant::now();
        for _ in 0..per_batch {
            std::hint::black_box(controller.step(std::hint::black_box(&state), &reference)?);
        }
        samples.push(start.elapsed().as_nanos() as f64 / per_batch as f64);
    }
    samples.sort_by(f64::total_cmp);
    println!("ns_per_cycle {:.1}", samples[samples.len() / 2]);
    Ok(())
}
