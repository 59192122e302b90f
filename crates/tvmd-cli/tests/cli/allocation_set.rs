//! The committed allocation benchmark set (`benches/data/allocation_set.json`) is what the
//! seeded generator writes; its attainable requests are `u = M f` with admissible `f`, its
//! outside requests satisfy their certificates; and the evaluation on it reports admissible
//! forces, the exact allocators exact, and no allocator beating a certificate.

use tvmd_core::allocation::AllocatorOptions;
use tvmd_core::nalgebra::{Vector3, Vector6};
use tvmd_core::presets::GRAVITY;
use tvmd_core::{
    AdmissibleSet, AllocationRequest, Allocator, AnyAllocator, GimbalCommand, TeamConfig,
};
use tvmd_studies::allocation_bench::{
    evaluate_requests, failure_mask, team, AllocationSet, Certificate, SetRequest, TeamRequests,
    SEED,
};

const COMMITTED: &str = include_str!("../../../../benches/data/allocation_set.json");

fn committed() -> AllocationSet {
    AllocationSet::from_json(COMMITTED).unwrap()
}

#[test]
fn committed_set_is_current() {
    let fresh = AllocationSet::generate(SEED).unwrap();
    assert!(
        fresh.to_json().unwrap() == COMMITTED,
        "benches/data/allocation_set.json is stale: regenerate it with `cargo run -p tvmd-sim \
         -- allocation-set` from the workspace root"
    );
    assert_eq!(committed(), fresh);
    // Another seed draws other requests.
    assert_ne!(AllocationSet::generate(SEED + 1).unwrap(), fresh);
}

#[test]
fn requests_are_attainable_by_construction_or_certified_outside() {
    let set = committed();
    let labels: Vec<String> = set.teams.iter().map(TeamRequests::label).collect();
    assert_eq!(
        labels,
        [
            "A4-Inc",
            "A6-Inc",
            "A8-Inc",
            "ring-16-Inc",
            "A4-Inc, agent 1 failed"
        ]
    );
    for tr in &set.teams {
        let t: TeamConfig<f64, 16> = team(&tr.team).unwrap();
        let mask = failure_mask(&t, &tr.failed).unwrap();
        let m = t.effectiveness(&mask);
        let set = AdmissibleSet::from_limits(t.limits());
        let (mut bound_hits, mut outside) = (0, 0);
        for r in &tr.requests {
            let u = Vector6::from_column_slice(&r.wrench);
            if let Some(forces) = &r.forces {
                assert_eq!(forces.len(), t.len());
                let mut f = [Vector3::zeros(); 16];
                for (i, (slot, g)) in f.iter_mut().zip(forces).enumerate() {
                    *slot = Vector3::from_column_slice(g);
                    let cmd = GimbalCommand::from_force(slot);
                    if mask.is_failed(i) {
                        assert_eq!(*slot, Vector3::zeros());
                    } else {
                        assert!(set.contains(&cmd, 1e-12), "{}: {cmd:?}", r.kind);
                        bound_hits += usize::from(!set.contains(&cmd, -1e-9));
                    }
                }
                assert!((m.wrench(&f) - u).norm() <= 1e-12 * u.norm(), "{}", r.kind);
            } else {
                outside += 1;
                let n = t.working(&mask).count() as f64;
                let lever: f64 = t.working(&mask).map(|(_, a)| a.position.norm()).sum();
                let sigma = t.limits().max_thrust();
                let (value, bound) = match r.certificate.unwrap() {
                    Certificate::ForceNorm => (u.fixed_rows::<3>(3).norm(), n * sigma),
                    Certificate::TorqueNorm => (u.fixed_rows::<3>(0).norm(), sigma * lever),
                    Certificate::Downward => (-u[5], 0.0),
                };
                assert_eq!(r.bound, Some(bound));
                assert!(
                    value > bound * 1.04 || (bound == 0.0 && value > 0.0),
                    "{r:?}"
                );
            }
        }
        // Boundary forces are part of the set, and every certificate is used.
        assert!(bound_hits > tr.requests.len(), "{}", tr.label());
        assert_eq!(outside, 12);
    }
}

/// The requests of `kind` of the team at `index`.
fn slice(set: &AllocationSet, index: usize, kind: &str) -> (TeamRequests, Vec<SetRequest>) {
    let tr = set.teams[index].clone();
    let requests = tr
        .requests
        .iter()
        .filter(|r| r.kind == kind)
        .cloned()
        .collect();
    (tr, requests)
}

