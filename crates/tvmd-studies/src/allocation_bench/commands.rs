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
    tvmd_log::paths::check_outputs(&[("the allocation set (--out)".into(), out)], &[])?;
    let set = AllocationSet::generate(seed)?;
    tvmd_log::paths::write_file(out, "write the allocation set", set.to_json()?.as_bytes())?;
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
    if let Some(p) = json {
        let inputs = [("the allocation set (--set)".to_string(), set_path)];
        tvmd_log::paths::check_outputs(&[("the JSON table (--json)".into(), p)], &inputs)?;
    }
    let text = std::fs::read_to_string(set_path)
        .map_err(StudyError::file("read the allocation set", set_path))?;
    let set = AllocationSet::from_json(&text)?;
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
        let text = serde_json::to_string_pretty(&value)? + "\n";
        tvmd_log::paths::write_file(p, "write the JSON table", text.as_bytes())?;
    }
    Ok(out)
}
