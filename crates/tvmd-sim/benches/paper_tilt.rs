//! Real-time factor of the simulator: one full 16 s `paper-tilt` run (rapier at 1 kHz, the tvmd
//! controller at 100 Hz, MCAP log written to a temporary directory) per iteration.
//!
//! `cargo bench -p tvmd-sim --bench paper_tilt`; after criterion's report it prints
//! `RTF = 16 s / median run time`.

use std::cell::RefCell;
use std::time::{Duration, Instant};

use criterion::{criterion_group, criterion_main, Criterion};
use tvmd_sim::runner::run_scenario;
use tvmd_sim::scenario::Scenario;

fn paper_tilt(c: &mut Criterion) {
    let scenario = Scenario::builtin("paper-tilt").expect("built-in scenario");
    let dir = std::env::temp_dir().join(format!("tvmd-sim-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temporary directory");
    let log = dir.join("paper-tilt.mcap");
    let runs = RefCell::new(Vec::new());
    let mut group = c.benchmark_group("simulator");
    group
        .sample_size(10)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(12));
    group.bench_function("paper_tilt_16s_with_mcap_log", |b| {
        b.iter_custom(|iters| {
            let mut total = Duration::ZERO;
            for _ in 0..iters {
                let t0 = Instant::now();
                let r = run_scenario(&scenario, Some(&log), None).expect("paper-tilt run");
                let dt = t0.elapsed();
                std::hint::black_box(&r.summary);
                runs.borrow_mut().push(dt.as_secs_f64());
                total += dt;
            }
            total
        });
    });
    group.finish();
    let mut times = runs.into_inner();
    times.sort_by(f64::total_cmp);
    if !times.is_empty() {
        let median = times[times.len() / 2];
        println!(
            "paper-tilt: {} runs, median {:.4} s per 16 s run => RTF = {:.1}x real time \
             (MCAP {} bytes)",
            times.len(),
            median,
            scenario.duration / median,
            std::fs::metadata(&log).map(|m| m.len()).unwrap_or(0)
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

criterion_group!(benches, paper_tilt);
criterion_main!(benches);
