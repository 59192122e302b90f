//! Turns `crates/tvmd-core/tests/data/core_vectors.json` into Rust statics for the firmware:
//! the inputs, the file's f64 outputs, and the host's f32 outputs of the very same case code
//! (`src/cases.rs`, run here on the host with std's libm).

use std::fmt::Write as _;
use std::path::PathBuf;

use serde_json::Value;

#[allow(dead_code)]
#[path = "src/cases.rs"]
mod cases;

use cases::{Family, MAX_OUTPUTS};

#[path = "build_allocation_set.rs"]
mod allocation_set;

fn nums(v: &Value) -> Vec<f64> {
    match v {
        Value::Number(n) => vec![n.as_f64().expect("number")],
        Value::Array(a) => a.iter().flat_map(nums).collect(),
        other => panic!("expected numbers, got {other}"),
    }
}

fn get(c: &Value, keys: &[&str]) -> Vec<f64> {
    keys.iter()
        .flat_map(|k| nums(c.get(*k).unwrap_or_else(|| panic!("missing key {k}"))))
        .collect()
}

/// `n_x`: agents whose `psi_quarter_turns` is even.
fn n_x(c: &Value) -> f64 {
    get(c, &["psi_quarter_turns"])
        .iter()
        .filter(|m| (**m as i64).rem_euclid(2) == 0)
        .count() as f64
}

/// Flattened inputs, expected outputs and their groups of one case (layouts in `cases::run`).
fn flatten(family: Family, c: &Value) -> (Vec<f64>, Vec<f64>, Vec<(usize, bool)>) {
    match family {
        Family::Gimbal => (
            get(c, &["eta_x", "eta_y", "thrust", "force"]),
            get(c, &["force", "inv_thrust", "inv_eta_x", "inv_eta_y"]),
            vec![(3, false), (3, false)],
        ),
        Family::Effectiveness => {
            let turns = get(c, &["psi_quarter_turns"]);
            let mut x = vec![turns.len() as f64];
            x.extend(get(c, &["positions", "psi_quarter_turns", "f"]));
            (x, get(c, &["wrench"]), vec![(6, false)])
        }
        Family::AfsSemiAxes => (
            get(
                c,
                &["n", "n_x", "sigma_x", "sigma_y", "max_thrust", "z", "s"],
            ),
            get(c, &["c_x", "c_y"]),
            vec![(2, false)],
        ),
        Family::ForceProjection => {
            let mut x = get(c, &["n"]);
            x.push(n_x(c));
            x.extend(get(c, &["sigma_x", "sigma_y", "max_thrust", "u"]));
            (x, get(c, &["u_projected"]), vec![(3, false)])
        }
        Family::AttitudePlanner => {
            let mut x = get(c, &["n"]);
            x.push(n_x(c));
            x.extend(get(
                c,
                &["sigma_x", "sigma_y", "max_thrust", "s", "R_r", "f_r"],
            ));
            let theta = get(c, &["theta"]);
            let planned = if theta == [0.0] { 0.0 } else { 1.0 };
            let mut want = theta;
            want.extend(get(c, &["R_d"]));
            want.push(planned);
            (x, want, vec![(1, true), (9, false), (1, true)])
        }
        Family::ControlCycle => (get(c, &["x"]), vec![], vec![]),
    }
}

/// Appends one `Case` per entry of `list`, with the host's f32 outputs.
fn emit(src: &mut String, key: &str, family: Family, list: &[Value]) {
    for (i, c) in list.iter().enumerate() {
        let (x, want, groups) = flatten(family, c);
        let mut out = [0.0f32; MAX_OUTPUTS];
        let k = cases::run(family, &x, &mut out)
            .unwrap_or_else(|e| panic!("host run of {key}[{i}]: {e}"));
        let host: Vec<String> = out[..k]
            .iter()
            .map(|o| format!("{:#010x}", o.to_bits()))
            .collect();
        let f = |a: &[f64]| {
            a.iter()
                .map(|x| format!("{x:?}"))
                .collect::<Vec<_>>()
                .join(", ")
        };
        writeln!(
            src,
            "    Case {{ name: \"{key}[{i}]\", family: Family::{family:?}, input: &[{}], \
                 expected: &[{}], groups: &{groups:?}, host: &[{}] }},",
            f(&x),
            f(&want),
            host.join(", ")
        )
        .unwrap();
    }
}

fn main() {
    let manifest = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").unwrap());
    let path = manifest.join("../../crates/tvmd-core/tests/data/core_vectors.json");
    println!("cargo:rerun-if-changed={}", path.display());
    println!("cargo:rerun-if-changed=src/cases.rs");
    println!("cargo:rerun-if-changed=memory.x");
    let text = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
    let v: Value = serde_json::from_str(&text).expect("core_vectors.json is not valid JSON");

    let families = [
        ("gimbal", Family::Gimbal),
        ("effectiveness", Family::Effectiveness),
        ("afs_semi_axes", Family::AfsSemiAxes),
        ("force_projection", Family::ForceProjection),
        ("attitude_planner", Family::AttitudePlanner),
    ];
    let mut src = String::from("pub static CASES: &[Case] = &[\n");
    for (key, family) in families {
        let list = v[key]
            .as_array()
            .unwrap_or_else(|| panic!("missing family {key}"));
        emit(&mut src, key, family, list);
    }
    // Control cycles of the paper's team (not in the vectors file): hover at the reference, an
    // offset, a moving team, and roll references from feasible to planner-saturated (bisecting).
    let mut cycles = Vec::new();
    for (p, w, vel, roll, ref_roll) in [
        ([0.0, 0.0, 1.0], [0.0; 3], [0.0; 3], 0.0, 0.0),
        ([0.3, -0.2, 0.8], [0.0; 3], [0.0; 3], 0.0, 0.0),
        (
            [0.0, 0.0, 1.0],
            [0.1, -0.2, 0.05],
            [0.2, 0.1, -0.3],
            0.05,
            0.0,
        ),
        ([0.0, 0.0, 1.0], [0.0; 3], [0.0; 3], 0.0, 0.2),
        ([0.0, 0.0, 1.0], [0.0; 3], [0.0; 3], 0.0, 0.5),
        ([0.0, 0.0, 1.0], [0.0; 3], [0.0; 3], 0.3, 0.8),
        (
            [0.1, 0.1, 1.2],
            [0.3, 0.0, -0.1],
            [0.5, 0.0, 0.0],
            -0.2,
            1.2,
        ),
    ] {
        let mut x: Vec<f64> = Vec::new();
        x.extend(p);
        x.extend(w);
        x.extend(vel);
        x.push(roll);
        x.extend([0.0, 0.0, 1.0, 0.0, 0.0, 0.0, ref_roll]);
        cycles.push(serde_json::json!({ "x": x }));
    }
    emit(&mut src, "control_cycle", Family::ControlCycle, &cycles);
    src.push_str("];\n");
    let out_dir = PathBuf::from(std::env::var("OUT_DIR").unwrap());
    std::fs::write(out_dir.join("vectors.rs"), src).unwrap();
    allocation_set::write(&manifest, &out_dir);
    // cortex-m-rt's link.x includes memory.x from the linker search path.
    std::fs::copy(manifest.join("memory.x"), out_dir.join("memory.x")).unwrap();
    println!("cargo:rustc-link-search={}", out_dir.display());
    // cortex-m-rt's linker script (vector table, sections); here rather than in
    // .cargo/config.toml, which cargo reads only when run from this directory.
    println!("cargo:rustc-link-arg-bins=-Tlink.x");
}
