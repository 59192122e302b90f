//! A test that a force is inside an admissible set by a margin, without the gimbal inverse:
//! the redistributions' per-agent `outside` test costs an `asin` and an `atan2` (about 180
//! Cortex-M4F instructions with the fast forms, more with `libm`'s), and most agents of most
//! requests are well inside.

use nalgebra::Vector3;

use crate::agent::admissible::AdmissibleSet;
use crate::foundation::real::{fmax, lit, sin_cos, sqrt, Real};

/// The bounds of one [`AdmissibleSet`] as sines and cosines (eq. 1's gimbal map, `eta_x =
/// asin(-f_y / T)`, `eta_y = atan2(f_x, f_z)`), for [`Interior::holds`].
#[derive(Clone, Copy, Debug)]
pub(crate) struct Interior<T: Real> {
    sin_x: (T, T),
    y_lo: (T, T),
    y_hi: (T, T),
    thrust_squared: (T, T),
}

impl<T: Real> Interior<T> {
    /// Margin (in sines, so at least as much in angle) and twice it on the squared thrust
    /// relative to its bounds: far above the round-off of `asin`, `atan2` and of these
    /// products (a few `eps`), so a force it holds is inside by the gimbal inverse too.
    const MARGIN: f64 = 1e-4;

    /// The test for `set` (whose angle ranges lie in `[-pi/2, pi/2]`, where `sin` is monotonic
    /// and `atan2`'s half-plane arcs do not wrap).
    pub(crate) fn new(set: &AdmissibleSet<T>) -> Self {
        let (x, y, t) = (set.eta_x(), set.eta_y(), set.thrust());
        let m: T = lit(Self::MARGIN);
        let two = T::one() + T::one();
        // A symmetric range (the usual one, from the agent's limits) takes one `sin_cos`.
        let sin_x_hi = sin_cos(x.hi).0;
        let sin_x_lo = if x.lo == -x.hi {
            -sin_x_hi
        } else {
            sin_cos(x.lo).0
        };
        let y_hi = sin_cos(y.hi);
        let y_lo = if y.lo == -y.hi {
            (-y_hi.0, y_hi.1)
        } else {
            sin_cos(y.lo)
        };
        Self {
            sin_x: (sin_x_lo + m, sin_x_hi - m),
            y_lo,
            y_hi,
            // Below a millionth of the largest thrust squared the exact test decides (a force
            // that small, or subnormal, has no accurate direction here).
            thrust_squared: (
                fmax(t.lo * t.lo * (T::one() + two * m), t.hi * t.hi * lit(1e-6)),
                t.hi * t.hi * (T::one() - two * m),
            ),
        }
    }

    /// The test of the agents' one set, when they all have the same (the usual case); `None`
    /// when they differ (rate limits), and then every agent takes the exact test.
    pub(crate) fn shared<const N: usize>(sets: &[AdmissibleSet<T>; N]) -> Option<Self> {
        sets.split_first()
            .filter(|(first, rest)| rest.iter().all(|s| s == *first))
            .map(|(first, _)| Self::new(first))
    }

