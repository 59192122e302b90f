//! Constraint geometry of one agent: the admissible set `E_f` as linear rows and second-order
//! cones on its force (see [`super::ClarabelAllocator`], "Why the constraints lie inside").

use super::settings::{ACTIVE_TOL, FEASIBLE_TOL, MAX_TAN_ANGLE};
use crate::agent::admissible::AdmissibleSet;
use crate::foundation::real::{to_f64, Real};

/// One side of the `eta_x` window.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum XBound {
    /// The linear row with `tan` of the bound (window side containing zero).
    Tan(f64),
    /// The cone `||f|| <= s f_y` (`s = -1 / sin(bound)` for the upper side, `1 / sin` for the
    /// lower side, always with the sign that makes it a cone on `f_y` or `-f_y`).
    Cone(f64),
}

impl XBound {
    pub(super) fn is_cone(self) -> bool {
        matches!(self, Self::Cone(_))
    }
}

/// One agent's constraint data in `f64`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Bounds {
    pub(super) tan_y_lo: f64,
    pub(super) tan_y_hi: f64,
    /// `eta_x <= hi_x`.
    pub(super) x_hi: XBound,
    /// `eta_x >= lo_x`.
    pub(super) x_lo: XBound,
    pub(super) thrust_lo: f64,
    pub(super) thrust_hi: f64,
    /// Linearized at a force `f0` ([`super::SequentialConvexAllocator`]): the linear `eta_x`
    /// rows use `axis . (f_x, f_z)` and the minimum-thrust row `lift . f` in place of `f_z`.
    pub(super) tilted: bool,
    /// Unit direction in the `x z` plane (`[0, 1]`, that is `f_z`, unless tilted).
    pub(super) axis: [f64; 2],
    /// Unit normal of the minimum-thrust row (`[0, 0, 1]` unless tilted).
    pub(super) lift: [f64; 3],
}

impl Bounds {
    pub(super) fn new<T: Real>(set: &AdmissibleSet<T>) -> Option<Self> {
        let capped = |a: T| to_f64(a).clamp(-MAX_TAN_ANGLE, MAX_TAN_ANGLE);
        let (lo_x, hi_x) = (capped(set.eta_x().lo), capped(set.eta_x().hi));
        let (lo_y, hi_y) = (capped(set.eta_y().lo), capped(set.eta_y().hi));
        let bounds = Self {
            tan_y_lo: lo_y.tan(),
            tan_y_hi: hi_y.tan(),
            // eta_x <= hi < 0: -f_y <= sin(hi) ||f||, i.e. ||f|| <= f_y / |sin hi|.
            x_hi: if hi_x >= 0.0 {
                XBound::Tan(hi_x.tan())
            } else {
                XBound::Cone(-1.0 / hi_x.sin())
            },
            // eta_x >= lo > 0: -f_y >= sin(lo) ||f||, i.e. ||f|| <= -f_y / sin lo.
            x_lo: if lo_x <= 0.0 {
                XBound::Tan(lo_x.tan())
            } else {
                XBound::Cone(1.0 / lo_x.sin())
            },
            thrust_lo: to_f64(set.thrust().lo).max(0.0),
            thrust_hi: to_f64(set.thrust().hi),
            tilted: false,
            axis: [0.0, 1.0],
            lift: [0.0, 0.0, 1.0],
        };
        let finite = [
            bounds.tan_y_lo,
            bounds.tan_y_hi,
            bounds.thrust_lo,
            bounds.thrust_hi,
            match bounds.x_hi {
                XBound::Tan(v) | XBound::Cone(v) => v,
            },
            match bounds.x_lo {
                XBound::Tan(v) | XBound::Cone(v) => v,
            },
        ]
        .iter()
        .all(|v| v.is_finite());
        finite.then_some(bounds)
    }

    pub(super) fn shape(&self) -> Shape {
        Shape {
            x_hi_cone: self.x_hi.is_cone(),
            x_lo_cone: self.x_lo.is_cone(),
            tilted: self.tilted,
        }
    }

