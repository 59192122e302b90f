//! The elliptic cone (eqs. 7-8) against the attainable set: per direction the ratio of the
//! cone's radius to the attainable radius, and the area fractions of soundness (how much of the
//! cone's cross-section is attainable) and conservatism (how much of the attainable
//! cross-section the cone covers), each as an interval from the brackets.

use tvmd_core::{AttainableForceSpace, Relaxation};

use super::section::CrossSection;

/// A closed interval `[lower, upper]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Interval {
    /// Lower end.
    pub lower: f64,
    /// Upper end.
    pub upper: f64,
}

/// The cone's radius along `angle` at height `u_z = height`: the ellipse of semi-axes
/// `c_x(u_z, s)`, `c_y(u_z, s)` capped by the ball `|u_f| <= n sigma_Tf` (eq. 7). Zero below
/// the apex.
pub fn cone_radius(
    afs: &AttainableForceSpace<f64>,
    s: Relaxation<f64>,
    height: f64,
    angle: f64,
) -> f64 {
    if height < 0.0 {
        return 0.0;
    }
    let axes = afs.semi_axes(height, s);
    let (sn, cs) = angle.sin_cos();
    let term = |u: f64, c: f64| {
        if u == 0.0 {
            0.0
        } else if c <= 0.0 {
            f64::INFINITY
        } else {
            (u / c).powi(2)
        }
    };
    let inv = term(cs, axes.c_x) + term(sn, axes.c_y);
    let ellipse = if inv == 0.0 {
        f64::INFINITY
    } else {
        1.0 / inv.sqrt()
    };
    let cap = (afs.max_force().powi(2) - height * height).max(0.0).sqrt();
    ellipse.min(cap)
}

/// The cone against one cross-section.
#[derive(Clone, Debug, PartialEq)]
pub struct ConeComparison {
    /// The relaxation `s` of the cone.
    pub relaxation: f64,
    /// Per direction of the section: `cone radius / attainable radius`, as the interval
    /// `[cone / upper, cone / lower]`.
    pub ratio: Vec<Interval>,
    /// `|cone ∩ attainable| / |cone|` (1: sound, the cone promises nothing the team cannot do).
    pub soundness: Interval,
    /// `|cone ∩ attainable| / |attainable|` (1: the cone gives away nothing).
    pub conservatism: Interval,
}

impl ConeComparison {
    /// The smallest and largest ratio over the directions, as `[min of lower, max of upper]`.
    pub fn ratio_range(&self) -> Interval {
        let lower = self
            .ratio
            .iter()
            .map(|r| r.lower)
            .fold(f64::INFINITY, f64::min);
        let upper = self.ratio.iter().map(|r| r.upper).fold(0.0, f64::max);
        Interval { lower, upper }
    }
}

/// Compares the cone at relaxation `s` with `section` (whose centre must be attained; `None`
/// otherwise). Areas come from the polar radii on the section's evenly spaced directions,
/// reading the attainable cross-section as star-shaped about its centre.
pub fn compare(
    afs: &AttainableForceSpace<f64>,
    s: Relaxation<f64>,
    section: &CrossSection,
) -> Option<ConeComparison> {
    let mut ratio = Vec::with_capacity(section.points.len());
    let (mut cone, mut att_lo, mut att_hi, mut both_lo, mut both_hi) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for p in &section.points {
        let lower = p.radius.lower?;
        let upper = p.radius.upper.max(lower);
        let rc = cone_radius(afs, s, section.query.height, p.angle);
        let div = |a: f64, b: f64| {
            if b > 0.0 {
                a / b
            } else if a > 0.0 {
                f64::INFINITY
            } else {
                1.0
            }
        };
        ratio.push(Interval {
            lower: div(rc, upper),
            upper: div(rc, lower),
        });
        cone += rc * rc;
        att_lo += lower * lower;
        att_hi += upper * upper;
        both_lo += rc.min(lower).powi(2);
        both_hi += rc.min(upper).powi(2);
    }
    let frac = |a: f64, b: f64| if b > 0.0 { (a / b).min(1.0) } else { 1.0 };
    Some(ConeComparison {
        relaxation: s.get(),
        ratio,
        soundness: Interval {
            lower: frac(both_lo, cone),
            upper: frac(both_hi, cone),
        },
        conservatism: Interval {
            lower: frac(both_lo, att_hi),
            upper: frac(both_hi, att_lo),
        },
    })
}