#[test]
fn evaluation_reports_admissible_forces_and_exact_interior_allocations() {
    let set = committed();
    for index in [0, 2] {
        let (tr, interior) = slice(&set, index, "interior");
        for name in AnyAllocator::<f64, 4>::NAMES {
            let row = evaluate_requests(&tr, &interior, name).unwrap();
            assert_eq!((row.attainable, row.inadmissible), (16, 0), "{name}");
        }
        // The exact-boundary allocator reproduces every interior request; the redistribution
        // is exact wherever the plain pseudo-inverse is (it returns the same forces there).
        let exact = evaluate_requests(&tr, &interior, "exact-boundary-redistribution").unwrap();
        assert_eq!(exact.exact_fraction(), 1.0, "{}", tr.label());
        for r in &interior {
            let one = std::slice::from_ref(r);
            let pi = evaluate_requests(&tr, one, "pseudo-inverse").unwrap();
            let rpi = evaluate_requests(&tr, one, "redistributed-pseudo-inverse").unwrap();
            assert!(rpi.exact >= pi.exact);
        }
    }
    // The 16-agent ring: the redistribution is exact on every interior request.
    let (tr, interior) = slice(&set, 3, "interior");
    let rpi = evaluate_requests(&tr, &interior, "redistributed-pseudo-inverse").unwrap();
    assert_eq!(rpi.exact_fraction(), 1.0);
}

#[test]
fn no_allocator_beats_a_certificate() {
    let set = committed();
    let tr = &set.teams[0];
    let t: TeamConfig<f64, 4> = team(&tr.team).unwrap();
    let m = t.effectiveness(&failure_mask(&t, &tr.failed).unwrap());
    let sets = [AdmissibleSet::from_limits(t.limits()); 4];
    for name in AnyAllocator::<f64, 4>::NAMES {
        let mut a = AnyAllocator::<f64, 4>::from_name(name, &AllocatorOptions::default()).unwrap();
        a.configure(&m);
        for r in tr.requests.iter().filter(|r| !r.attainable()) {
            let u = Vector6::from_column_slice(&r.wrench);
            a.reset();
            let out = a.allocate(&AllocationRequest {
                effectiveness: &m,
                sets: &sets,
                wrench: u,
            });
            let bound = r.bound.unwrap();
            // What no admissible f can avoid, from the certificate.
            let floor = match r.certificate.unwrap() {
                Certificate::ForceNorm => u.fixed_rows::<3>(3).norm() - bound,
                Certificate::TorqueNorm => u.fixed_rows::<3>(0).norm() - bound,
                Certificate::Downward => -u[5],
            };
            assert!(out.wrench_error >= floor * (1.0 - 1e-12), "{name}: {r:?}");
            if r.certificate != Some(Certificate::TorqueNorm) {
                assert!(out.e_f >= floor * (1.0 - 1e-12), "{name}: {r:?}");
            }
            assert!(out.e_f.is_finite() && out.e_f < 10.0 * t.mass() * GRAVITY);
        }
    }
}

#[test]
fn cli_writes_the_set_and_prints_the_tables() {
    let dir = std::env::temp_dir().join(format!("tvmd-alloc-set-{}", std::process::id()));
    let set = dir.join("set.json");
    let bin = || std::process::Command::new(env!("CARGO_BIN_EXE_tvmd-sim"));
    let out = bin()
        .args(["allocation-set", "--out"])
        .arg(&set)
        .output()
        .unwrap();
    assert!(out.status.success(), "{out:?}");
    assert!(std::fs::read_to_string(&set).unwrap() == COMMITTED);
    let json = dir.join("rows.json");
    let out = bin()
        .args([
            "allocation-eval",
            "--allocators",
            "pseudo-inverse,redistributed-pseudo-inverse",
        ])
        .arg("--set")
        .arg(&set)
        .arg("--json")
        .arg(&json)
        .output()
        .unwrap();
    let table = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{out:?}");
    assert_eq!(
        table.matches("| pseudo-inverse |").count(),
        2 * 5,
        "{table}"
    );
    let rows: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(rows["set"].as_array().unwrap().len(), 10);
    assert!(rows["closed_loop"].is_null());
    let out = bin()
        .args(["allocation-eval", "--allocators", "magic", "--set"])
        .arg(&set)
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("magic"));
    std::fs::remove_dir_all(&dir).unwrap();
}
