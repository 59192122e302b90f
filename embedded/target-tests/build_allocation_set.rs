//! The allocation benchmark set (`benches/data/allocation_set.json`, issue 16) as f32 statics
//! for the cost firmware, with the host's f32 forces of the default allocator
//! (`ExactBoundaryRedistribution`, a reset allocator per request, as `allocation-eval` runs it)
//! for the comparison on the target.

use std::fmt::Write as _;
use std::path::Path;

use nalgebra::Vector6;
use serde_json::Value;
use tvmd_core::team::presets;
use tvmd_core::{
    AdmissibleSet, AllocationRequest, Allocator, ExactBoundaryRedistribution, FailureMask,
    TeamConfig,
};

/// The ring's radius of the set (`tvmd_studies::allocation_bench::RING16_RADIUS`).
const RING16_RADIUS: f32 = 1.8;

fn team<const N: usize>(name: &str) -> TeamConfig<f32, N> {
    match name {
        "a4_inc" => presets::a4_inc(),
        "a6_inc" => presets::a6_inc(),
        "a8_inc" => presets::a8_inc(),
        "ring16_inc" => presets::ring(16, RING16_RADIUS, true, presets::paper_limits()),
        other => panic!("unknown team {other}"),
    }
    .unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// `pub static <ID>: SetTeam<N>` for one team of the set.
fn emit<const N: usize>(src: &mut String, t: &Value) {
    let name = t["team"].as_str().expect("team");
    let failed: Vec<usize> = t["failed"]
        .as_array()
        .expect("failed")
        .iter()
        .map(|i| i.as_u64().expect("index") as usize)
        .collect();
    let config = team::<N>(name);
    let mask = FailureMask::with_failed(&failed).expect("failure mask");
    let e = config.effectiveness(&mask);
    let sets = [AdmissibleSet::from_limits(config.limits()); N];
    let mut id = name.to_uppercase();
    for i in &failed {
        write!(id, "_F{i}").unwrap();
    }
    writeln!(
        src,
        "pub static {id}: SetTeam<{N}> = SetTeam {{ name: {:?}, failed: &{failed:?}, requests: &[",
        id.to_lowercase()
    )
    .unwrap();
    for r in t["requests"].as_array().expect("requests") {
        // Attainable and outside requests alike, in the set's order.
        let w: Vec<f32> = r["wrench"]
            .as_array()
            .expect("wrench")
            .iter()
            .map(|x| x.as_f64().expect("number") as f32)
            .collect();
        let wrench = Vector6::from_column_slice(&w);
        let out = ExactBoundaryRedistribution::<f32, N>::new().allocate(&AllocationRequest {
            effectiveness: &e,
            sets: &sets,
            wrench,
        });
        let forces: Vec<[f32; 3]> = out.forces.iter().map(|f| [f.x, f.y, f.z]).collect();
        writeln!(
            src,
            "    SetRequest {{ wrench: {w:?}, host: {forces:?}, host_rounds: {} }},",
            out.rounds
        )
        .unwrap();
    }
    src.push_str("]};\n");
}

/// Writes `allocation_set.rs` into `out_dir`.
pub fn write(manifest: &Path, out_dir: &Path) {
    let path = manifest.join("../../benches/data/allocation_set.json");
    println!("cargo:rerun-if-changed={}", path.display());
    println!("cargo:rerun-if-changed=build_allocation_set.rs");
    let text = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
    let v: Value = serde_json::from_str(&text).expect("allocation_set.json is not valid JSON");
    let mut src = String::new();
    for t in v["teams"].as_array().expect("teams") {
        match t["team"].as_str().expect("team") {
            "a4_inc" => emit::<4>(&mut src, t),
            "a6_inc" => emit::<6>(&mut src, t),
            "a8_inc" => emit::<8>(&mut src, t),
            _ => emit::<16>(&mut src, t),
        }
    }
    std::fs::write(out_dir.join("allocation_set.rs"), src).unwrap();
}
