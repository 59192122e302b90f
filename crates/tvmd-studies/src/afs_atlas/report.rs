//! One team's atlas entry: hover ceiling, the cone against the attainable set at a few
//! heights, and `s*`, as a serializable row (the CLI's table, Python's dict, the docs' table).

use std::sync::atomic::{AtomicBool, Ordering};

use nalgebra::Vector3;
use serde::Serialize;
use tvmd_core::{FailureMask, Relaxation, TeamConfig};

use super::certify::{certified_relaxation_until, HeightRange};
use super::compare::{compare, cone_radius, Interval};
use super::model::AtlasModel;
use super::section::{cross_section_until, CrossSection, SectionQuery};
use tvmd_plant::GRAVITY;

use crate::StudyError;

/// What to compute.
#[derive(Clone, Debug, PartialEq)]
pub struct AtlasSettings {
    /// Heights of the comparison, in multiples of the weight `m_C g`.
    pub heights: Vec<f64>,
    /// Directions per cross-section.
    pub directions: usize,
    /// The relaxation of the compared cone (1: the cone of eq. 8 itself).
    pub relaxation: f64,
    /// The range `s*` is certified over.
    pub range: HeightRange,
    /// The torque the agents must hold (N m).
    pub torque: [f64; 3],
}

impl Default for AtlasSettings {
    /// Heights 0.5, 1.0 and 1.5 `m_C g`, 36 directions, `s = 1`, the default [`HeightRange`],
    /// zero torque.
    fn default() -> Self {
        Self {
            heights: vec![0.5, 1.0, 1.5],
            directions: 36,
            relaxation: 1.0,
            range: HeightRange::default(),
            torque: [0.0; 3],
        }
    }
}

/// The comparison at one height (every number an interval from the brackets).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct HeightRow {
    /// `u_z / (m_C g)`.
    pub height: f64,
    /// Whether the section's centre was attained (otherwise `ratio` and `conservatism` are
    /// `None`).
    pub attained: bool,
    /// Whether the height is above the hover ceiling's outer bound: nothing is attainable at
    /// this torque (`soundness` is then 0 if the cone admits any lateral force, else 1).
    pub empty: bool,
    /// Smallest and largest `cone / attainable` radius ratio over the directions.
    pub ratio: Option<[f64; 2]>,
    /// `|cone ∩ attainable| / |cone|`.
    pub soundness: Option<[f64; 2]>,
    /// `|cone ∩ attainable| / |attainable|`.
    pub conservatism: Option<[f64; 2]>,
    /// The widest bracket of the section, relative to its upper bound (`None` unless attained).
    pub worst_width: Option<f64>,
}

/// One team's entry.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct AtlasRow {
    /// The team's name.
    pub team: String,
    /// Failed agents.
    pub failed: Vec<usize>,
    /// Working agents.
    pub n: usize,
    /// `m_C g` (N).
    pub weight: f64,
    /// The hover ceiling bracket, in `m_C g` (`[lower, upper]`; lower `None` if not attained).
    pub ceiling: [Option<f64>; 2],
    /// Whether hover at the weight is within the attained ceiling.
    pub can_hover: bool,
    /// The comparisons.
    pub heights: Vec<HeightRow>,
    /// `s*` bracketed (`None` when the ceiling was not attained).
    pub certified: Option<[f64; 2]>,
    /// The range of `s*`, `[lowest, highest]` height in `m_C g`.
    pub certified_range: Option<[f64; 2]>,
    /// Where `s*`'s lower end is limited: `[u_z / (m_C g), angle in degrees]`.
    pub limiting: Option<[f64; 2]>,
    /// The widest bracket over the certification grid, relative.
    pub certified_worst_width: Option<f64>,
    /// Why nothing was computed (e.g. a degraded team that cannot produce every wrench).
    pub note: Option<String>,
}

impl AtlasRow {
    /// A row for a team and mask the atlas cannot treat, with the reason.
    pub fn unavailable(team: &str, failed: &[usize], note: String) -> Self {
        Self {
            team: team.to_string(),
            failed: failed.to_vec(),
            n: 0,
            weight: f64::NAN,
            ceiling: [None, None],
            can_hover: false,
            heights: Vec::new(),
            certified: None,
            certified_range: None,
            limiting: None,
            certified_worst_width: None,
            note: Some(note),
        }
    }
}

