//! PNG figures reproducing the paper's simulation figures, drawn with plotters.
//!
//! - [`state_profile`]: position `x, y, z` against `x_r`; roll, pitch, yaw against the reference
//!   and the planned roll (paper, "state profile in the simulation");
//! - [`lyapunov`]: `V_x` and `V_R` on a log scale (paper, "Lyapunov candidates profile");
//! - [`relaxation_study`]: planned roll, actual roll, `e_f` and position error for several
//!   relaxations `s` (paper, "tracking performance with different attitude planner relaxation").
//!
//! The data come either from a run's samples ([`PlotSeries::from_samples`]) or from an MCAP log
//! written by the simulator ([`PlotSeries::from_mcap`]), so a log can be re-plotted without
//! re-running it.
//!
//! Text is drawn with plotters' `ab_glyph` backend and a font embedded in the binary
//! (`assets/TvmdPlotSans.ttf`, a renamed subset of DejaVu Sans, see `assets/FONT-LICENSE.txt`):
//! no system fontconfig or freetype is needed.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Once;

use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;
use prost::Message;

use crate::log::{proto, METADATA_SCENARIO};
use crate::sim::Sample;
use crate::SimError;

/// The most samples a run's figures are drawn from: a run keeps this many evenly spaced
/// controller ticks for its figures (a 1500 px wide figure shows no more), whatever its length.
pub const PLOT_SAMPLES: usize = 20_000;

/// The embedded font (a renamed subset of DejaVu Sans).
const FONT: &[u8] = include_bytes!("../assets/TvmdPlotSans.ttf");

static FONT_ONCE: Once = Once::new();

pub(crate) fn register_font() {
    FONT_ONCE.call_once(|| {
        // The embedded font is known to parse; a failure would only lose the labels.
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT);
    });
}

/// One time step of a plotted run.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PlotPoint {
    /// Time (s).
    pub t: f64,
    /// `x` (m).
    pub position: [f64; 3],
    /// `x_r` (m).
    pub reference_position: [f64; 3],
    /// Roll, pitch, yaw of `R` (rad).
    pub roll_pitch_yaw: [f64; 3],
    /// Roll, pitch, yaw of `R_r` (rad).
    pub reference_roll_pitch_yaw: [f64; 3],
    /// Planned roll (rad).
    pub planned_roll: Option<f64>,
    /// `e_f` (N).
    pub e_f: Option<f64>,
    /// `V_x`.
    pub v_x: Option<f64>,
    /// `V_R`.
    pub v_r: Option<f64>,
}

impl PlotPoint {
    fn position_error(&self) -> f64 {
        (0..3)
            .map(|i| (self.position[i] - self.reference_position[i]).powi(2))
            .sum::<f64>()
            .sqrt()
    }
}

/// The time series of one run.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PlotSeries {
    /// Name shown in titles and legends (e.g. the scenario name).
    pub label: String,
    /// The planner relaxation `s` of the run, if known.
    pub relaxation: Option<f64>,
    /// The points, in time order.
    pub points: Vec<PlotPoint>,
}

fn read_err(what: impl Into<String>) -> SimError {
    SimError::LogRead(what.into())
}

fn arr3(v: &[f64], field: &str) -> Result<[f64; 3], SimError> {
    <[f64; 3]>::try_from(v)
        .map_err(|_| read_err(format!("`{field}` has {} entries, not 3", v.len())))
}

impl PlotSeries {
    /// From a run's samples.
    pub fn from_samples(label: &str, relaxation: Option<f64>, samples: &[Sample]) -> Self {
        Self {
            label: label.to_string(),
            relaxation,
            points: samples
                .iter()
                .map(|s| PlotPoint {
                    t: s.t,
                    position: s.position,
                    reference_position: s.reference_position,
                    roll_pitch_yaw: s.roll_pitch_yaw,
                    reference_roll_pitch_yaw: s.reference_roll_pitch_yaw,
                    planned_roll: s.planned_roll,
                    e_f: s.e_f,
                    v_x: s.v_x,
                    v_r: s.v_r,
                })
                .collect(),
        }
    }