    /// Whether `f` is inside the set by the margin: `T` inside its range, `-f_y / T` inside
    /// `[sin eta_x.lo, sin eta_x.hi]`, and the direction `(f_z, f_x)` inside the arc from
    /// `eta_y.lo` to `eta_y.hi` (two cross products). `false` says nothing: the caller then runs
    /// the exact test (also for a zero, tiny, huge or non-finite force).
    #[inline]
    pub(crate) fn holds(&self, f: &Vector3<T>) -> bool {
        let squared = f.norm_squared();
        // Written so a NaN (or an overflow to infinity) fails too.
        if !(squared > self.thrust_squared.0 && squared < self.thrust_squared.1) {
            return false;
        }
        let t = sqrt(squared);
        let m = t * lit::<T>(Self::MARGIN);
        let (sy, cy) = self.y_lo;
        let (sh, ch) = self.y_hi;
        -f.y >= t * self.sin_x.0
            && -f.y <= t * self.sin_x.1
            && f.x * cy - f.z * sy >= m
            && f.z * sh - f.x * ch >= m
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::indexing_slicing)]
    use super::*;
    use crate::agent::gimbal::GimbalCommand;
    use crate::agent::limits::Interval;
    use crate::team::presets;

    /// Over a dense grid of forces, around and across every boundary of asymmetric sets: a
    /// force the test holds is inside by the gimbal inverse (both forms), and the test holds
    /// most forces well inside.
    fn never_holds_an_outside_force<T: Real>() {
        let sets = [
            // The paper's limits (pi/6, pi/4, 13.734 N).
            AdmissibleSet::from_limits(&presets::paper_limits()),
            AdmissibleSet::new(
                Interval {
                    lo: lit(-0.2),
                    hi: lit(0.45),
                },
                Interval {
                    lo: lit(0.1),
                    hi: lit(1.5),
                },
                Interval {
                    lo: lit(2.0),
                    hi: lit(9.0),
                },
            )
            .unwrap(),
            AdmissibleSet::new(
                Interval {
                    lo: -T::frac_pi_2(),
                    hi: T::frac_pi_2(),
                },
                Interval {
                    lo: -T::frac_pi_2(),
                    hi: lit(-1.0),
                },
                Interval {
                    lo: T::zero(),
                    hi: lit(5.5),
                },
            )
            .unwrap(),
        ];
        for set in &sets {
            let test = Interior::new(set);
            let (mut held, mut inside) = (0, 0);
            let k = 24;
            for a in 0..=k {
                for b in 0..=2 * k {
                    for c in 0..=k {
                        let s = |i: i32, n: i32, range: f64| {
                            lit::<T>(range * (i as f64 / n as f64 - 0.5))
                        };
                        let eta_x = s(a, k, 3.2);
                        let eta_y = s(b, 2 * k, 6.4);
                        let thrust = s(c, k, 24.0) + lit(12.0);
                        let f = GimbalCommand {
                            eta_x,
                            eta_y,
                            thrust,
                        }
                        .force();
                        let exact = set.violation(&GimbalCommand::from_force(&f)) <= T::zero();
                        let fast = set.violation(&GimbalCommand::from_force_fast(&f)) <= T::zero();
                        if test.holds(&f) {
                            assert!(exact && fast, "{f:?} held, outside {set:?}");
                            held += 1;
                        }
                        // A zero force is the idle command, inside when the thrust range
                        // starts at 0; the test leaves it to the exact one.
                        inside += usize::from(exact && thrust > T::zero());
                    }
                }
            }
            assert!(held * 10 >= inside * 7, "held {held} of {inside}: {set:?}");
        }
        // Across each boundary, at offsets below, at and above the margin: the test never holds
        // a force the gimbal inverse finds outside.
        let offsets = [0.0, 1e-6, 1e-5, 9e-5, 1e-4, 1.1e-4, 2e-4, 1e-3];
        for set in &sets {
            let test = Interior::new(set);
            let (x, y, t) = (set.eta_x(), set.eta_y(), set.thrust());
            let mid = |i: Interval<T>| (i.lo + i.hi) * lit(0.5);
            for d in offsets.iter().flat_map(|d| [*d, -*d]) {
                let d: T = lit(d);
                for (eta_x, eta_y, thrust) in [
                    (x.lo + d, mid(y), mid(t)),
                    (x.hi + d, mid(y), mid(t)),
                    (mid(x), y.lo + d, mid(t)),
                    (mid(x), y.hi + d, mid(t)),
                    (mid(x), mid(y), t.lo * (T::one() + d)),
                    (mid(x), mid(y), t.hi * (T::one() + d)),
                    (x.hi + d, y.hi + d, t.hi * (T::one() + d)),
                ] {
                    let f = GimbalCommand {
                        eta_x,
                        eta_y,
                        thrust,
                    }
                    .force();
                    if test.holds(&f) {
                        let exact = set.violation(&GimbalCommand::from_force(&f)) <= T::zero();
                        let fast = set.violation(&GimbalCommand::from_force_fast(&f)) <= T::zero();
                        assert!(exact && fast, "{f:?} held, outside {set:?}");
                    }
                }
            }
        }
        // Nothing held that the exact test must see.
        let test = Interior::new(&sets[0]);
        for f in [
            Vector3::zeros(),
            Vector3::new(T::zero(), T::zero(), T::zero() / T::zero()),
            Vector3::new(T::zero(), T::zero(), T::max_value().unwrap()),
        ] {
            assert!(!test.holds(&f));
        }
    }

    #[test]
    fn holds_only_forces_inside_by_the_gimbal_inverse() {
        never_holds_an_outside_force::<f32>();
        never_holds_an_outside_force::<f64>();
    }
}
