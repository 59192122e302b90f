//! Speed of the simulator (issue 19): the real-time factor of the 16 s `paper-tilt` flight (rapier
//! at 1 kHz, the tvmd controller at 100 Hz) with and without its MCAP log, the coarse-step mode
//! (`physics.dt = 0.002`), flights per second for a batch on every core, and two floors: a bare
//! rapier world like the (one dynamic body of five balls over a cuboid ground) stepped
//! alone, and the simulator's own `PhysicsWorld` stepped alone, hovering and resting on the
//! ground.
//!
//! `cargo bench -p tvmd-sim --bench paper_tilt`; after criterion's report it prints one line per
//! case, `RTF = simulated time / median wall time`.

use std::cell::RefCell;
use std::time::{Duration, Instant};

use criterion::{criterion_group, criterion_main, Criterion};
use nalgebra::Vector3;
use rapier3d_f64::prelude::{ColliderBuilder, IntegrationParameters, RigidBodyBuilder};
use rapier3d_f64::{math as rm, pipeline::PhysicsWorld};
use tvmd_plant::physics::{ExtraWrench, PhysicsWorld as TvmdWorld, PlantState};
use tvmd_scenario::Scenario;
use tvmd_sim::runner::{fly, run_many, worker_count, RunSpec};
use tvmd_sim::sim::SampleRetention;
use tvmd_sim::GRAVITY;

/// The CLI's allocator (`src/main.rs`), so the flights here cost what `tvmd-sim run` pays.
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

fn spec(scenario: &Scenario, log: Option<std::path::PathBuf>) -> RunSpec {
    RunSpec {
        scenario: scenario.clone(),
        log,
        pil: None,
        // As `tvmd-sim run`: the summary folds every tick, no sample is kept.
        samples: SampleRetention::None,
    }
}

fn median(mut times: Vec<f64>) -> f64 {
    times.sort_by(f64::total_cmp);
    times.get(times.len() / 2).copied().unwrap_or(f64::NAN)
}

/// Times `run` (one flight per call) in a criterion group; returns the median seconds per call.
fn time_flights(c: &mut Criterion, name: &str, mut run: impl FnMut()) -> f64 {
    let times = RefCell::new(Vec::new());
    let mut group = c.benchmark_group("simulator");
    group
        .sample_size(10)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(8));
    group.bench_function(name, |b| {
        b.iter_custom(|iters| {
            let mut total = Duration::ZERO;
            for _ in 0..iters {
                let t0 = Instant::now();
                run();
                let dt = t0.elapsed();
                times.borrow_mut().push(dt.as_secs_f64());
                total += dt;
            }
            total
        });
    });
    group.finish();
    median(times.into_inner())
}

/// The world of the floor: one dynamic body (five ball colliders, can_sleep off) over a
/// cuboid ground, stepped with a constant upward force that holds it in the air.
fn bare_world(iterations: usize) -> PhysicsWorld {
    let mut world = PhysicsWorld::new();
    world.gravity = rm::Vector::new(0.0, 0.0, -9.81);
    world.integration_parameters = IntegrationParameters {
        dt: 1e-3,
        num_solver_iterations: iterations,
        ..IntegrationParameters::default()
    };
    let body = RigidBodyBuilder::dynamic()
        .translation(rm::Vector::new(0.0, 0.0, 1.5))
        .can_sleep(false)
        .build();
    let body = world.bodies.insert(body);
    let a = 0.5 * std::f64::consts::SQRT_2 / 2.0;
    for p in [[a, a], [a, -a], [-a, -a], [-a, a], [0.0, 0.0]] {
        let ball = ColliderBuilder::ball(0.05)
            .translation(rm::Vector::new(p[0], p[1], 0.0))
            .density(if p == [0.0, 0.0] { 0.0 } else { 1000.0 });
        world.insert_collider(ball, Some(body));
    }
    world.insert_collider(
        ColliderBuilder::cuboid(1000.0, 1000.0, 0.5).translation(rm::Vector::new(0.0, 0.0, -0.55)),
        None,
    );
    let rb = &mut world.bodies[body];
    let hover = rb.mass() * 9.81;
    rb.add_force(rm::Vector::new(0.0, 0.0, hover), true);
    world
}

const STEPS: usize = 16_000;

