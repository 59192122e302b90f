//! `tvmd-sim plot`: figures from MCAP logs.

use std::path::{Path, PathBuf};

use tvmd_studies::plot::{self, PlotSeries};

use crate::error::CliError;

pub fn cmd_plot(logs: &[PathBuf], out: &Path) -> Result<(), CliError> {
    // Every log is read before the figure directory is made: a missing or unreadable log
    // leaves nothing behind.
    let all = logs
        .iter()
        .map(PlotSeries::from_mcap_file)
        .collect::<Result<Vec<_>, _>>()?;
    // The rule of every output ([`tvmd_log::paths`]): checked before any figure is drawn.
    tvmd_log::paths::check_output_dir(out, "the figure directory (--out)")?;
    for (path, series) in logs.iter().zip(&all) {
        let stem = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| series.label.clone());
        for p in plot::write_run_figures(series, out, &stem)? {
            println!("figure:   {}", p.display());
        }
    }
    if all.len() > 1 {
        let path = out.join("relaxation.png");
        plot::relaxation_study(&all, &path)?;
        println!("figure:   {}", path.display());
    }
    Ok(())
}
