//! `tvmd-sim sweep`: the relaxation study.

use std::path::{Path, PathBuf};

use serde::Serialize;
use tvmd_log::paths::check_output_dir;
use tvmd_scenario::Precision;
use tvmd_sim::control::hover_roll_limit;
use tvmd_sim::runner::*;
use tvmd_sim::RunRequest;
use tvmd_studies::plot::{self, PlotSeries};

use crate::error::CliError;
use std::sync::atomic::Ordering;

use super::run::{plot_retention, print_stride, write_json};
use crate::interrupt::{catch_interrupts, INTERRUPT};
use crate::progress::{progress_bar, ticks_of};

/// One row of the relaxation study.
#[derive(Serialize, Clone)]
struct SweepRow {
    relaxation: f64,
    controller_precision: Precision,
    allocator: String,
    max_planned_roll: Option<f64>,
    hover_roll_limit: f64,
    max_e_f: Option<f64>,
    max_e_f_time: Option<f64>,
    e_f_onset: Option<f64>,
    max_position_error_after_4s: f64,
    max_position_error_6_to_12s: Option<f64>,
    final_v_x: Option<f64>,
    saturated_periods: usize,
    real_time_factor: f64,
}

pub fn cmd_sweep(
    relaxations: &[f64],
    request: &RunRequest,
    plots: Option<PathBuf>,
    logs: Option<PathBuf>,
    summary: Option<PathBuf>,
    jobs: Option<usize>,
) -> Result<(), CliError> {
    let base = request.spec()?.scenario;
    let mut specs = sweep_specs(&base, relaxations, logs.as_deref())?;
    for spec in &mut specs {
        spec.samples = plot_retention(plots.is_some());
    }
    if specs.is_empty() {
        return Err(CliError::Other("no relaxation given".into()));
    }
    let extra: Vec<(String, &Path)> = summary
        .iter()
        .map(|p| ("the summary (--summary)".to_string(), p.as_path()))
        .collect();
    // Every output is checked before the first flight ([`tvmd_log::paths`]).
    if let Some(dir) = &logs {
        check_output_dir(dir, "the log directory (--logs)")?;
    }
    if let Some(dir) = &plots {
        check_output_dir(dir, "the figure directory (--plots)")?;
    }
    check_batch_outputs(&specs, &extra)?;
    catch_interrupts();
    let total: u64 = specs.iter().map(|s| ticks_of(&s.scenario)).sum();
    let bar = progress_bar(total, &format!("{} runs", specs.len()));
    let outcomes = run_many_until(specs, jobs, Some(&|_, _| bar.inc(1)), Some(&INTERRUPT));
    bar.finish_and_clear();
    if INTERRUPT.load(Ordering::SeqCst) {
        return Err(CliError::Interrupted(
            "the sweep was stopped; every started run's log is finalised".into(),
        ));
    }
    let mut rows = Vec::new();
    let mut series = Vec::new();
    let mut stride = 1;
    for outcome in outcomes {
        let sc = &outcome.spec.scenario;
        let r = outcome
            .result
            .map_err(|e| CliError::Other(format!("run {}: {e}", sc.name)))?;
        let s = &r.summary;
        let paper = &r.paper;
        rows.push(SweepRow {
            relaxation: sc.relaxation,
            controller_precision: sc.controller_precision,
            allocator: sc.allocator.clone(),
            max_planned_roll: s.max_planned_roll,
            hover_roll_limit: hover_roll_limit(sc, sc.relaxation)?,
            max_e_f: s.max_e_f,
            max_e_f_time: s.max_e_f_time,
            e_f_onset: paper.e_f_onset,
            max_position_error_after_4s: s.max_position_error_after_4s,
            max_position_error_6_to_12s: paper.max_position_error_6_to_12s,
            final_v_x: s.final_v_x,
            saturated_periods: s.saturated_periods,
            real_time_factor: s.real_time_factor,
        });
        series.push(PlotSeries::from_samples(
            &sc.name,
            Some(sc.relaxation),
            &r.samples,
        ));
        stride = stride.max(r.sample_stride);
    }
    println!(
        "controller precision: {}, allocator: {}",
        base.controller_precision, base.allocator
    );
    let na =
        |v: Option<f64>, prec: usize| v.map_or_else(|| "-".to_string(), |x| format!("{x:.prec$}"));
    println!(
        "{:>5} {:>11} {:>11} {:>10} {:>6} {:>9} {:>10} {:>10} {:>10} {:>6}",
        "s",
        "max phi_d",
        "atan(c_y)",
        "max e_f",
        "at t",
        "e_f onset",
        "|e_x|t>=4",
        "|e_x|6-12",
        "final V_x",
        "sat."
    );
    println!(
        "{:>5} {:>11} {:>11} {:>10} {:>6} {:>9} {:>10} {:>10} {:>10} {:>6}",
        "", "(rad)", "(rad)", "(N)", "(s)", "(s)", "(m)", "(m)", "", "(per.)"
    );
    for r in &rows {
        println!(
            "{:>5} {:>11.6} {:>11.6} {:>10.3e} {:>6.2} {:>9} {:>10.4} {:>10} {:>10.3e} {:>6}",
            r.relaxation,
            r.max_planned_roll.unwrap_or(f64::NAN),
            r.hover_roll_limit,
            r.max_e_f.unwrap_or(f64::NAN),
            r.max_e_f_time.unwrap_or(f64::NAN),
            na(r.e_f_onset, 2),
            r.max_position_error_after_4s,
            na(r.max_position_error_6_to_12s, 4),
            r.final_v_x.unwrap_or(f64::NAN),
            r.saturated_periods
        );
    }
    if let Some(p) = &summary {
        write_json(p, &rows)?;
        println!("summary:  {}", p.display());
    }
    if let Some(dir) = &plots {
        let path = dir.join("relaxation.png");
        plot::relaxation_study(&series, &path)?;
        println!("figure:   {}", path.display());
        print_stride(stride);
    }
    if let Some(dir) = &logs {
        println!("logs:     {}", dir.display());
    }
    Ok(())
}
