//! `tvmd-sim record-cycles`.

use std::path::Path;

use tvmd_scenario::{Overrides, Scenario};
use tvmd_sim::runner::*;

use crate::error::CliError;

pub fn cmd_record_cycles(
    scenario: &str,
    out: &Path,
    cycles: usize,
    allocator: Option<String>,
) -> Result<(), CliError> {
    let scenario = Scenario::load(scenario)?.with_overrides(&Overrides {
        allocator,
        ..Overrides::default()
    })?;
    let recording = record_cycles(&scenario, cycles)?;
    if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)?;
    }
    let bytes = recording.to_bytes();
    std::fs::write(out, &bytes)?;
    println!(
        "recorded {cycles} f32 control cycles of {} ({} agents, {} bytes): {}",
        scenario.name,
        recording.config.n,
        bytes.len(),
        out.display()
    );
    Ok(())
}