    /// Every constraint's slack at `f` (negative: violated), in the order of the rows.
    pub(super) fn slacks(&self, [fx, fy, fz]: [f64; 3]) -> [f64; 6] {
        let norm = (fx * fx + fy * fy + fz * fz).sqrt();
        let (along, lifted) = if self.tilted {
            let ([ax, az], [hx, hy, hz]) = (self.axis, self.lift);
            (ax * fx + az * fz, hx * fx + hy * fy + hz * fz)
        } else {
            (fz, fz)
        };
        [
            self.tan_y_hi * fz - fx,
            fx - self.tan_y_lo * fz,
            match self.x_hi {
                XBound::Tan(t) => t * along + fy,
                XBound::Cone(s) => s * fy - norm,
            },
            match self.x_lo {
                XBound::Tan(t) => -fy - t * along,
                XBound::Cone(s) => -s * fy - norm,
            },
            lifted - self.thrust_lo,
            self.thrust_hi - norm,
        ]
    }

    /// Whether a constraint is active at `f` within [`ACTIVE_TOL`] (of the pyramid: after
    /// [`Self::repair`], as the polish has always judged it).
    pub(super) fn active(&self, f: [f64; 3]) -> bool {
        if self.tilted {
            let tol = ACTIVE_TOL * self.thrust_hi.max(f64::MIN_POSITIVE);
            self.slacks(f).iter().any(|s| *s <= tol)
        } else {
            self.repair(f).1
        }
    }

    /// Whether `f` satisfies every constraint up to [`FEASIBLE_TOL`] of the maximum thrust.
    pub(super) fn feasible(&self, f: [f64; 3]) -> bool {
        let tol = -FEASIBLE_TOL * self.thrust_hi;
        self.slacks(f).iter().all(|s| *s >= tol)
    }

    /// The largest `t` in `[0, limit]` with `from + t (to - from)` feasible (`from` feasible), by
    /// bisection (the set is convex, so feasibility along the segment is an interval).
    pub(super) fn max_step(&self, from: [f64; 3], to: [f64; 3], limit: f64) -> f64 {
        if self.feasible(lerp(from, to, limit)) {
            return limit;
        }
        let (mut lo, mut hi) = (0.0, limit);
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if self.feasible(lerp(from, to, mid)) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        lo
    }

    /// Moves a solver solution onto the linear rows and the thrust cone (by the solver
    /// tolerance) and says whether any constraint is active within [`ACTIVE_TOL`].
    pub(super) fn repair(&self, f: [f64; 3]) -> ([f64; 3], bool) {
        let [mut fx, mut fy, mut fz] = f;
        fz = fz.max(self.thrust_lo);
        fx = fx.max(self.tan_y_lo * fz).min(self.tan_y_hi * fz);
        // -f_y <= tan(hi) f_z  <=>  f_y >= -tan(hi) f_z; -f_y >= tan(lo) f_z <=> f_y <= -tan(lo) f_z.
        if let XBound::Tan(t) = self.x_hi {
            fy = fy.max(-t * fz);
        }
        if let XBound::Tan(t) = self.x_lo {
            fy = fy.min(-t * fz);
        }
        let norm = (fx * fx + fy * fy + fz * fz).sqrt();
        if norm > self.thrust_hi && norm > 0.0 {
            let scale = self.thrust_hi / norm;
            fx *= scale;
            fy *= scale;
            fz *= scale;
        }
        let f = [fx, fy, fz];
        let tol = ACTIVE_TOL * self.thrust_hi.max(f64::MIN_POSITIVE);
        (f, self.slacks(f).iter().any(|s| *s <= tol))
    }
}

/// `a + t (b - a)`.
pub(super) fn lerp(a: [f64; 3], b: [f64; 3], t: f64) -> [f64; 3] {
    let [a0, a1, a2] = a;
    let [b0, b1, b2] = b;
    [a0 + t * (b0 - a0), a1 + t * (b1 - a1), a2 + t * (b2 - a2)]
}

/// The structural kind of one agent's constraints (which `eta_x` sides are cones).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Shape {
    pub(super) x_hi_cone: bool,
    pub(super) x_lo_cone: bool,
    /// Linearized rows (more nonzeros in `A`, same rows).
    pub(super) tilted: bool,
}

