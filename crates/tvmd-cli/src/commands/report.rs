//! The summary table `run` prints.

use serde::Serialize;
use tvmd_scenario::Precision;
use tvmd_sim::sim::{PaperMetrics, RunSummary};

/// Everything `run` writes to the summary JSON.
#[derive(Serialize)]
pub struct RunReport<'a> {
    pub(crate) scenario: &'a str,
    pub(crate) relaxation: f64,
    pub(crate) allocator: &'a str,
    /// The control law: `"paper"`, `"offset-free"` or `"custom"` (a `[law]` table).
    pub(crate) law: &'a str,
    /// The null-space stage (`margin`, `inward-tilt=<rad>`), if any.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub(crate) null_space: Option<String>,
    /// The controller's float type, `"f64"` or `"f32"`.
    pub(crate) controller_precision: Precision,
    /// Where the controller ran: `"host"` or the emulated target.
    pub(crate) controller_target: &'a str,
    /// `atan(c_y(1, s))`, the hover law's planned-roll limit.
    pub(crate) hover_roll_limit: Option<f64>,
    pub(crate) summary: &'a RunSummary,
    pub(crate) paper: PaperMetrics,
    pub(crate) log: Option<String>,
}

fn opt(v: Option<f64>, unit: &str) -> String {
    v.map_or_else(|| "-".to_string(), |x| format!("{x:.6} {unit}"))
}

fn settled(t: Option<f64>) -> String {
    t.map_or_else(|| "not settled".to_string(), |x| format!("{x:.2} s"))
}

fn opt_e(v: Option<f64>, unit: &str) -> String {
    v.map_or_else(|| "-".to_string(), |x| format!("{x:.3e} {unit}"))
}

pub fn print_run(r: &RunReport<'_>) {
    let s = r.summary;
    let p = &r.paper;
    let mut rows: Vec<(&str, String)> = vec![
        ("scenario", r.scenario.to_string()),
        ("relaxation s", format!("{}", r.relaxation)),
        ("allocator", r.allocator.to_string()),
        ("law", r.law.to_string()),
        ("controller precision", r.controller_precision.to_string()),
        ("controller target", r.controller_target.to_string()),
        ("simulated time", format!("{:.3} s", s.time)),
        (
            "wall time / RTF",
            format!(
                "{:.3} s / {:.1}x real time",
                s.wall_time, s.real_time_factor
            ),
        ),
        (
            "max position error",
            format!("{:.4} m", s.max_position_error),
        ),
        (
            "max pos. error t >= 4 s",
            format!("{:.4} m", s.max_position_error_after_4s),
        ),
        (
            "final position error",
            format!("{:.4} m", s.final_position_error),
        ),
        (
            "horizontal error 4 s/12 s",
            format!(
                "{} / {}",
                opt(s.horizontal_error_at_4s, "m"),
                opt(s.horizontal_error_at_12s, "m")
            ),
        ),
        ("max planned roll", opt(s.max_planned_roll, "rad")),
        ("atan(c_y(1, s))", opt(r.hover_roll_limit, "rad")),
        ("max actual roll", format!("{:.6} rad", s.max_roll)),
        (
            "stage-B attitude settling",
            opt(p.stage_b_attitude_settling, "s"),
        ),
        (
            "max e_f (at t)",
            format!("{} ({})", opt_e(s.max_e_f, "N"), opt(s.max_e_f_time, "s")),
        ),
        ("max e_f / (m_C g)", opt_e(s.max_e_f_over_weight, "")),
        ("final V_x", opt_e(s.final_v_x, "")),
        (
            "largest rise of V_x",
            p.max_v_x_rise.map_or_else(
                || "-".to_string(),
                |r| {
                    format!(
                        "{:.3e} -> {:.3e} ({:.2} s -> {:.2} s)",
                        r.from_value, r.to_value, r.from, r.to
                    )
                },
            ),
        ),
        (
            "thrust min / max",
            format!("{} / {}", opt(s.min_thrust, "N"), opt(s.max_thrust, "N")),
        ),
        (
            "max |eta_x| / |eta_y|",
            format!("{:.4} / {:.4} rad", s.max_abs_eta_x, s.max_abs_eta_y),
        ),
        ("saturated periods", s.saturated_periods.to_string()),
        ("skipped cycles", s.cycle_errors.to_string()),
        ("failure masks", hover_classifications(s)),
        (
            "final position",
            format!(
                "[{:.4}, {:.4}, {:.4}] m",
                s.final_position[0], s.final_position[1], s.final_position[2]
            ),
        ),
        (
            "final speed",
            format!(
                "{:.2e} m/s",
                s.final_velocity.iter().map(|v| v * v).sum::<f64>().sqrt()
            ),
        ),
    ];
    let m = &s.metrics;
    if let Some(e) = &m.position {
        rows.push((
            "pos. settling / steady",
            format!(
                "{} / {}",
                settled(e.settling_time),
                opt(e.steady_state, "m")
            ),
        ));
    }
    if let Some(e) = &m.planned_attitude {
        rows.push((
            "R_d settling / steady",
            format!(
                "{} / {}",
                settled(e.settling_time),
                opt(e.steady_state, "rad")
            ),
        ));
    }
    if let Some(eta) = &m.thrust_efficiency {
        rows.push((
            "thrust efficiency mean/min",
            format!("{:.4} / {:.4}", eta.mean, eta.min),
        ));
    }
    rows.push((
        "verdict",
        if s.verdict.success {
            "success".to_string()
        } else {
            format!("FAILED: {}", s.verdict.failures.join("; "))
        },
    ));
    if let (Some(name), Some(n)) = (&r.null_space, &s.null_space) {
        rows.push(("null-space stage", name.clone()));
        rows.push((
            "margin mean / min",
            format!(
                "{:.3} -> {:.3} / {:.3} -> {:.3}",
                n.mean_margin_before, n.mean_margin_after, n.min_margin_before, n.min_margin_after
            ),
        ));
    }
    for (k, v) in rows {
        println!("{k:<26} {v}");
    }
}

/// The run's failure masks as the controller took them: each hover classification, and each
/// mask it refused (it then keeps allocating to the agents it was told have failed).
fn hover_classifications(s: &RunSummary) -> String {
    if s.hover_classifications.is_empty() {
        return "-".into();
    }
    let each: Vec<String> = s
        .hover_classifications
        .iter()
        .map(|h| match &h.refused {
            Some(why) => format!("t = {:.2} s REFUSED ({why})", h.time),
            None => format!(
                "t = {:.2} s {} (margin {:.3}{})",
                h.time,
                if h.capable {
                    "hover-capable"
                } else {
                    "NOT hover-capable"
                },
                h.margin,
                if h.landing { ", landing" } else { "" }
            ),
        })
        .collect();
    each.join("; ")
}
