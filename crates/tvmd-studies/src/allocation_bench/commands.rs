//! The `tvmd-sim allocation-set` and `allocation-eval` commands (kept here so `main.rs` only
//! parses their arguments).

use std::path::Path;

use tvmd_core::AnyAllocator;

use super::{
    closed_loop_rows, evaluate_set, markdown_by_kind, markdown_closed_loop, markdown_table,
    AllocationSet, EvaluationRow,
};
use crate::StudyError;

/// Writes the set drawn with `seed` to `out`; returns a one-line description.
pub fn write_set(out: &Path, seed: u64) -> Result<String, StudyError> {
    let set = AllocationSet::generate(seed)?;
    if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)?;
    }
    std::fs::write(out, set.to_json()?)?;
    let requests: usize = set.teams.iter().map(|t| t.requests.len()).sum();
    Ok(format!(
        "allocation set (seed {seed}): {} teams, {requests} requests: {}",
        set.teams.len(),
        out.display()
    ))
}

/// Every allocator of this build (`AnyAllocator::NAMES`, so allocators added to the name table
/// are picked up without edits), or the given ones.
pub fn allocator_names(given: &[String]) -> Vec<String> {
    if given.is_empty() {
        AnyAllocator::<f64, 4>::NAMES
            .iter()
            .map(|s| (*s).to_string())
            .collect()
    } else {
        given.to_vec()
    }
}

/// Evaluates `allocators` on the set at `set_path` and, with `closed_loop`, flies paper-tilt at
/// `s = 1` with each; returns the markdown tables (and writes the rows as JSON to `json`).
pub fn evaluate_file(
    set_path: &Path,
    allocators: &[String],
    closed_loop: bool,
    json: Option<&Path>,
) -> Result<String, StudyError> {
    let set = AllocationSet::from_json(&std::fs::read_to_string(set_path)?)?;
    let names: Vec<&str> = allocators.iter().map(String::as_str).collect();
    let rows: Vec<EvaluationRow> = evaluate_set(&set, &names)?;
    let mut out = format!(
        "Allocation set {} (seed {}); exact: e_f / |u_fd| <= 1e-9\n\n{}",
        set_path.display(),
        set.seed,
        markdown_table(&rows)
    );
    out += "\nExact (e_f) by kind of attainable request\n\n";
    out += &markdown_by_kind(&rows);
    let closed = if closed_loop {
        let c = closed_loop_rows(&names)?;
        out += "\npaper-tilt, s = 1, f64 controller\n\n";
        out += &markdown_closed_loop(&c);
        Some(c)
    } else {
        None
    };
    if let Some(p) = json {
        let value = serde_json::json!({ "set": rows, "closed_loop": closed });
        std::fs::write(p, serde_json::to_string_pretty(&value)? + "\n")?;
    }
    Ok(out)
}