impl Shape {
    /// Rows of the nonnegative cone: two `eta_y` rows, the linear `eta_x` rows, `f_z >= T_lo`.
    pub(super) fn linear_rows(self) -> usize {
        3 + usize::from(!self.x_hi_cone) + usize::from(!self.x_lo_cone)
    }

    /// Number of 4-dimensional second-order cones: thrust, plus the `eta_x` cones.
    pub(super) fn cones(self) -> usize {
        1 + usize::from(self.x_hi_cone) + usize::from(self.x_lo_cone)
    }
}

#[cfg(test)]
pub(super) mod tests {
    #![allow(clippy::unwrap_used, clippy::indexing_slicing)]
    use super::*;
    use crate::agent::admissible::Interval;

    /// `E_f` of eq. (6) with `sigma_x = pi/6`, `sigma_y = pi/4`, `T in [0, 10]`.
    pub(in crate::allocation::clarabel) fn symmetric() -> Bounds {
        let set = AdmissibleSet::new(
            Interval::symmetric(core::f64::consts::FRAC_PI_6),
            Interval::symmetric(core::f64::consts::FRAC_PI_4),
            Interval { lo: 0.0, hi: 10.0 },
        );
        Bounds::new(&set.unwrap()).unwrap()
    }

    #[test]
    fn symmetric_set_is_the_pyramid_and_the_thrust_ball() {
        let b = symmetric();
        assert!((b.tan_y_hi - 1.0).abs() < 1e-15 && (b.tan_y_lo + 1.0).abs() < 1e-15);
        let t = core::f64::consts::FRAC_PI_6.tan();
        assert_eq!((b.x_hi, b.x_lo), (XBound::Tan(t), XBound::Tan(-t)));
        assert_eq!((b.shape().linear_rows(), b.shape().cones()), (5, 1));
        // Slacks in row order at a vertical force of 5 N.
        let s = b.slacks([0.0, 0.0, 5.0]);
        let expected = [5.0, 5.0, 5.0 * t, 5.0 * t, 5.0, 5.0];
        for (got, want) in s.iter().zip(expected) {
            assert!((got - want).abs() < 1e-12, "{s:?}");
        }
        assert!(b.feasible([0.0, 0.0, 5.0]));
        assert!(!b.feasible([6.0, 0.0, 5.0])); // eta_y beyond pi/4
        assert!(!b.feasible([0.0, 0.0, 11.0])); // thrust beyond 10 N
    }

    #[test]
    fn window_excluding_zero_becomes_a_cone() {
        let lo = 0.2_f64;
        let set = AdmissibleSet::new(
            Interval { lo, hi: 0.4 },
            Interval::symmetric(0.5),
            Interval { lo: 1.0, hi: 10.0 },
        );
        let b = Bounds::new(&set.unwrap()).unwrap();
        assert_eq!(b.x_lo, XBound::Cone(1.0 / lo.sin()));
        assert_eq!((b.shape().linear_rows(), b.shape().cones()), (4, 2));
        // eta_x = 0.3 lies inside, eta_x = 0.1 outside.
        let f = |eta_x: f64| [0.0, -5.0 * eta_x.sin(), 5.0 * eta_x.cos()];
        assert!(b.feasible(f(0.3)) && !b.feasible(f(0.1)));
    }

    #[test]
    fn repair_moves_onto_the_rows_and_flags_activity() {
        let b = symmetric();
        let (f, active) = b.repair([0.0, 0.0, 12.0]);
        assert_eq!(f, [0.0, 0.0, 10.0]);
        assert!(active);
        let (f, active) = b.repair([0.0, 0.0, 5.0]);
        assert_eq!(f, [0.0, 0.0, 5.0]);
        assert!(!active);
        let t = b.max_step([0.0, 0.0, 5.0], [0.0, 0.0, 15.0], 1.0);
        assert!((t - 0.5).abs() < 1e-12, "{t}");
        assert_eq!(lerp([0.0, 1.0, 2.0], [2.0, 3.0, 4.0], 0.5), [1.0, 2.0, 3.0]);
    }
}