fn speed(c: &mut Criterion) {
    let scenario = Scenario::builtin("paper-tilt").expect("built-in scenario");
    let mut coarse = scenario.clone();
    coarse.physics.dt = 0.002;
    coarse.validate().expect("coarse-step scenario");
    let dir = std::env::temp_dir().join(format!("tvmd-sim-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temporary directory");
    let log = dir.join("paper-tilt.mcap");
    let flight = |s: &RunSpec| {
        let f = fly(s, None, None).expect("paper-tilt flight");
        assert!(f.error.is_none(), "{:?}", f.error);
        std::hint::black_box(f.result.summary);
    };
    let logged = spec(&scenario, Some(log.clone()));
    let bare = spec(&scenario, None);
    let coarse_spec = spec(&coarse, None);
    let with_log = time_flights(c, "paper_tilt_16s_with_mcap_log", || flight(&logged));
    let no_log = time_flights(c, "paper_tilt_16s_no_log", || flight(&bare));
    let coarse_t = time_flights(c, "paper_tilt_16s_no_log_dt_2ms", || flight(&coarse_spec));

    let cores = worker_count(None, usize::MAX);
    let batch: Vec<RunSpec> = (0..4 * cores).map(|_| bare.clone()).collect();
    let batch_t = time_flights(c, "paper_tilt_batch_all_cores", || {
        for outcome in run_many(batch.clone(), None, None) {
            std::hint::black_box(outcome.result.expect("batch flight").summary);
        }
    });

    let mut floors = Vec::new();
    for iterations in [4, 1] {
        let name = format!("bare_rapier_16000_steps_{iterations}_iterations");
        let t = time_flights(c, &name, || {
            let mut world = bare_world(iterations);
            for _ in 0..STEPS {
                world.step();
            }
            std::hint::black_box(&world.bodies);
        });
        floors.push((iterations, t));
    }

    // The simulator's own world (one body, the compound collider, gyroscopic terms, a wrench
    // applied every step) hovering in the air, and resting on the ground: the physics part of a
    // flight without the controller and the loop.
    let team = scenario.team_body().expect("paper-tilt team");
    let hover = vec![Vector3::new(0.0, 0.0, team.mass() * GRAVITY / team.len() as f64); 4];
    let mut own = Vec::new();
    for (name, z, forces) in [
        ("hovering", 1.5, hover),
        ("resting_on_the_ground", 0.0, vec![Vector3::zeros(); 4]),
    ] {
        let t = time_flights(c, &format!("tvmd_world_16000_steps_{name}"), || {
            let at = PlantState::at_rest(Vector3::new(0.0, 0.0, z));
            let mut world = TvmdWorld::new(&team, &scenario.physics, &at).expect("world");
            let extra = ExtraWrench::default();
            for _ in 0..STEPS {
                world.step(&forces, &extra).expect("step");
            }
            std::hint::black_box(world.state());
        });
        own.push((name, t));
    }

    let d = scenario.duration;
    println!(
        "paper-tilt with MCAP log: median {with_log:.4} s per 16 s flight => RTF = {:.0}x (MCAP {} \
         bytes)",
        d / with_log,
        std::fs::metadata(&log).map(|m| m.len()).unwrap_or(0)
    );
    println!(
        "paper-tilt without log:   median {no_log:.4} s => RTF = {:.0}x",
        d / no_log
    );
    println!(
        "paper-tilt, dt = 2 ms, without log: median {coarse_t:.4} s => RTF = {:.0}x",
        d / coarse_t
    );
    println!(
        "batch of {} flights without log on {cores} workers: median {batch_t:.3} s => {:.1} \
         flights/s, {:.0}x real time in all",
        batch.len(),
        batch.len() as f64 / batch_t,
        batch.len() as f64 * d / batch_t
    );
    for (iterations, t) in floors {
        println!(
            "bare rapier world, {iterations} solver iteration(s): {:.2} us per 1 ms step => {:.0}x \
             real time at most",
            t / STEPS as f64 * 1e6,
            1e-3 * STEPS as f64 / t
        );
    }
    for (name, t) in own {
        println!(
            "tvmd-sim world {}: {:.2} us per 1 ms step",
            name.replace('_', " "),
            t / STEPS as f64 * 1e6
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

criterion_group!(benches, speed);
criterion_main!(benches);