    /// From the bytes of an MCAP log written by the simulator: `/state`, `/reference`,
    /// `/planner`, `/allocation` and `/lyapunov` messages matched by log time; label and
    /// relaxation from the scenario metadata if present. Needs `/state` and `/reference`.
    pub fn from_mcap(bytes: &[u8]) -> Result<Self, SimError> {
        let mut rows: BTreeMap<u64, PlotPoint> = BTreeMap::new();
        let mut seen_state = false;
        let mut seen_reference = false;
        let stream = mcap::MessageStream::new(bytes).map_err(|e| read_err(e.to_string()))?;
        for m in stream {
            let m = m.map_err(|e| read_err(e.to_string()))?;
            let topic = m.channel.topic.as_str();
            if !matches!(
                topic,
                "/state" | "/reference" | "/planner" | "/allocation" | "/lyapunov"
            ) {
                continue;
            }
            let row = rows.entry(m.log_time).or_default();
            row.t = m.log_time as f64 * 1e-9;
            let bad = |e: prost::DecodeError| {
                read_err(format!(
                    "`{topic}` message is not a tvmd protobuf message: {e}"
                ))
            };
            match topic {
                "/state" => {
                    seen_state = true;
                    let s = proto::State::decode(&*m.data).map_err(bad)?;
                    row.t = s.t;
                    row.position = arr3(&s.position, "/state.position")?;
                    row.roll_pitch_yaw = arr3(&s.roll_pitch_yaw, "/state.roll_pitch_yaw")?;
                }
                "/reference" => {
                    seen_reference = true;
                    let r = proto::Reference::decode(&*m.data).map_err(bad)?;
                    row.reference_position = arr3(&r.position, "/reference.position")?;
                    row.reference_roll_pitch_yaw =
                        arr3(&r.roll_pitch_yaw, "/reference.roll_pitch_yaw")?;
                }
                "/planner" => {
                    row.planned_roll =
                        Some(proto::Planner::decode(&*m.data).map_err(bad)?.planned_roll);
                }
                "/allocation" => {
                    row.e_f = Some(proto::Allocation::decode(&*m.data).map_err(bad)?.e_f);
                }
                _ => {
                    let l = proto::Lyapunov::decode(&*m.data).map_err(bad)?;
                    row.v_x = Some(l.v_x);
                    row.v_r = Some(l.v_r);
                }
            }
        }
        if !seen_state || !seen_reference {
            return Err(read_err(
                "the log has no `/state` or no `/reference` messages (not a tvmd-sim run?)",
            ));
        }
        let mut label = String::from("run");
        let mut relaxation = None;
        if let Ok(Some(summary)) = mcap::Summary::read(bytes) {
            for idx in summary
                .metadata_indexes
                .iter()
                .filter(|i| i.name == METADATA_SCENARIO)
            {
                if let Ok(meta) = mcap::read::metadata(bytes, idx) {
                    if let Some(n) = meta.metadata.get("name") {
                        label.clone_from(n);
                    }
                    relaxation = meta.metadata.get("relaxation").and_then(|s| s.parse().ok());
                }
            }
        }
        Ok(Self {
            label,
            relaxation,
            points: rows.into_values().collect(),
        })
    }

    /// Reads an MCAP file and calls [`PlotSeries::from_mcap`].
    pub fn from_mcap_file(path: impl AsRef<Path>) -> Result<Self, SimError> {
        let path = path.as_ref();
        let bytes = std::fs::read(path)?;
        Self::from_mcap(&bytes).map_err(|e| match e {
            SimError::LogRead(m) => SimError::LogRead(format!("{}: {m}", path.display())),
            other => other,
        })
    }

    fn time_range(&self) -> (f64, f64) {
        let t0 = self.points.first().map_or(0.0, |p| p.t);
        let t1 = self.points.last().map_or(1.0, |p| p.t);
        (t0, if t1 > t0 { t1 } else { t0 + 1.0 })
    }

    fn legend(&self) -> String {
        match self.relaxation {
            Some(s) => format!("s = {s}"),
            None => self.label.clone(),
        }
    }
}

pub(crate) fn plot_err(e: impl std::fmt::Display) -> SimError {
    SimError::Plot(e.to_string())
}

/// A line of a panel.
pub(crate) struct Line {
    label: String,
    color: RGBColor,
    dashed: bool,
    points: Vec<(f64, f64)>,
}

impl Line {
    pub(crate) fn new(label: impl Into<String>, color: RGBColor, points: Vec<(f64, f64)>) -> Self {
        Self {
            label: label.into(),
            color,
            dashed: false,
            points,
        }
    }

    pub(crate) fn dashed(mut self) -> Self {
        self.dashed = true;
        self
    }
}

pub(crate) const COLORS: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(255, 127, 14),
    RGBColor(0, 0, 0),
];

fn y_range(lines: &[Line]) -> (f64, f64) {
    let (lo, hi) = lines
        .iter()
        .flat_map(|l| l.points.iter().map(|p| p.1))
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    if !lo.is_finite() {
        return (-1.0, 1.0);
    }
    let span = (hi - lo).max(1e-3 * (1.0 + hi.abs().max(lo.abs())));
    (lo - 0.08 * span, hi + 0.08 * span)
}

