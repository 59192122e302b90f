//! The exact boundary of one agent's admissible set `E_f` (eq. 6) in force space, written as
//! six constraints `g(f) = c . f + s ||f|| + k <= 0`, each with a closed-form first exit along a
//! ray `f + tau d`.
//!
//! With `f = T [cos eta_x sin eta_y, -sin eta_x, cos eta_x cos eta_y]` (eq. 1):
//! - `eta_x <= a` is `-f_y <= sin(a) ||f||` (a cone around the `y` axis), `eta_x >= a` is
//!   `f_y <= -sin(a) ||f||`;
//! - `eta_y <= b` is `f_x cos b - f_z sin b <= 0` (a plane through the origin: `(f_x, f_z)` is
//!   `T cos eta_x (sin eta_y, cos eta_y)` with `cos eta_x >= 0`), `eta_y >= b` its mirror;
//! - `T <= T_max` is the sphere `||f|| <= T_max`, `T >= T_min` the outside of the ball `T_min`.
//!
//! Together they are exactly the set [`AdmissibleSet::contains`] tests, without the gimbal
//! inverse (`asin`, `atan2`) in the loop.

use nalgebra::Vector3;

use crate::agent::admissible::AdmissibleSet;
use crate::agent::limits::Interval;
use crate::foundation::linalg::{max_abs, norm};
use crate::foundation::real::{eps, fmax, lit, sin_cos, sqrt, Real};

/// Number of constraints of one agent.
pub(in crate::allocation) const CONSTRAINTS: usize = 6;

/// `g(f) = c . f + s ||f|| + k <= 0`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(in crate::allocation) struct Constraint<T: Real> {
    c: Vector3<T>,
    s: T,
    k: T,
    /// `|c| + |s|`, a Lipschitz constant of `g`.
    lipschitz: T,
}

impl<T: Real> Constraint<T> {
    /// `g = 0` everywhere: a placeholder until a set's constraints are built.
    pub(super) fn placeholder() -> Self {
        Self {
            c: Vector3::zeros(),
            s: T::zero(),
            k: T::zero(),
            lipschitz: T::zero(),
        }
    }

    /// `g(f)`, overflow-safe (the norm does not square).
    pub(in crate::allocation) fn value(&self, f: &Vector3<T>) -> T {
        self.c.dot(f) + self.s * norm(f) + self.k
    }

    /// `g(f)` given `||f||`.
    pub(super) fn value_with_norm(&self, f: &Vector3<T>, norm: T) -> T {
        self.c.dot(f) + self.s * norm + self.k
    }

    /// `grad g(f) = c + s f / ||f||` (`c` at the origin, where the cones have no normal).
    #[cfg(any(test, feature = "null-space"))]
    pub(in crate::allocation) fn gradient(&self, f: &Vector3<T>) -> Vector3<T> {
        self.gradient_with_norm(f, norm(f))
    }

    /// [`Self::gradient`] given `n = ||f||` (one norm for all of an agent's constraints).
    pub(super) fn gradient_with_norm(&self, f: &Vector3<T>, n: T) -> Vector3<T> {
        if n > T::zero() {
            self.c + f * (self.s / n)
        } else {
            self.c
        }
    }

    /// Whether `g` is curved (a cone or a sphere): a step along its tangent plane leaves the
    /// boundary to second order, so the agent is retracted onto the set after it.
    pub(in crate::allocation) fn curved(&self) -> bool {
        self.s != T::zero()
    }

    /// The first `tau >= 0` at which `f + tau d` leaves `{g <= 0}`: `Some(0)` when `f` is on
    /// (or, by round-off, just beyond) the boundary and `d` points out; `None` when the ray never
    /// leaves. `f` and `d` finite. (The walk scales one ray for all six; the null-space stage
    /// asks one constraint at a time.)
    #[cfg(any(test, feature = "null-space"))]
    pub(in crate::allocation) fn first_exit(&self, f: &Vector3<T>, d: &Vector3<T>) -> Option<T> {
        Ray::new(f, d, self.k.abs())
            .and_then(|ray| self.first_exit_along(&ray, T::max_value().unwrap_or_else(T::one)))
    }

