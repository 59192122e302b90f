//! `tvmd-sim run`.

use std::path::{Path, PathBuf};

use serde::Serialize;
use tvmd_log::paths::{check_output_dir, check_outputs, file_stem, write_file};
use tvmd_log::LiveOptions;
use tvmd_scenario::ScenarioError;
use tvmd_sim::control::hover_roll_limit;
use tvmd_sim::runner::*;
use tvmd_sim::sim::SampleRetention;
use tvmd_sim::{RunRequest, ScenarioSource, SimError};
use tvmd_studies::plot::{self, PlotSeries};

use crate::error::CliError;

use super::report::print_run;
use super::report::RunReport;
use crate::interrupt::{catch_interrupts, INTERRUPT};
use crate::progress::{progress_bar, ticks_of};

pub struct RunArgs {
    pub(crate) scenario: String,
    pub(crate) out: Option<PathBuf>,
    pub(crate) no_log: bool,
    pub(crate) plots: Option<PathBuf>,
    pub(crate) summary: Option<PathBuf>,
    pub(crate) relaxation: Option<f64>,
    pub(crate) allocator: Option<String>,
    pub(crate) null_space: Option<tvmd_scenario::NullSpaceConfig>,
    pub(crate) team: Option<String>,
    pub(crate) law: Option<String>,
    pub(crate) detect: Option<String>,
    pub(crate) reports: Option<String>,
    pub(crate) precision: Option<String>,
    pub(crate) pil: Option<String>,
    pub(crate) live: Option<LiveOptions>,
}

/// `--detect` refused for a law without the disturbance observer (a paper-law scenario, or
/// `--law paper`): the message says which law to fly.
fn detect_hint(e: SimError, law_given: bool) -> SimError {
    match e {
        SimError::Scenario(ScenarioError::InvalidScenario { field, reason })
            if field == "fault_detection" =>
        {
            let hint = if law_given {
                "--detect flies with `--law offset-free` only"
            } else {
                "this scenario flies a law without it: add `--law offset-free` to --detect"
            };
            SimError::invalid_field(field, format!("{reason}; {hint}"))
        }
        other => other,
    }
}

pub fn cmd_run(a: RunArgs) -> Result<(), CliError> {
    // The one run request of the command line and Python: parses the options (errors name
    // them), loads the scenario, applies the overrides and validates.
    let request = RunRequest {
        scenario: ScenarioSource::NameOrFile(a.scenario.clone()),
        relaxation: a.relaxation,
        allocator: a.allocator,
        null_space: a.null_space,
        team: a.team,
        law: a.law.as_deref().map(RunRequest::parse_law).transpose()?,
        fault_detection: a
            .detect
            .as_deref()
            .map(RunRequest::parse_fault_detection)
            .transpose()?,
        reports: a
            .reports
            .as_deref()
            .map(RunRequest::parse_reports)
            .transpose()?,
        samples: plot_retention(a.plots.is_some()),
        ..RunRequest::default()
    }
    .with_strings(a.precision.as_deref(), a.pil.as_deref(), None)?;
    let mut spec = request.spec().map_err(|e| match &a.detect {
        Some(_) => detect_hint(e, a.law.is_some()),
        None => e,
    })?;
    let stem = file_stem(&spec.scenario.name);
    let log = if a.no_log {
        None
    } else {
        Some(
            a.out
                .unwrap_or_else(|| PathBuf::from(format!("out/{stem}.mcap"))),
        )
    };
    let summary_path = a
        .summary
        .or_else(|| log.as_ref().map(|l| l.with_extension("summary.json")));
    // Every output is checked, and its directory made, before the run starts.
    let mut outputs: Vec<(String, &Path)> = Vec::new();
    if let Some(l) = &log {
        outputs.push(("the log (--out)".into(), l));
    }
    if let Some(p) = &summary_path {
        outputs.push(("the summary (--summary)".into(), p));
    }
    let inputs: Vec<(String, &Path)> = request
        .input()
        .map(|p| ("scenario file".to_string(), p))
        .into_iter()
        .collect();
    check_outputs(&outputs, &inputs)?;
    if let Some(dir) = &a.plots {
        check_output_dir(dir, "the figure directory (--plots)")?;
    }
    // Memory stays flat: the summary folds every tick, the log streams it, and only the
    // figures need samples (a bounded, evenly spaced set).
    spec.log.clone_from(&log);
    let scenario = &spec.scenario;
    catch_interrupts();
    let bar = progress_bar(ticks_of(scenario), &scenario.name);
    let mut tick = |_t: f64| bar.inc(1);
    let mut on_listen = |address: std::net::SocketAddr| {
        bar.suspend(|| {
            println!("live:     ws://{address} (Foxglove: Open connection -> Foxglove WebSocket)");
        });
    };
    let live = a.live.map(|options| LiveView {
        options,
        on_listen: &mut on_listen,
    });
    let flight = fly_live(&spec, live, Some(&mut tick), Some(&INTERRUPT));
    bar.finish_and_clear();
    let Flight { result, error } = flight?;
    let report = RunReport {
        scenario: &scenario.name,
        relaxation: scenario.relaxation,
        allocator: &scenario.allocator,
        law: scenario.law.name(),
        null_space: scenario.null_space.map(|n| n.to_string()),
        controller_precision: scenario.controller_precision,
        controller_target: &result.summary.controller_target,
        hover_roll_limit: hover_roll_limit(scenario, scenario.relaxation).ok(),
        summary: &result.summary,
        paper: result.paper.clone(),
        log: log.as_ref().map(|p| p.display().to_string()),
    };
    print_run(&report);
    if let Some(p) = &summary_path {
        write_json(p, &report)?;
        println!("summary:  {}", p.display());
    }
    if let Some(l) = &log {
        println!("log:      {} (open in Foxglove)", l.display());
    }
    // A failed flight still leaves its log and a summary of what was simulated.
    if let Some(error) = error {
        return Err(CliError::Sim(error));
    }
    if result.summary.interrupted {
        return Err(CliError::Interrupted(format!(
            "stopped at t = {:.3} s of {} s; the log and summary hold what was simulated",
            result.summary.time, scenario.duration
        )));
    }
    if let Some(dir) = &a.plots {
        let series =
            PlotSeries::from_samples(&scenario.name, Some(scenario.relaxation), &result.samples);
        for p in plot::write_run_figures(&series, dir, &stem)? {
            println!("figure:   {}", p.display());
        }
        print_stride(result.sample_stride);
    }
    Ok(())
}

/// The samples a command-line run keeps: a bounded set for figures, else none.
pub fn plot_retention(plots: bool) -> SampleRetention {
    if plots {
        SampleRetention::AtMost(plot::PLOT_SAMPLES)
    } else {
        SampleRetention::None
    }
}

/// Says when the figures show every `stride`-th controller tick only.
pub fn print_stride(stride: usize) {
    if stride > 1 {
        println!(
            "figures:  every {stride}th controller tick (at most {} samples per run)",
            plot::PLOT_SAMPLES
        );
    }
}

/// Writes `value` as pretty JSON to `path` through a temporary file, errors naming the path.
pub fn write_json<T: Serialize>(path: &Path, value: &T) -> Result<(), CliError> {
    let text = serde_json::to_string_pretty(value)? + "\n";
    write_file(path, "write the summary", text.as_bytes())?;
    Ok(())
}