pub(crate) fn draw_lines<'a, DB: DrawingBackend + 'a, Y: Ranged<ValueType = f64>>(
    chart: &mut ChartContext<'a, DB, Cartesian2d<RangedCoordf64, Y>>,
    lines: &[Line],
) -> Result<(), SimError> {
    for line in lines {
        let style = line.color.stroke_width(2);
        let color = line.color;
        if line.dashed {
            chart
                .draw_series(DashedLineSeries::new(
                    line.points.iter().copied(),
                    6,
                    4,
                    style,
                ))
                .map_err(plot_err)?
                .label(line.label.as_str())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], color));
        } else {
            chart
                .draw_series(LineSeries::new(line.points.iter().copied(), style))
                .map_err(plot_err)?
                .label(line.label.as_str())
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 18, y)], color.stroke_width(2))
                });
        }
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK.mix(0.3))
        .label_font(("sans-serif", 14))
        .position(SeriesLabelPosition::UpperRight)
        .draw()
        .map_err(plot_err)?;
    Ok(())
}

fn panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    title: &str,
    y_label: &str,
    (t0, t1): (f64, f64),
    lines: &[Line],
) -> Result<(), SimError> {
    let (lo, hi) = y_range(lines);
    let mut chart = ChartBuilder::on(area)
        .caption(title, ("sans-serif", 18))
        .margin(8)
        .x_label_area_size(34)
        .y_label_area_size(64)
        .build_cartesian_2d(t0..t1, lo..hi)
        .map_err(plot_err)?;
    chart
        .configure_mesh()
        .x_desc("t (s)")
        .y_desc(y_label)
        .label_style(("sans-serif", 13))
        .axis_desc_style(("sans-serif", 14))
        .light_line_style(WHITE.mix(0.0))
        .draw()
        .map_err(plot_err)?;
    draw_lines(&mut chart, lines)
}

/// Smallest value shown on the log-scale panels.
const LOG_FLOOR: f64 = 1e-12;

fn log_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    title: &str,
    y_label: &str,
    (t0, t1): (f64, f64),
    lines: &[Line],
) -> Result<(), SimError> {
    let clamped: Vec<Line> = lines
        .iter()
        .map(|l| Line {
            label: l.label.clone(),
            color: l.color,
            dashed: l.dashed,
            points: l
                .points
                .iter()
                .map(|&(t, v)| (t, v.max(LOG_FLOOR)))
                .collect(),
        })
        .collect();
    let hi = clamped
        .iter()
        .flat_map(|l| l.points.iter().map(|p| p.1))
        .filter(|v| v.is_finite())
        .fold(LOG_FLOOR * 10.0, f64::max);
    let lo = clamped
        .iter()
        .flat_map(|l| l.points.iter().map(|p| p.1))
        .filter(|v| v.is_finite())
        .fold(hi, f64::min)
        .max(hi * 1e-10);
    let mut chart = ChartBuilder::on(area)
        .caption(title, ("sans-serif", 18))
        .margin(8)
        .x_label_area_size(34)
        .y_label_area_size(64)
        .build_cartesian_2d(t0..t1, (lo * 0.5..hi * 2.0).log_scale())
        .map_err(plot_err)?;
    chart
        .configure_mesh()
        .x_desc("t (s)")
        .y_desc(y_label)
        .label_style(("sans-serif", 13))
        .axis_desc_style(("sans-serif", 14))
        .y_label_formatter(&|v| format!("{v:.0e}"))
        .light_line_style(WHITE.mix(0.0))
        .draw()
        .map_err(plot_err)?;
    draw_lines(&mut chart, &clamped)
}

fn series_of(s: &PlotSeries, f: impl Fn(&PlotPoint) -> Option<f64>) -> Vec<(f64, f64)> {
    s.points
        .iter()
        .filter_map(|p| f(p).map(|v| (p.t, v)))
        .collect()
}

pub(crate) fn ensure_parent(path: &Path) -> Result<(), SimError> {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)?;
    }
    Ok(())
}

/// Figure (a), the state profile: position `x, y, z` against `x_r` (top row) and roll, pitch,
/// yaw against the reference, with the planned roll `phi_d` in the roll panel (bottom row).
pub fn state_profile(series: &PlotSeries, path: &Path) -> Result<(), SimError> {
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
pub fn lyapunov(series: &PlotSeries, path: &Path) -> Result<(), SimError> {
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
pub fn relaxation_study(runs: &[PlotSeries], path: &Path) -> Result<(), SimError> {
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
) -> Result<Vec<PathBuf>, SimError> {
    std::fs::create_dir_all(dir)?;
    let state = dir.join(format!("{stem}-state.png"));
    let lyap = dir.join(format!("{stem}-lyapunov.png"));
    state_profile(series, &state)?;
    lyapunov(series, &lyap)?;
    Ok(vec![state, lyap])
}
