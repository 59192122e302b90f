//! The study's figures: box plots of the metrics across groups, and the success rate per group
//! (against the model-error level when the study has several).

use std::path::{Path, PathBuf};

use plotters::prelude::*;

use super::flight::FlightRow;
use super::report::{group_key, quantile, GroupSummary};
use crate::plot::{ensure_parent, plot_err, register_font, COLORS};
use crate::StudyError;

/// A metric the box plots show: file stem, title, unit and how to read it from a row.
type Metric = (
    &'static str,
    &'static str,
    &'static str,
    fn(&FlightRow) -> Option<f64>,
);

/// The metrics with a box plot each.
pub const METRICS: [Metric; 5] = [
    (
        "box_position_steady_state",
        "steady-state position error",
        "m",
        |r| r.position_steady_state,
    ),
    ("box_position_peak", "peak position error", "m", |r| {
        r.position_peak
    }),
    (
        "box_position_settling_time",
        "2% settling time of the position error",
        "s",
        |r| r.position_settling_time,
    ),
    (
        "box_planned_attitude_settling_time",
        "settling time of the attitude error to R_d",
        "s",
        |r| r.planned_attitude_settling_time,
    ),
    (
        "box_thrust_efficiency",
        "mean thrust efficiency",
        "-",
        |r| r.mean_thrust_efficiency,
    ),
];

/// A short allocator name for the figures' axes.
fn short(allocator: &str) -> &str {
    match allocator {
        "exact-boundary-redistribution" => "EBR",
        "redistributed-pseudo-inverse" => "RPI",
        "pseudo-inverse" => "PI",
        "weighted-pseudo-inverse" => "WPI",
        "clarabel" => "QP",
        "clarabel-sequential" => "QP-seq",
        other => other,
    }
}

fn label(k: &(String, String, f64), several_levels: bool) -> String {
    if several_levels {
        format!("{} {} x{}", k.0, short(&k.1), k.2)
    } else {
        format!("{} {}", k.0, short(&k.1))
    }
}

/// Tukey's box: quartiles, whiskers at the most extreme values within 1.5 IQR of the box,
/// and the values beyond them.
struct TukeyBox {
    q1: f64,
    median: f64,
    q3: f64,
    low: f64,
    high: f64,
    outliers: Vec<f64>,
}

impl TukeyBox {
    fn new(values: &[f64]) -> Option<Self> {
        let q = |p: f64| quantile(values.iter().copied(), p);
        let (q1, median, q3) = (q(0.25)?, q(0.5)?, q(0.75)?);
        let fence = 1.5 * (q3 - q1);
        let inside = values
            .iter()
            .copied()
            .filter(|v| *v >= q1 - fence && *v <= q3 + fence);
        let (low, high) = inside.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
        let outliers = values
            .iter()
            .copied()
            .filter(|v| *v < low || *v > high)
            .collect();
        Some(Self {
            q1,
            median,
            q3,
            low,
            high,
            outliers,
        })
    }
}

/// One box per group of `metric`'s values (groups with no value are left empty).
fn box_plot(
    rows: &[FlightRow],
    groups: &[GroupSummary],
    metric: &Metric,
    path: &Path,
) -> Result<(), StudyError> {
    let (_, title, unit, read) = metric;
    let several = levels(groups).len() > 1;
    let keys: Vec<(String, String, f64)> = groups
        .iter()
        .map(|g| (g.team.clone(), g.allocator.clone(), g.model_error))
        .collect();
    let values: Vec<Vec<f64>> = keys
        .iter()
        .map(|k| {
            rows.iter()
                .filter(|r| &group_key(r) == k)
                .filter_map(read)
                .filter(|v| v.is_finite())
                .collect()
        })
        .collect();
    let all = values.iter().flatten().copied();
    let (lo, hi) = all.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
        (a.min(v), b.max(v))
    });
    let (lo, hi) = if lo.is_finite() {
        let span = (hi - lo).max(1e-6 * (1.0 + hi.abs()));
        (lo - 0.08 * span, hi + 0.08 * span)
    } else {
        (0.0, 1.0)
    };
    let n = keys.len();
    let width = (200 + 130 * n).clamp(640, 2400) as u32;
    let root = BitMapBackend::new(path, (width, 560)).into_drawing_area();
    root.fill(&WHITE).map_err(plot_err)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(
            format!("{title} ({} flights)", rows.len()),
            ("sans-serif", 20),
        )
        .margin(12)
        .x_label_area_size(50)
        .y_label_area_size(80)
        .build_cartesian_2d(-0.5..n as f64 - 0.5, lo..hi)
        .map_err(plot_err)?;
    let names: Vec<String> = keys.iter().map(|k| label(k, several)).collect();
    chart
        .configure_mesh()
        .y_desc(*unit)
        .x_labels(n + 1)
        .x_label_formatter(&|x| {
            let i = x.round();
            if (x - i).abs() < 1e-6 && i >= 0.0 {
                names.get(i as usize).cloned().unwrap_or_default()
            } else {
                String::new()
            }
        })
        .label_style(("sans-serif", 13))
        .light_line_style(WHITE.mix(0.0))
        .draw()
        .map_err(plot_err)?;
    for (i, v) in values.iter().enumerate() {
        let Some(b) = TukeyBox::new(v) else {
            continue;
        };
        let color = COLORS[i % COLORS.len()];
        let x = i as f64;
        let (w, cap) = (0.3, 0.15);
        let line =
            |a: (f64, f64), c: (f64, f64)| PathElement::new(vec![a, c], color.stroke_width(2));
        chart
            .draw_series([Rectangle::new(
                [(x - w, b.q1), (x + w, b.q3)],
                color.stroke_width(2),
            )])
            .map_err(plot_err)?;
        chart
            .draw_series([
                line((x - w, b.median), (x + w, b.median)),
                line((x, b.q3), (x, b.high)),
                line((x, b.q1), (x, b.low)),
                line((x - cap, b.high), (x + cap, b.high)),
                line((x - cap, b.low), (x + cap, b.low)),
            ])
            .map_err(plot_err)?;
        chart
            .draw_series(b.outliers.iter().map(|&y| Circle::new((x, y), 3, color)))
            .map_err(plot_err)?;
    }
    root.present().map_err(plot_err)
}