    /// [`Self::first_exit`] along a ray scaled once for all of an agent's constraints, or
    /// `None` for an exit that is certainly beyond `2 within`.
    ///
    /// Closed form: squaring `c . x + k = -s ||x||` gives a quadratic in `tau`; a root is kept
    /// when it is a root of `g` itself (`s (c . x + k) <= 0`) and `g` increases through it.
    /// The ray is scaled by the largest input component (`k` included), which leaves `tau`
    /// unchanged (`g` is homogeneous of degree one in `(f, d, k)`) and keeps the squares finite.
    pub(super) fn first_exit_along(&self, ray: &Ray<T>, within: T) -> Option<T> {
        let (f, d) = (&ray.f, &ray.d);
        let k = self.k / ray.scale;
        let tol: T = eps::<T>() * lit(64.0);
        let p = self.c.dot(f) + k;
        let q = self.c.dot(d);
        let g0 = p + self.s * ray.f_len;
        // The slope of `g` along `d` at a point `x` with `x . d` and `||x||` given.
        let slope = |x_dot_d: T, x_len: T| {
            if x_len > T::zero() {
                q + self.s * x_dot_d / x_len
            } else {
                q + self.s * ray.d_len
            }
        };
        if g0 > -tol && slope(ray.fd, ray.f_len) > tol * ray.d_len {
            return Some(T::zero());
        }
        // `g` changes by at most `(|c| + |s|) ||d||` per unit of `tau`: no exit before
        // `-g0 / ((|c| + |s|) ||d||)`. Beyond twice `within` (round-off of the roots allowed for),
        // the exit cannot be the walk's first and the quadratic is not solved.
        let slope_bound = self.lipschitz * ray.d_len;
        if -g0 > within * slope_bound * lit(2.0) {
            return None;
        }
        if !self.curved() {
            return (q > T::zero()).then(|| fmax(-p / q, T::zero()));
        }
        let s2 = self.s * self.s;
        let a = q * q - s2 * ray.dd;
        let b = p * q - s2 * ray.fd;
        let c = p * p - s2 * ray.ff;
        let mut roots = [None, None];
        if a.abs() <= tol * (q * q + s2 * ray.dd) {
            if b != T::zero() {
                roots[0] = Some(-c / (b + b));
            }
        } else {
            let disc = b * b - a * c;
            if disc < T::zero() {
                return None;
            }
            // The stable pair: no cancellation between `b` and the root of the discriminant.
            let w = -(b + sqrt(disc).copysign(b));
            roots[0] = Some(w / a);
            if w != T::zero() {
                roots[1] = Some(c / w);
            }
        }
        roots
            .into_iter()
            .flatten()
            .filter(|t| t.is_finite() && *t >= T::zero())
            .filter(|t| {
                let x = f + d * *t;
                self.s * (p + q * *t) <= T::zero() && slope(x.dot(d), sqrt(x.dot(&x))) > T::zero()
            })
            .fold(None, |best: Option<T>, t| match best {
                Some(b) if b <= t => Some(b),
                _ => Some(t),
            })
    }

    /// `f` moved onto this curved constraint's boundary without trigonometry: a sphere scales
    /// `f` to its radius; a cone (`c = +-e_y`) sets `f_y` to its value on the cone at `||f||` and
    /// scales `(f_x, f_z)` to keep `||f||`. `f` itself for a plane, at the origin, or when the
    /// result would not be finite.
    pub(super) fn retract(&self, f: &Vector3<T>) -> Vector3<T> {
        let n = norm(f);
        if !self.curved() || n <= T::zero() || !n.is_finite() {
            return *f;
        }
        let zero = T::zero();
        let out = if self.c == Vector3::zeros() {
            // `s ||f|| + k = 0`.
            f * (-self.k / self.s / n)
        } else if self.c.x == zero && self.c.z == zero && self.c.y != zero {
            // `c_y f_y + s ||f|| + k = 0`, `c_y = +-1`.
            let fy = -(self.s * n + self.k) / self.c.y;
            let side = Vector3::new(f.x, zero, f.z);
            let side_len = norm(&side);
            let rest = sqrt(fmax(n * n - fy * fy, zero));
            if side_len <= zero {
                return *f;
            }
            let mut out = side * (rest / side_len);
            out.y = fy;
            out
        } else {
            return *f;
        };
        if out.iter().all(|x| x.is_finite()) {
            out
        } else {
            *f
        }
    }

    /// `|k|`, the part of the ray's scale this constraint needs.
    pub(super) fn offset(&self) -> T {
        self.k.abs()
    }
}

/// A ray `f + tau d` scaled by its largest component (and the largest constraint offset `|k|`),
/// with the products every constraint's first exit uses, computed once per agent and round.
pub(super) struct Ray<T: Real> {
    f: Vector3<T>,
    d: Vector3<T>,
    scale: T,
    ff: T,
    dd: T,
    fd: T,
    f_len: T,
    d_len: T,
}

