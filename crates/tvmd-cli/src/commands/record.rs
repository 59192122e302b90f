//! `tvmd-sim record-cycles`.

use std::path::Path;

use tvmd_log::paths::{check_outputs, write_file};
use tvmd_scenario::{Overrides, Scenario};
use tvmd_sim::runner::*;

use crate::error::CliError;

pub fn cmd_record_cycles(
    scenario_arg: &str,
    out: &Path,
    cycles: usize,
    allocator: Option<String>,
) -> Result<(), CliError> {
    let scenario = Scenario::load(scenario_arg)?.with_overrides(&Overrides {
        allocator,
        ..Overrides::default()
    })?;
    let input = Path::new(scenario_arg);
    let inputs: Vec<(String, &Path)> = if input.is_file() {
        vec![("scenario file".into(), input)]
    } else {
        Vec::new()
    };
    check_outputs(&[("the recording (--out)".into(), out)], &inputs)?;
    let recording = record_cycles(&scenario, cycles)?;
    let bytes = recording.to_bytes();
    write_file(out, "write the recording", &bytes)?;
    println!(
        "recorded {cycles} f32 control cycles of {} ({} agents, {} bytes): {}",
        scenario.name,
        recording.config.n,
        bytes.len(),
        out.display()
    );
    Ok(())
}
