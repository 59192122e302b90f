//! Control-cycle benchmarks: each stage and the full `Controller::step`, for
//! n in {3, 4, 8, 16, 32, 64} agents, in f32 and f64.
//!
//! The capacity `N` equals `n`, so the cost measured is that of `n` agents (no empty slots).
//! Inputs: the team 0.2 m off its hover reference while the reference rolls to pi/3, so the
//! planner runs its bisection; the redistribution benchmark uses a request that saturates.
//! Run: `cargo bench --bench control_cycle` (add `--features clarabel` for the QP allocator).

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use tvmd::core::controller::roll;
use tvmd::core::nalgebra::{Vector3, Vector6};
use tvmd::core::team::presets;
use tvmd::core::{
    project_force, AdmissibleSet, AllocationRequest, Allocator, AttitudePlanner, Controller,
    ControllerSettings, ExactBoundaryRedistribution, FailureMask, PseudoInverse, Real,
    RedistributedPseudoInverse, Reference, RigidState, TeamConfig,
};

fn lit<T: Real>(x: f64) -> T {
    tvmd::core::nalgebra::convert(x)
}

/// The paper's A4-Inc for n = 4, else an inconsistent ring with the paper's agents spaced as
/// in the paper's square.
fn team<T: Real, const N: usize>() -> TeamConfig<T, N> {
    let team = if N == 4 {
        presets::a4_inc()
    } else {
        let radius = 0.5 * (N as f64 / 4.0).sqrt();
        presets::ring(N, lit(radius), true, presets::paper_limits())
    };
    team.unwrap_or_else(|e| panic!("benchmark team with {N} agents: {e}"))
}

fn inputs<T: Real>() -> (RigidState<T>, Reference<T>) {
    let state = RigidState::at_rest(Vector3::new(lit(0.2), T::zero(), lit(1.5)));
    let mut reference = Reference::hover(Vector3::new(T::zero(), T::zero(), lit(1.5)));
    reference.attitude = roll(lit(std::f64::consts::FRAC_PI_3));
    (state, reference)
}

fn bench_size<T: Real, const N: usize>(c: &mut Criterion, float: &str) {
    let team = team::<T, N>();
    let none = FailureMask::none();
    let afs = team.afs(&none).expect("afs");
    let settings = ControllerSettings::<T>::paper();
    let (state, reference) = inputs::<T>();
    let weight = team.mass() * lit(9.81);
    let u = Vector3::new(lit(2.0), lit(-1.0), weight);

    let mut g = c.benchmark_group(float);
    g.bench_with_input(BenchmarkId::new("afs_contains", N), &u, |b, u| {
        b.iter(|| afs.contains(black_box(u), settings.relaxation))
    });
    let wide = Vector3::new(weight, -weight, weight);
    g.bench_with_input(BenchmarkId::new("projection", N), &wide, |b, u| {
        b.iter(|| project_force(&afs, black_box(u)))
    });
    let planner = AttitudePlanner::new(settings.relaxation);
    let f_r = Vector3::new(T::zero(), T::zero(), weight);
    g.bench_with_input(BenchmarkId::new("planner", N), &f_r, |b, f_r| {
        b.iter(|| planner.plan(&afs, black_box(&reference.attitude), black_box(f_r)))
    });
    // As the controller plans: the cone at the planner's `s` kept between periods (`plan_in`).
    let cone = afs.cone(settings.relaxation);
    g.bench_with_input(BenchmarkId::new("planner_in", N), &f_r, |b, f_r| {
        b.iter(|| planner.plan_in(&cone, black_box(&reference.attitude), black_box(f_r)))
    });
    let plant = tvmd::core::law::Plant::new(team.mass(), team.inertia(), lit(9.81))
        .expect("the preset team's plant is valid");
    let r_d = roll(lit(0.33));
    g.bench_with_input(BenchmarkId::new("control_law", N), &state, |b, state| {
        b.iter(|| {
            let u_fr = tvmd::core::law::force_request(
                &plant,
                &settings.gains,
                black_box(state),
                &reference,
            );
            tvmd::core::law::control_wrench(
                &plant,
                &settings.gains,
                state,
                &reference,
                &r_d,
                &u_fr,
                &nalgebra_identity(),
            )
        })
    });
    let e = team.effectiveness(&none);
    let sets = [AdmissibleSet::from_limits(team.limits()); N];
    let hover = AllocationRequest {
        effectiveness: &e,
        sets: &sets,
        wrench: Vector6::new(lit(0.5), lit(-0.3), lit(0.1), lit(1.0), lit(-0.5), weight),
    };
    g.bench_with_input(BenchmarkId::new("pseudo_inverse", N), &hover, |b, r| {
        b.iter(|| PseudoInverse.allocate(black_box(r)))
    });
    let saturating = AllocationRequest {
        wrench: Vector6::new(lit(8.0), lit(-6.0), lit(3.0), weight, -weight, weight),
        ..hover
    };
    g.bench_with_input(
        BenchmarkId::new("redistributed_pseudo_inverse", N),
        &saturating,
        |b, r| b.iter(|| RedistributedPseudoInverse.allocate(black_box(r))),
    );
    // From no previous forces: the redistributed pseudo-inverse's start, then the walk.
    g.bench_with_input(
        BenchmarkId::new("exact_boundary_redistribution", N),
        &saturating,
        |b, r| b.iter(|| ExactBoundaryRedistribution::<T, N>::new().allocate(black_box(r))),
    );
    #[cfg(feature = "clarabel")]
    {
        let mut qp = tvmd::core::allocation::ClarabelAllocator::<T, N>::new(lit(1e-6), None)
            .expect("clarabel allocator");
        g.bench_with_input(BenchmarkId::new("clarabel", N), &saturating, |b, r| {
            b.iter(|| qp.allocate(black_box(r)))
        });
        g.bench_with_input(
            BenchmarkId::new("clarabel_admissible", N),
            &hover,
            |b, r| b.iter(|| qp.allocate(black_box(r))),
        );
        // Without the warm start every call steps from the redistributed pseudo-inverse.
        let mut sequential = tvmd::core::allocation::SequentialConvexAllocator::<T, N>::default()
            .with_warm_start(false);
        g.bench_with_input(
            BenchmarkId::new("clarabel_sequential", N),
            &saturating,
            |b, r| b.iter(|| sequential.allocate(black_box(r))),
        );
    }
    let mut controller =
        Controller::new(team, settings, RedistributedPseudoInverse).expect("controller");
    g.bench_with_input(BenchmarkId::new("cycle", N), &state, |b, state| {
        b.iter(|| controller.step(black_box(state), black_box(&reference)))
    });
    g.finish();
}

fn nalgebra_identity<T: Real>() -> tvmd::core::nalgebra::Matrix3<T> {
    tvmd::core::nalgebra::Matrix3::identity()
}

fn all_sizes<T: Real>(c: &mut Criterion, float: &str) {
    bench_size::<T, 3>(c, float);
    bench_size::<T, 4>(c, float);
    bench_size::<T, 8>(c, float);
    bench_size::<T, 16>(c, float);
    bench_size::<T, 32>(c, float);
    bench_size::<T, 64>(c, float);
}

fn f64_stages(c: &mut Criterion) {
    all_sizes::<f64>(c, "f64");
}

fn f32_stages(c: &mut Criterion) {
    all_sizes::<f32>(c, "f32");
}

criterion_group!(benches, f64_stages, f32_stages);
criterion_main!(benches);