impl<T: Real> Ray<T> {
    /// `None` when everything is zero or a component is not finite (no exit).
    pub(super) fn new(f: &Vector3<T>, d: &Vector3<T>, offset: T) -> Option<Self> {
        let scale = fmax(fmax(max_abs(f), max_abs(d)), offset);
        if scale <= T::zero() || !scale.is_finite() {
            return None;
        }
        let (f, d) = (f / scale, d / scale);
        // Scaled to components of at most one: plain norms cannot overflow (an underflow is
        // a force at the origin, which it is to this precision).
        let (ff, dd) = (f.dot(&f), d.dot(&d));
        Some(Self {
            f,
            d,
            scale,
            ff,
            dd,
            fd: f.dot(&d),
            f_len: sqrt(ff),
            d_len: sqrt(dd),
        })
    }
}

/// `set` with `|eta_x| <= pi/2 - 1e-3`: at `|eta_x| = pi/2` the force lies on the `y` axis,
/// where `eta_y` is undefined, and near it the gimbal inverse `eta_x = asin(-f_y / T)` loses
/// `eps / cos(eta_x)` rad, which moves the force `T eps / cos(eta_x)` off the one allocated.
/// One milliradian short of the axis, every force the walk returns inverts to a command that
/// reproduces it within `1e3 eps T`, in `f32` and `f64`. (`set` itself if the narrowed ranges
/// do not make a set.)
pub(in crate::allocation) fn regular<T: Real>(set: &AdmissibleSet<T>) -> AdmissibleSet<T> {
    let cap = T::frac_pi_2() - lit(1e-3);
    let ex = set.eta_x();
    let hi = ex.hi.min(cap);
    let narrowed = Interval {
        lo: ex.lo.max(-cap).min(hi),
        hi,
    };
    AdmissibleSet::new(narrowed, set.eta_y(), set.thrust()).unwrap_or(*set)
}