/// A row with the cross-sections it was computed from (the comparison heights).
#[derive(Clone, Debug)]
pub struct AtlasEntry {
    /// The row.
    pub row: AtlasRow,
    /// The comparison heights' sections, in order.
    pub sections: Vec<CrossSection>,
    /// The model.
    pub model: AtlasModel,
}

fn pair(i: Interval) -> [f64; 2] {
    [i.lower, i.upper]
}

/// Computes one team's entry. Errors for a bad failure mask or settings.
pub fn atlas_entry<const N: usize>(
    name: &str,
    team: &TeamConfig<f64, N>,
    failed: &[usize],
    settings: &AtlasSettings,
) -> Result<AtlasEntry, StudyError> {
    atlas_entry_until(name, team, failed, settings, None)
}

/// [`atlas_entry`], stopping within one ray once `cancel` is set
/// ([`StudyError::Interrupted`]).
pub fn atlas_entry_until<const N: usize>(
    name: &str,
    team: &TeamConfig<f64, N>,
    failed: &[usize],
    settings: &AtlasSettings,
    cancel: Option<&AtomicBool>,
) -> Result<AtlasEntry, StudyError> {
    let bad = |name: &str, reason: String| StudyError::InvalidArgument {
        name: name.into(),
        reason,
    };
    let s = Relaxation::new(settings.relaxation).map_err(|e| bad("relaxation", e.to_string()))?;
    if settings.directions < 4 || settings.directions > 3600 {
        return Err(bad(
            "directions",
            format!("must be in [4, 3600], got {}", settings.directions),
        ));
    }
    let r = settings.range;
    if !(r.from > 0.0 && r.from < r.to && r.to < 1.0) || r.heights < 2 || r.heights > 200 {
        return Err(bad(
            "range",
            format!("need 0 < from < to < 1 and 2..=200 heights, got {r:?}"),
        ));
    }
    if settings
        .heights
        .iter()
        .any(|h| !(h.is_finite() && *h > 0.0 && *h < 100.0))
    {
        return Err(bad(
            "heights",
            format!("each in (0, 100) m_C g, got {:?}", settings.heights),
        ));
    }
    if settings.torque.iter().any(|t| !t.is_finite()) {
        return Err(bad("torque", "must be finite".into()));
    }
    let mask = FailureMask::with_failed(failed).map_err(|e| bad("failed", e.to_string()))?;
    let model = AtlasModel::new(team, &mask).map_err(|e| match e {
        tvmd_core::ConfigError::RankDeficient { .. } => StudyError::invalid_team(
            "M(Xi) is not rank 6 without these agents: not every wrench is attainable",
        ),
        other => bad("failed", other.to_string()),
    })?;
    let weight = model.mass * GRAVITY;
    let torque = Vector3::from(settings.torque);
    let sections: Vec<CrossSection> = settings
        .heights
        .iter()
        .map(|h| {
            cross_section_until(
                &model,
                &SectionQuery {
                    height: h * weight,
                    torque,
                    directions: settings.directions,
                },
                cancel,
            )
        })
        .collect();
    let cert = certified_relaxation_until(
        &model,
        &torque,
        &settings.range,
        settings.directions,
        cancel,
    );
    if cancel.is_some_and(|c| c.load(Ordering::Relaxed)) {
        return Err(StudyError::Interrupted(format!(
            "the atlas of {name} was stopped before it finished"
        )));
    }
    let ceiling = cert.as_ref().map_or_else(
        || super::section::hover_ceiling(&model, &torque).bracket,
        |c| c.ceiling,
    );
    let heights = settings
        .heights
        .iter()
        .zip(&sections)
        .map(|(h, section)| {
            let cmp = compare(&model.afs, s, section);
            // Above the ceiling's outer bound nothing is attainable at this torque: whatever
            // the cone admits there is unsound.
            let empty = section.query.height > ceiling.upper;
            let cone_admits = section
                .points
                .iter()
                .any(|p| cone_radius(&model.afs, s, section.query.height, p.angle) > 0.0);
            let soundness = match (&cmp, empty) {
                (Some(c), _) => Some(pair(c.soundness)),
                (None, true) => Some(if cone_admits { [0.0, 0.0] } else { [1.0, 1.0] }),
                (None, false) => None,
            };
            HeightRow {
                height: *h,
                attained: cmp.is_some(),
                empty,
                ratio: cmp.as_ref().map(|c| pair(c.ratio_range())),
                soundness,
                conservatism: cmp.as_ref().map(|c| pair(c.conservatism)),
                worst_width: cmp.as_ref().map(|_| section.worst_relative_width()),
            }
        })
        .collect();
    let row = AtlasRow {
        team: name.to_string(),
        failed: failed.to_vec(),
        n: model.len(),
        weight,
        ceiling: [
            ceiling.lower.map(|c| c / weight),
            Some(ceiling.upper / weight),
        ],
        can_hover: ceiling.lower.is_some_and(|c| c > weight),
        heights,
        certified: cert.as_ref().map(|c| [c.lower, c.upper]),
        certified_range: cert
            .as_ref()
            .and_then(|c| Some([*c.heights.first()? / weight, *c.heights.last()? / weight])),
        limiting: cert
            .as_ref()
            .map(|c| [c.limiting.0 / weight, c.limiting.1.to_degrees()]),
        certified_worst_width: cert.as_ref().map(|c| {
            c.sections
                .iter()
                .map(CrossSection::worst_relative_width)
                .fold(0.0, f64::max)
        }),
        note: None,
    };
    Ok(AtlasEntry {
        row,
        sections,
        model,
    })
}

