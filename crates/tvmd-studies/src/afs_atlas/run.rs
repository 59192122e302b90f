//! `tvmd-sim afs TEAM`: the atlas of one catalogue team (or `all`), as a table, JSON and PNG
//! cross-sections. The binary only parses these arguments and prints what [`run`] returns.

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};

use tvmd_log::paths;

use tvmd_core::presets::Preset;
use tvmd_core::TeamConfig;

use super::certify::HeightRange;
use super::plot::cross_sections;
use super::report::{atlas_entry_until, markdown_table, AtlasRow, AtlasSettings};
use crate::StudyError;

/// Arguments of `tvmd-sim afs`.
#[derive(Debug, Clone)]
pub struct AtlasRequest {
    /// A catalogue team (`a3-con` .. `a10-inc`, `t10-con`, `t10-inc`, `a4-diamond-inc`, ...)
    /// or `all`.
    pub team: String,
    /// Failed agents (0-based), comma-separated.
    pub failed: Vec<usize>,
    /// Also every one-agent failure of each team.
    pub each_failure: bool,
    /// Comparison heights in multiples of m_C g, comma-separated.
    pub heights: Vec<f64>,
    /// Directions per cross-section.
    pub directions: usize,
    /// Relaxation s of the compared cone.
    pub relaxation: f64,
    /// Heights of the s* certification grid (from 0.1 to 0.9 of the hover ceiling).
    pub certify_heights: usize,
    /// Torque the agents must hold (N m), `x,y,z`.
    pub torque: Vec<f64>,
    /// Directory for the PNG cross-sections (`<team>[-failed-<i>].png`).
    pub plots: Option<PathBuf>,
    /// Write the rows as JSON here.
    pub json: Option<PathBuf>,
}

/// The teams the arguments name.
pub fn presets(team: &str) -> Result<Vec<Preset>, StudyError> {
    if team == "all" {
        return Ok(Preset::ALL.to_vec());
    }
    Preset::from_name(team).map(|p| vec![p]).ok_or_else(|| {
        let known: Vec<&str> = Preset::ALL.iter().map(|p| p.name()).collect();
        StudyError::InvalidArgument {
            name: "team".into(),
            reason: format!("unknown team `{team}` (known: all, {})", known.join(", ")),
        }
    })
}

/// Computes every row the arguments ask for, writes the plots and JSON, and returns the rows
/// and the Markdown table.
pub fn run(args: &AtlasRequest) -> Result<(Vec<AtlasRow>, String), StudyError> {
    run_until(args, None)
}

/// [`run`], stopping within one ray once `cancel` is set ([`StudyError::Interrupted`]; no
/// file is written then). The outputs (`plots`, `json`) are checked before any work.
pub fn run_until(
    args: &AtlasRequest,
    cancel: Option<&AtomicBool>,
) -> Result<(Vec<AtlasRow>, String), StudyError> {
    let settings = AtlasSettings {
        heights: args.heights.clone(),
        directions: args.directions,
        relaxation: args.relaxation,
        range: HeightRange {
            heights: args.certify_heights,
            ..HeightRange::default()
        },
        torque: <[f64; 3]>::try_from(args.torque.as_slice()).map_err(|_| {
            StudyError::InvalidArgument {
                name: "torque".into(),
                reason: format!("needs three values x,y,z, got {:?}", args.torque),
            }
        })?,
    };
    if let Some(dir) = &args.plots {
        paths::check_output_dir(dir, "the figure directory (--plots)")?;
    }
    if let Some(path) = &args.json {
        paths::check_outputs(&[("the JSON table (--json)".into(), path)], &[])?;
    }
    let mut jobs = Vec::new();
    for preset in presets(&args.team)? {
        let team: TeamConfig<f64, 16> = preset
            .team()
            .map_err(|e| StudyError::invalid_team(e.to_string()))?;
        jobs.push((preset, team, args.failed.clone(), false));
        if args.each_failure {
            jobs.extend((0..team.len()).map(|i| (preset, team, vec![i], true)));
        }
    }
    let job =
        |(preset, team, failed, optional): &(Preset, TeamConfig<f64, 16>, Vec<usize>, bool)| {
            let entry = match atlas_entry_until(preset.name(), team, failed, &settings, cancel) {
                Ok(entry) => entry,
                Err(e @ StudyError::Interrupted(_)) => return Err(e),
                // A one-agent failure the team cannot survive is a row of the table, not an error
                // of the whole run.
                Err(e) if *optional => {
                    return Ok(AtlasRow::unavailable(preset.name(), failed, e.to_string()))
                }
                Err(e) => return Err(e),
            };
            if let Some(dir) = &args.plots {
                let suffix: String = failed.iter().map(|i| format!("-failed-{i}")).collect();
                let path = dir.join(format!("{}{suffix}.png", preset.name()));
                cross_sections(&entry, args.relaxation, &path)?;
            }
            Ok(entry.row)
        };
    // Rows are independent: spread them over the cores, keeping their order.
    let workers = tvmd_sim::pool::worker_count(None, jobs.len());
    let rows = tvmd_sim::pool::map_in_order(&jobs, workers, |_, spec| job(spec))
        .into_iter()
        .map(|r| r.unwrap_or_else(|| Err(StudyError::Internal("an atlas worker panicked".into()))))
        .collect::<Result<Vec<AtlasRow>, StudyError>>()?;
    if cancel.is_some_and(|c| c.load(Ordering::Relaxed)) {
        return Err(StudyError::Interrupted(
            "the atlas was stopped before every row was computed; nothing was written".into(),
        ));
    }
    if let Some(path) = &args.json {
        let text = serde_json::to_string_pretty(&rows)?;
        paths::write_file(path, "write the atlas JSON", text.as_bytes())?;
    }
    let table = markdown_table(&rows);
    Ok((rows, table))
}