/// The six constraints of `set` (a bound that can never bind, `T >= 0`, is `-T_max <= 0`:
/// never violated, never crossed, never on the boundary). The limits' sines through
/// [`sin_cos`]: `libm`'s `f32` ones run in software `f64` on a Cortex-M4F (about 2,200
/// instructions each, four per allocation); the same bits as `T::sin_cos` in `f64`.
pub(in crate::allocation) fn constraints<T: Real>(
    set: &AdmissibleSet<T>,
) -> [Constraint<T>; CONSTRAINTS] {
    let zero = T::zero();
    let y = Vector3::new(zero, T::one(), zero);
    let plane = |b: T, sign: T| {
        let (sb, cb) = sin_cos(b);
        Vector3::new(cb, zero, -sb) * sign
    };
    let ex = set.eta_x();
    let ey = set.eta_y();
    let th = set.thrust();
    let constraint = |c: Vector3<T>, s: T, k: T| Constraint {
        c,
        s,
        k,
        lipschitz: norm(&c) + s.abs(),
    };
    let never = constraint(Vector3::zeros(), zero, -th.hi.max(T::one()));
    [
        constraint(-y, -sin_cos(ex.hi).0, zero),
        constraint(y, sin_cos(ex.lo).0, zero),
        constraint(plane(ey.hi, T::one()), zero, zero),
        constraint(plane(ey.lo, -T::one()), zero, zero),
        constraint(Vector3::zeros(), T::one(), -th.hi),
        if th.lo > zero {
            constraint(Vector3::zeros(), -T::one(), th.lo)
        } else {
            never
        },
    ]
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::indexing_slicing, clippy::panic)]
    use super::*;
    use crate::agent::gimbal::GimbalCommand;

    fn set() -> AdmissibleSet<f64> {
        AdmissibleSet::new(
            Interval { lo: -0.4, hi: 0.6 },
            Interval { lo: -0.7, hi: 0.5 },
            Interval { lo: 0.5, hi: 10.0 },
        )
        .unwrap()
    }

    fn inside(f: &Vector3<f64>) -> bool {
        constraints(&set()).iter().all(|c| c.value(f) <= 1e-12)
    }

    #[test]
    fn the_constraints_describe_the_admissible_set() {
        let s = set();
        let mut checked = 0;
        for i in 0..21 {
            for j in 0..21 {
                for t in [0.2, 0.6, 3.0, 9.9, 10.1, 14.0] {
                    let cmd = GimbalCommand {
                        thrust: t,
                        eta_x: -1.5 + 0.15 * i as f64,
                        eta_y: -1.5 + 0.15 * j as f64,
                    };
                    let f = cmd.force();
                    let back = GimbalCommand::from_force(&f);
                    // Away from the boundary, where round-off cannot decide.
                    let margin = [
                        (back.eta_x - 0.6).abs(),
                        (back.eta_x + 0.4).abs(),
                        (back.eta_y - 0.5).abs(),
                        (back.eta_y + 0.7).abs(),
                        (back.thrust - 10.0).abs(),
                        (back.thrust - 0.5).abs(),
                    ];
                    if margin.iter().any(|m| *m < 1e-6) {
                        continue;
                    }
                    assert_eq!(inside(&f), s.contains(&back, 0.0), "{cmd:?}");
                    checked += 1;
                }
            }
        }
        assert!(checked > 2000, "{checked}");
    }

    #[test]
    fn first_exit_lands_on_the_boundary_and_no_earlier() {
        let s = set();
        let cs = constraints(&s);
        let start = GimbalCommand {
            thrust: 4.0,
            eta_x: 0.1,
            eta_y: -0.1,
        }
        .force();
        let mut exits = 0;
        for k in 0..200 {
            let a = k as f64 * 0.7;
            let d = Vector3::new(a.cos() * 8.0, (1.3 * a).sin() * 8.0, (0.4 * a).cos() * 6.0);
            let tau = cs
                .iter()
                .filter_map(|c| c.first_exit(&start, &d))
                .fold(f64::INFINITY, f64::min);
            assert!(tau > 0.0);
            if tau.is_finite() {
                exits += 1;
                let edge = start + d * tau;
                let worst = cs.iter().map(|c| c.value(&edge)).fold(f64::MIN, f64::max);
                assert!(worst.abs() < 1e-9, "{k}: g = {worst}");
                for frac in [0.25, 0.5, 0.9, 0.999] {
                    assert!(inside(&(start + d * tau * frac)), "{k} {frac}");
                }
                assert!(!inside(&(start + d * tau * 1.001)), "{k}");
            } else {
                for t in [0.5, 2.0, 50.0] {
                    assert!(inside(&(start + d * t)), "{k} {t}");
                }
            }
        }
        assert!(exits > 150, "{exits}");
    }

    #[test]
    fn on_the_boundary_an_outward_step_exits_at_once_and_an_inward_one_does_not() {
        let cs = constraints(&set());
        let edge = GimbalCommand {
            thrust: 10.0,
            eta_x: 0.2,
            eta_y: 0.1,
        }
        .force();
        let thrust = &cs[4];
        assert!(thrust.value(&edge).abs() < 1e-12);
        assert_eq!(thrust.first_exit(&edge, &edge), Some(0.0));
        // Inward: through the origin, out on the far side.
        assert!((thrust.first_exit(&edge, &(-edge)).unwrap() - 2.0).abs() < 1e-12);
        let cone = &cs[0];
        let on_cone = GimbalCommand {
            thrust: 3.0,
            eta_x: 0.6,
            eta_y: 0.0,
        }
        .force();
        let out = cone.gradient(&on_cone);
        assert_eq!(cone.first_exit(&on_cone, &out), Some(0.0));
        assert!(cone.first_exit(&on_cone, &(-out)).is_none_or(|t| t > 0.1));
    }

    #[test]
    fn f32_exits_agree_with_f64() {
        let s32 = AdmissibleSet::new(
            Interval {
                lo: -0.4f32,
                hi: 0.6,
            },
            Interval { lo: -0.7, hi: 0.5 },
            Interval { lo: 0.5, hi: 10.0 },
        )
        .unwrap();
        let (c32, c64) = (constraints(&s32), constraints(&set()));
        let f = Vector3::new(0.3, -0.2, 4.0);
        for k in 0..50 {
            let a = k as f64;
            let d = Vector3::new(a.sin() * 5.0, a.cos() * 5.0, (2.0 * a).sin());
            for (a32, a64) in c32.iter().zip(&c64) {
                let t64 = a64.first_exit(&f, &d);
                let t32 = a32.first_exit(&f.cast::<f32>(), &d.cast::<f32>());
                match (t32, t64) {
                    (Some(x), Some(y)) => assert!((x as f64 - y).abs() < 1e-4 * (1.0 + y)),
                    (None, None) => {}
                    other => panic!("{k}: {other:?}"),
                }
            }
        }
    }
}
