//! The null-space stage after every allocator, in `f64` and `f32`: on random teams (presets,
//! with and without a failed agent) and random attainable and saturated requests, the refined
//! forces are finite and admissible, failed agents stay at zero, the wrench moves by at most
//! the stated drift bound, and the objective (and, for the margin objective, the smallest
//! margin) never falls. The controller runs the stage only when configured.
#![cfg(feature = "null-space")]

use nalgebra::{Vector3, Vector6};
use proptest::prelude::*;
use rand::{rngs::StdRng, Rng, SeedableRng};
use tvmd_core::team::presets;
use tvmd_core::{
    AdmissibleSet, AllocationRequest, Allocator, AnyAllocator, Controller, ControllerSettings,
    FailureMask, GimbalCommand, NullSpaceObjective, NullSpaceReport, NullSpaceStage, Real,
    Reference, RigidState, TeamConfig,
};

const CAP: usize = 8;

fn team_by_index<T: Real>(which: usize) -> TeamConfig<T, CAP> {
    match which % 4 {
        0 => presets::a4_inc().unwrap(),
        1 => presets::a4_con().unwrap(),
        2 => presets::ring(6, nalgebra::convert(0.5), true, presets::paper_limits()).unwrap(),
        _ => presets::ring(8, nalgebra::convert(0.6), false, presets::paper_limits()).unwrap(),
    }
}

fn lit<T: Real>(x: f64) -> T {
    nalgebra::convert(x)
}

/// A command inside `set`, at one of its bounds about a third of the time per range.
fn admissible_command<T: Real>(rng: &mut StdRng, set: &AdmissibleSet<T>) -> GimbalCommand<T> {
    let to = |x: T| -> f64 { nalgebra::try_convert(x).unwrap() };
    let pick = |rng: &mut StdRng, lo: T, hi: T| match rng.random_range(0..6) {
        0 => lo,
        1 => hi,
        _ => lit(rng.random_range(to(lo)..=to(hi))),
    };
    GimbalCommand {
        eta_x: pick(rng, set.eta_x().lo, set.eta_x().hi),
        eta_y: pick(rng, set.eta_y().lo, set.eta_y().hi),
        thrust: pick(rng, set.thrust().lo, set.thrust().hi),
    }
}