fn levels(groups: &[GroupSummary]) -> Vec<f64> {
    let mut v: Vec<f64> = groups.iter().map(|g| g.model_error).collect();
    v.sort_by(f64::total_cmp);
    v.dedup();
    v
}

/// The success rate per team and allocator against the model-error level (one point per level
/// when the study has one).
fn success_rate(groups: &[GroupSummary], path: &Path) -> Result<(), StudyError> {
    let levels = levels(groups);
    let (x0, x1) = match (levels.first(), levels.last()) {
        (Some(&a), Some(&b)) if b > a => (a, b),
        (Some(&a), _) => (a - 0.5, a + 0.5),
        _ => (0.0, 1.0),
    };
    let root = BitMapBackend::new(path, (900, 560)).into_drawing_area();
    root.fill(&WHITE).map_err(plot_err)?;
    let mut chart = ChartBuilder::on(&root)
        .caption("success rate against model error", ("sans-serif", 20))
        .margin(12)
        .x_label_area_size(50)
        .y_label_area_size(70)
        .build_cartesian_2d(x0..x1, 0.0..105.0)
        .map_err(plot_err)?;
    chart
        .configure_mesh()
        .x_desc("model-error multiplier")
        .y_desc("success (%)")
        .label_style(("sans-serif", 13))
        .light_line_style(WHITE.mix(0.0))
        .draw()
        .map_err(plot_err)?;
    let mut series: Vec<(String, String)> = Vec::new();
    for g in groups {
        let k = (g.team.clone(), g.allocator.clone());
        if !series.contains(&k) {
            series.push(k);
        }
    }
    for (i, (team, allocator)) in series.iter().enumerate() {
        let color = COLORS[i % COLORS.len()];
        let points: Vec<(f64, f64)> = groups
            .iter()
            .filter(|g| &g.team == team && &g.allocator == allocator)
            .map(|g| (g.model_error, 100.0 * g.success_rate))
            .collect();
        chart
            .draw_series(LineSeries::new(
                points.iter().copied(),
                color.stroke_width(2),
            ))
            .map_err(plot_err)?
            .label(format!("{team} {}", short(allocator)))
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 18, y)], color.stroke_width(2))
            });
        chart
            .draw_series(points.iter().map(|&p| Circle::new(p, 4, color.filled())))
            .map_err(plot_err)?;
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK.mix(0.3))
        .label_font(("sans-serif", 14))
        .position(SeriesLabelPosition::LowerLeft)
        .draw()
        .map_err(plot_err)?;
    root.present().map_err(plot_err)
}

/// Writes every figure of the study into `dir`; returns the files.
pub fn write_plots(
    rows: &[FlightRow],
    groups: &[GroupSummary],
    dir: &Path,
) -> Result<Vec<PathBuf>, StudyError> {
    register_font();
    let mut out = Vec::new();
    for metric in &METRICS {
        let path = dir.join(format!("{}.png", metric.0));
        ensure_parent(&path)?;
        tvmd_log::paths::write_via_temporary(&path, "write the figure", |t| {
            box_plot(rows, groups, metric, t)
        })?;
        out.push(path);
    }
    let path = dir.join("success_rate.png");
    tvmd_log::paths::write_via_temporary(&path, "write the figure", |t| success_rate(groups, t))?;
    out.push(path);
    Ok(out)
}