fn interval(x: &Option<[f64; 2]>, digits: usize) -> String {
    match x {
        Some([a, b]) if (b - a).abs() < 0.5 * 10f64.powi(-(digits as i32)) => {
            format!("{a:.digits$}")
        }
        Some([a, b]) if b.is_infinite() => format!("[{a:.digits$}, inf]"),
        Some([a, b]) => format!("[{a:.digits$}, {b:.digits$}]"),
        None => "-".into(),
    }
}

/// The rows as a Markdown table (intervals print as one number when they agree to the shown
/// digits).
pub fn markdown_table(rows: &[AtlasRow]) -> String {
    let Some(first) = rows.first() else {
        return String::new();
    };
    let mut head = String::from("| team | failed | ceiling (m_C g) |");
    let mut rule = String::from("|---|---|---|");
    for h in &first.heights {
        head += &format!(" ratio @{0} | sound @{0} | cons @{0} |", h.height);
        rule += "---|---|---|";
    }
    head += " s* | s* range (m_C g) | limited at (m_C g, deg) | widest bracket |";
    rule += "---|---|---|---|";
    let mut out = format!("{head}\n{rule}\n");
    for r in rows {
        let failed = if r.failed.is_empty() {
            "-".to_string()
        } else {
            r.failed
                .iter()
                .map(|i| i.to_string())
                .collect::<Vec<_>>()
                .join(",")
        };
        let ceiling = match r.ceiling {
            [Some(a), Some(b)] => interval(&Some([a, b]), 3),
            _ => "not attained".into(),
        };
        let mut line = format!("| {} | {failed} | {ceiling} |", r.team);
        if let Some(note) = &r.note {
            for _ in &first.heights {
                line += " - | - | - |";
            }
            line += &format!(" - | - | {note} | - |\n");
            out += &line;
            continue;
        }
        for h in &r.heights {
            let ratio = match (h.empty, h.ratio) {
                (true, _) => "empty".to_string(),
                (false, None) => "not attained".to_string(),
                (false, Some([a, _])) if a > 1e3 => "> 1000 (a point)".to_string(),
                (false, ratio) => interval(&ratio, 3),
            };
            line += &format!(
                " {ratio} | {} | {} |",
                interval(&h.soundness, 3),
                interval(&h.conservatism, 3)
            );
        }
        let range = r
            .certified_range
            .map_or("-".into(), |[a, b]| format!("{a:.2}-{b:.2}"));
        let limiting = r
            .limiting
            .map_or("-".into(), |[h, a]| format!("{h:.2}, {a:.0}"));
        let widest = r
            .heights
            .iter()
            .filter_map(|h| h.worst_width)
            .chain(r.certified_worst_width)
            .fold(0.0, f64::max);
        line += &format!(
            " {} | {range} | {limiting} | {:.1e} |",
            interval(&r.certified, 3),
            widest
        );
        out += &line;
        out.push('\n');
    }
    out
}
