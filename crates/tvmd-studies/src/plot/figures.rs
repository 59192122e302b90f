//! The paper's figures: state profile, Lyapunov candidates, relaxation study.

use std::path::{Path, PathBuf};

use plotters::prelude::*;

use super::draw::{
    ensure_parent, log_panel, panel, plot_err, register_font, series_of, Line, COLORS,
};
use super::PlotSeries;
use crate::StudyError;

/// Figure (a), the state profile: position `x, y, z` against `x_r` (top row) and roll, pitch,
/// yaw against the reference, with the planned roll `phi_d` in the roll panel (bottom row).
pub fn state_profile(series: &PlotSeries, path: &Path) -> Result<(), StudyError> {
    tvmd_log::paths::write_via_temporary(path, "write the figure", |path| {
        draw_state_profile(series, path)
    })
}

fn draw_state_profile(series: &PlotSeries, path: &Path) -> Result<(), StudyError> {
    register_font();
    ensure_parent(path)?;
    let root = BitMapBackend::new(path, (1500, 820)).into_drawing_area();
    root.fill(&WHITE).map_err(plot_err)?;
    let root = root
        .titled(
            &format!("State profile: {}", series.label),
            ("sans-serif", 22),
        )
        .map_err(plot_err)?;
    let areas = root.split_evenly((2, 3));
    let range = series.time_range();
    let names = ["x", "y", "z"];
    for (i, name) in names.iter().enumerate() {
        panel(
            &areas[i],
            &format!("position {name}"),
            "m",
            range,
            &[
                Line::new(
                    name.to_string(),
                    COLORS[0],
                    series_of(series, |p| Some(p.position[i])),
                ),
                Line::new(
                    format!("{name}_r"),
                    COLORS[1],
                    series_of(series, |p| Some(p.reference_position[i])),
                )
                .dashed(),
            ],
        )?;
    }
    let angles = ["roll", "pitch", "yaw"];
    for (i, name) in angles.iter().enumerate() {
        let mut lines = vec![
            Line::new(
                name.to_string(),
                COLORS[0],
                series_of(series, |p| Some(p.roll_pitch_yaw[i])),
            ),
            Line::new(
                format!("{name} ref."),
                COLORS[1],
                series_of(series, |p| Some(p.reference_roll_pitch_yaw[i])),
            )
            .dashed(),
        ];
        if i == 0 {
            lines.push(
                Line::new(
                    "planned roll",
                    COLORS[2],
                    series_of(series, |p| p.planned_roll),
                )
                .dashed(),
            );
        }
        panel(&areas[3 + i], name, "rad", range, &lines)?;
    }
    root.present().map_err(plot_err)?;
    Ok(())
}

/// Figure (b): the Lyapunov candidates `V_x` and `V_R` against time (log scale).
pub fn lyapunov(series: &PlotSeries, path: &Path) -> Result<(), StudyError> {
    tvmd_log::paths::write_via_temporary(path, "write the figure", |path| {
        draw_lyapunov(series, path)
    })
}

fn draw_lyapunov(series: &PlotSeries, path: &Path) -> Result<(), StudyError> {
    register_font();
    ensure_parent(path)?;
    let root = BitMapBackend::new(path, (1200, 520)).into_drawing_area();
    root.fill(&WHITE).map_err(plot_err)?;
    let root = root
        .titled(
            &format!("Lyapunov candidates: {}", series.label),
            ("sans-serif", 22),
        )
        .map_err(plot_err)?;
    let areas = root.split_evenly((1, 2));
    let range = series.time_range();
    log_panel(
        &areas[0],
        "V_x = |e_x|_Kx + |e_v|_Kv",
        "V_x",
        range,
        &[Line::new("V_x", COLORS[0], series_of(series, |p| p.v_x))],
    )?;
    log_panel(
        &areas[1],
        "V_R = Psi(R, R_d) + |e_Ω|_KΩ",
        "V_R",
        range,
        &[Line::new("V_R", COLORS[1], series_of(series, |p| p.v_r))],
    )?;
    root.present().map_err(plot_err)?;
    Ok(())
}

/// Figure (c), the relaxation study: planned roll (with the reference roll), actual roll,
/// allocation error `e_f` and position error `||x - x_r||` for each run.
pub fn relaxation_study(runs: &[PlotSeries], path: &Path) -> Result<(), StudyError> {
    tvmd_log::paths::write_via_temporary(path, "write the figure", |path| {
        draw_relaxation_study(runs, path)
    })
}

fn draw_relaxation_study(runs: &[PlotSeries], path: &Path) -> Result<(), StudyError> {
    register_font();
    ensure_parent(path)?;
    let root = BitMapBackend::new(path, (1500, 900)).into_drawing_area();
    root.fill(&WHITE).map_err(plot_err)?;
    let root = root
        .titled("Relaxation study", ("sans-serif", 22))
        .map_err(plot_err)?;
    let areas = root.split_evenly((2, 2));
    let range = runs
        .iter()
        .map(PlotSeries::time_range)
        .reduce(|a, b| (a.0.min(b.0), a.1.max(b.1)))
        .unwrap_or((0.0, 1.0));
    let color = |k: usize| COLORS[k % (COLORS.len() - 1)];
    let mut planned: Vec<Line> = runs
        .iter()
        .enumerate()
        .map(|(k, r)| Line::new(r.legend(), color(k), series_of(r, |p| p.planned_roll)))
        .collect();
    if let Some(first) = runs.first() {
        planned.push(
            Line::new(
                "reference roll",
                COLORS[5],
                series_of(first, |p| Some(p.reference_roll_pitch_yaw[0])),
            )
            .dashed(),
        );
    }
    panel(&areas[0], "planned roll φ_d", "rad", range, &planned)?;
    let actual: Vec<Line> = runs
        .iter()
        .enumerate()
        .map(|(k, r)| {
            Line::new(
                r.legend(),
                color(k),
                series_of(r, |p| Some(p.roll_pitch_yaw[0])),
            )
        })
        .collect();
    panel(&areas[1], "actual roll φ", "rad", range, &actual)?;
    let e_f: Vec<Line> = runs
        .iter()
        .enumerate()
        .map(|(k, r)| Line::new(r.legend(), color(k), series_of(r, |p| p.e_f)))
        .collect();
    panel(
        &areas[2],
        "allocation error e_f = |u_fd - u_f|",
        "N",
        range,
        &e_f,
    )?;
    let err: Vec<Line> = runs
        .iter()
        .enumerate()
        .map(|(k, r)| {
            Line::new(
                r.legend(),
                color(k),
                series_of(r, |p| Some(p.position_error())),
            )
        })
        .collect();
    panel(&areas[3], "position error |x - x_r|", "m", range, &err)?;
    root.present().map_err(plot_err)?;
    Ok(())
}

/// Writes figures (a) and (b) of one run into `dir` as `<stem>-state.png` and
/// `<stem>-lyapunov.png`; returns the paths.
pub fn write_run_figures(
    series: &PlotSeries,
    dir: &Path,
    stem: &str,
) -> Result<Vec<PathBuf>, StudyError> {
    tvmd_log::paths::check_output_dir(dir, "the figure directory")?;
    let state = dir.join(format!("{stem}-state.png"));
    let lyap = dir.join(format!("{stem}-lyapunov.png"));
    state_profile(series, &state)?;
    lyapunov(series, &lyap)?;
    Ok(vec![state, lyap])
}