/// One random case: team, failure, request kind, allocator and objective from `seed`; checks
/// every property and returns the report.
fn check_case<T: Real>(seed: u64) -> NullSpaceReport<T> {
    let mut rng = StdRng::seed_from_u64(seed);
    let team: TeamConfig<T, CAP> = team_by_index(rng.random_range(0..4));
    let n = team.len();
    // One failed agent a third of the time, if the rest keep rank 6.
    let mut failures = FailureMask::none();
    if rng.random_range(0..3) == 0 {
        let candidate = FailureMask::with_failed(&[rng.random_range(0..n)]).unwrap();
        if team.effectiveness(&candidate).check_rank().is_ok() {
            failures = candidate;
        }
    }
    let e = team.effectiveness(&failures);
    let sets = [AdmissibleSet::from_limits(team.limits()); CAP];
    let mut forces = [Vector3::zeros(); CAP];
    for (f, s) in forces.iter_mut().zip(&sets).take(n) {
        *f = admissible_command(&mut rng, s).force();
    }
    // Attainable by construction, or scaled beyond the attainable set.
    let scale: T = if rng.random_bool(0.5) {
        T::one()
    } else {
        lit(rng.random_range(1.3..4.0))
    };
    let wrench: Vector6<T> = e.wrench(&forces) * scale;
    let request = AllocationRequest {
        effectiveness: &e,
        sets: &sets,
        wrench,
    };
    let names = AnyAllocator::<T, CAP>::NAMES;
    let name = names[rng.random_range(0..names.len())];
    let mut allocator = AnyAllocator::<T, CAP>::from_name(name, &Default::default()).unwrap();
    allocator.configure(&e);
    let allocation = allocator.allocate(&request);
    let objective = if rng.random_bool(0.5) {
        NullSpaceObjective::Margin
    } else {
        NullSpaceObjective::InwardTilt {
            angle: lit(rng.random_range(-0.4..0.4)),
        }
    };
    let stage = NullSpaceStage::new(objective, rng.random_range(1..=16)).unwrap();
    let (refined, report) = stage.refine(&request, &allocation);
    let context = format!("seed {seed}: {name}, {objective:?}, {failures:?}, {report:?}");
    for (i, (f, f0)) in refined.forces.iter().zip(&allocation.forces).enumerate() {
        assert!(f.iter().all(|x| x.is_finite()), "{context}: agent {i}");
        if e.block(i).is_none() {
            assert_eq!(*f, Vector3::zeros(), "{context}: failed agent {i}");
        } else if f != f0 {
            // A moved agent is inside its set by the gimbal inverse, exactly.
            let cmd = GimbalCommand::from_force(f);
            assert_eq!(sets[i].violation(&cmd), T::zero(), "{context}: agent {i}");
        }
    }
    let drift = (e.wrench(&refined.forces) - e.wrench(&allocation.forces)).norm();
    let bound = NullSpaceStage::drift_bound(&e, &allocation.forces, &refined.forces);
    assert!(drift <= bound, "{context}: drift {drift:?} > {bound:?}");
    assert!(refined.e_f.is_finite() && refined.wrench_error.is_finite());
    assert!(
        report.objective_after >= report.objective_before,
        "{context}"
    );
    if objective == NullSpaceObjective::Margin {
        assert!(report.margin_after >= report.margin_before, "{context}");
    }
    if report.changed() {
        assert!(
            report.ran && report.largest_force_change > T::zero(),
            "{context}"
        );
    } else {
        assert_eq!(refined, allocation, "{context}");
    }
    report
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(384))]

    #[test]
    fn the_stage_keeps_the_wrench_and_the_sets_in_f64(seed in any::<u64>()) {
        check_case::<f64>(seed);
    }

    #[test]
    fn the_stage_keeps_the_wrench_and_the_sets_in_f32(seed in any::<u64>()) {
        check_case::<f32>(seed);
    }
}

#[test]
fn the_stage_changes_most_cases_and_raises_margins_on_average() {
    // Not vacuous: over fixed seeds most cases run and change, and the smallest margin rises
    // on average (whatever the objective).
    let (mut changed, mut gain, mut margin_cases) = (0, 0.0, 0);
    for seed in 0..300u64 {
        let r = check_case::<f64>(seed);
        if r.changed() {
            changed += 1;
        }
        if r.ran {
            gain += r.margin_after - r.margin_before;
            margin_cases += 1;
        }
    }
    assert!(changed > 150, "{changed} of 300 changed");
    assert!(margin_cases > 250 && gain > 0.0, "{margin_cases} {gain}");
}

#[test]
fn the_controller_runs_the_stage_only_when_configured() {
    let team = presets::a4_inc::<f32, 4>().unwrap();
    let state = RigidState::at_rest(Vector3::new(0.3, -0.2, 1.5));
    let mut reference = Reference::hover(Vector3::new(0.0, 0.0, 1.5));
    reference.attitude = tvmd_core::rotation::roll(0.6);
    let allocator = || AnyAllocator::from_name("redistributed-pseudo-inverse", &Default::default());
    let mut plain =
        Controller::new(team, ControllerSettings::paper(), allocator().unwrap()).unwrap();
    let out = plain.step(&state, &reference).unwrap();
    assert_eq!(out.null_space, NullSpaceReport::off());
    let settings = ControllerSettings {
        null_space: Some(NullSpaceStage::new(NullSpaceObjective::Margin, 8).unwrap()),
        ..ControllerSettings::paper()
    };
    let mut refined = Controller::new(team, settings, allocator().unwrap()).unwrap();
    let with = refined.step(&state, &reference).unwrap();
    assert!(with.null_space.ran, "{:?}", with.null_space);
    assert!(with.null_space.margin_after >= with.null_space.margin_before);
    assert!(with.command_clamp <= tvmd_core::command::command_tolerance());
    // Same wrench to round-off, same law.
    assert_eq!(with.law.u_d, out.law.u_d);
    let drift = (with.allocation.wrench - out.allocation.wrench).norm();
    assert!(drift <= 1e-3 * out.allocation.wrench.norm(), "{drift}");
}
