//! The certified relaxation `s*`: the largest `s` whose cone (eqs. 7-8) lies inside the
//! attainable set at every height of a range and every direction of a grid.

use nalgebra::Vector3;
use std::sync::atomic::AtomicBool;
use tvmd_core::Relaxation;

use super::compare::cone_radius;
use super::model::AtlasModel;
use super::ray::Bracket;
use super::section::{cross_section_until, hover_ceiling, CrossSection, SectionQuery};

/// The cone counts as inside an attained radius up to `CERTIFY_TOLERANCE n sigma_Tf` (N): the
/// bisection's stopping width, 1e-9, plus the residual accepted as attained, 1e-10, with margin.
pub const CERTIFY_TOLERANCE: f64 = 1e-8;

/// The heights checked: `heights` values of `u_z` evenly from `from` to `to` times the hover
/// ceiling's attained (lower) value.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HeightRange {
    /// Lowest height, as a fraction of the hover ceiling.
    pub from: f64,
    /// Highest height, as a fraction of the hover ceiling.
    pub to: f64,
    /// Number of heights (at least 2).
    pub heights: usize,
}

impl Default for HeightRange {
    /// `0.1` to `0.9` of the hover ceiling, nine heights (for the paper's agents, `sigma_Tf =
    /// 2 m_i g`, a full team: `0.2` to `1.8 m_C g`).
    fn default() -> Self {
        Self {
            from: 0.1,
            to: 0.9,
            heights: 9,
        }
    }
}

/// `s*` bracketed over a grid of heights and directions.
#[derive(Clone, Debug)]
pub struct CertifiedRelaxation {
    /// Certified: for every `s <= lower` the cone's radius is at most an attained radius (plus
    /// [`CERTIFY_TOLERANCE`]` n sigma_Tf`) at every grid point: the cone is inside the attainable
    /// set there.
    pub lower: f64,
    /// For `s > upper` the cone exceeds the outer bound at some grid point (unsound there for
    /// certain); the exact grid value of `s*` is in `[lower, upper]`.
    pub upper: f64,
    /// Where `lower` is limited: `(u_z in N, angle in rad)`.
    pub limiting: (f64, f64),
    /// The hover ceiling (N), bracketed.
    pub ceiling: Bracket,
    /// The heights checked (N).
    pub heights: Vec<f64>,
    /// The sections computed, one per height.
    pub sections: Vec<CrossSection>,
}

/// The largest `s` in `(0, 1]` with the cone's radius at most `r` (0 when even a vanishing `s`
/// exceeds `r`), by bisection (`c_x`, `c_y` grow with `s`).
pub fn largest_relaxation_within(model: &AtlasModel, height: f64, angle: f64, r: f64) -> f64 {
    let radius = |s: f64| {
        Relaxation::new(s).map_or(f64::INFINITY, |s| cone_radius(&model.afs, s, height, angle))
    };
    if radius(1.0) <= r {
        return 1.0;
    }
    let (mut lo, mut hi) = (0.0, 1.0);
    for _ in 0..50 {
        let mid = 0.5 * (lo + hi);
        if radius(mid) <= r {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    lo
}

/// `s*` for `model` with the required `torque` over `range` and `directions` directions.
/// `None` when the hover ceiling (and so the range) could not be attained.
pub fn certified_relaxation(
    model: &AtlasModel,
    torque: &Vector3<f64>,
    range: &HeightRange,
    directions: usize,
) -> Option<CertifiedRelaxation> {
    certified_relaxation_until(model, torque, range, directions, None)
}

/// [`certified_relaxation`], cut short once `cancel` is set (the result is then incomplete:
/// the caller discards it).
pub fn certified_relaxation_until(
    model: &AtlasModel,
    torque: &Vector3<f64>,
    range: &HeightRange,
    directions: usize,
    cancel: Option<&AtomicBool>,
) -> Option<CertifiedRelaxation> {
    let ceiling = hover_ceiling(model, torque).bracket;
    let top = ceiling.lower?;
    let k = range.heights.max(2);
    let heights: Vec<f64> = (0..k)
        .map(|i| top * (range.from + (range.to - range.from) * i as f64 / (k - 1) as f64))
        .collect();
    // The smallest per-point s and where it is (the first such point).
    let mut lower = (f64::INFINITY, (f64::NAN, f64::NAN));
    let mut upper = 1.0_f64;
    let mut sections = Vec::with_capacity(k);
    for &height in &heights {
        let section = cross_section_until(
            model,
            &SectionQuery {
                height,
                torque: *torque,
                directions,
            },
            cancel,
        );
        for p in &section.points {
            // Attained to the inner solve's precision: where the cone is capped by the ball
            // `|u_f| <= n sigma_Tf` and the set reaches that ball too (near the ceiling), the
            // two radii agree to rounding, and no relaxation should be charged for it.
            let inner = p
                .radius
                .lower
                .map_or(0.0, |r| r + CERTIFY_TOLERANCE * model.scale());
            let s_in = largest_relaxation_within(model, height, p.angle, inner);
            if s_in < lower.0 {
                lower = (s_in, (height, p.angle));
            }
            upper = upper.min(largest_relaxation_within(
                model,
                height,
                p.angle,
                p.radius.upper,
            ));
        }
        sections.push(section);
    }
    let lower = (lower.0.min(1.0), lower.1);
    Some(CertifiedRelaxation {
        lower: lower.0,
        upper: upper.max(lower.0),
        limiting: lower.1,
        ceiling,
        heights,
        sections,
    })
}
