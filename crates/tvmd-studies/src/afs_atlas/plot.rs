//! PNG figures of the atlas: per height, the attainable cross-section (inner and outer bounds)
//! and the cone at the compared and the certified relaxations.

use std::path::Path;

use plotters::prelude::*;
use tvmd_core::Relaxation;

use super::compare::cone_radius;
use super::report::AtlasEntry;
use crate::plot::{draw_lines, ensure_parent, plot_err, register_font, Line, COLORS};
use crate::StudyError;

fn polar(points: impl Iterator<Item = (f64, f64)>) -> Vec<(f64, f64)> {
    let mut out: Vec<(f64, f64)> = points.map(|(a, r)| (r * a.cos(), r * a.sin())).collect();
    if let Some(first) = out.first().copied() {
        out.push(first);
    }
    out
}

/// Draws `entry`'s cross-sections side by side into `path`: the attained boundary (solid),
/// the outer bound (dashed), the cone at the entry's relaxation and at `s*` (if certified).
pub fn cross_sections(entry: &AtlasEntry, relaxation: f64, path: &Path) -> Result<(), StudyError> {
    tvmd_log::paths::write_via_temporary(path, "write the figure", |path| {
        draw_cross_sections(entry, relaxation, path)
    })
}

fn draw_cross_sections(entry: &AtlasEntry, relaxation: f64, path: &Path) -> Result<(), StudyError> {
    register_font();
    ensure_parent(path)?;
    let k = entry.sections.len().max(1);
    let root = BitMapBackend::new(path, (480 * k as u32, 540)).into_drawing_area();
    root.fill(&WHITE).map_err(plot_err)?;
    let failed = if entry.row.failed.is_empty() {
        String::new()
    } else {
        format!(", agents {:?} failed", entry.row.failed)
    };
    let root = root
        .titled(
            &format!(
                "{}{failed}: attainable lateral force vs the elliptic cone",
                entry.row.team
            ),
            ("sans-serif", 20),
        )
        .map_err(plot_err)?;
    let areas = root.split_evenly((1, k));
    let certified = entry.row.certified.map(|[lo, _]| lo);
    let reach = entry
        .sections
        .iter()
        .flat_map(|s| s.points.iter().map(|p| p.radius.upper))
        .filter(|r| r.is_finite())
        .fold(1.0, f64::max)
        * 1.15;
    for (area, (section, h)) in areas
        .iter()
        .zip(entry.sections.iter().zip(&entry.row.heights))
    {
        let mut chart = ChartBuilder::on(area)
            .caption(format!("u_z = {:.2} m_C g", h.height), ("sans-serif", 16))
            .margin(10)
            .x_label_area_size(30)
            .y_label_area_size(40)
            .build_cartesian_2d(-reach..reach, -reach..reach)
            .map_err(plot_err)?;
        chart
            .configure_mesh()
            .x_desc("u_x (N)")
            .y_desc("u_y (N)")
            .label_style(("sans-serif", 12))
            .draw()
            .map_err(plot_err)?;
        let height = section.query.height;
        let inner = polar(
            section
                .points
                .iter()
                .map(|p| (p.angle, p.radius.lower.unwrap_or(0.0))),
        );
        let outer = polar(
            section
                .points
                .iter()
                .map(|p| (p.angle, p.radius.upper.max(0.0))),
        );
        let dense = 360;
        let cone = |s: f64| -> Vec<(f64, f64)> {
            let Ok(s) = Relaxation::new(s) else {
                return Vec::new();
            };
            polar((0..dense).map(|i| {
                let a = std::f64::consts::TAU * i as f64 / dense as f64;
                (a, cone_radius(&entry.model.afs, s, height, a))
            }))
        };
        let mut lines = vec![
            Line::new("attained (inner)", COLORS[0], inner),
            Line::new("outer bound", COLORS[0], outer).dashed(),
            Line::new(
                format!("cone s = {relaxation}"),
                COLORS[1],
                cone(relaxation),
            ),
        ];
        if let Some(s) = certified {
            lines.push(Line::new(format!("cone s* = {s:.3}"), COLORS[2], cone(s)));
        }
        draw_lines(&mut chart, &lines)?;
    }
    root.present().map_err(plot_err)?;
    Ok(())
}
