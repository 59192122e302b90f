//! Small dense solvers for the 6x6 Gram matrices, written out so the control cycle has no
//! panic path (nalgebra's decompositions keep bounds assertions that survive optimization; the
//! thumbv7em link check in `embedded/cycle-check` proves this module has none).
// Triangular solves read clearest with index loops over the fixed 6x6 arrays.
#![allow(clippy::indexing_slicing, clippy::needless_range_loop)]

use nalgebra::storage::Storage;
use nalgebra::{Dim, Matrix, Matrix3, Matrix6, Matrix6x3, SVector, Vector3, Vector6};

use crate::foundation::real::{eps, fmax, lit, sqrt, Real};

/// The torque part `u_tau` (rows 0-2) and the force part `u_f` (rows 3-5) of a wrench
/// `u = [u_tau; u_f]`, by destructuring the storage: a view's `into_owned` keeps a length
/// assertion that survives a size-optimized (`opt-level = "z"`) link.
pub(crate) fn wrench_parts<T: Real>(u: &Vector6<T>) -> (Vector3<T>, Vector3<T>) {
    let [[t0, t1, t2, f0, f1, f2]] = u.data.0;
    (Vector3::new(t0, t1, t2), Vector3::new(f0, f1, f2))
}

/// The columns of a 3x3 matrix (of a rotation: its body axes), without a length assertion
/// (see [`wrench_parts`]).
pub(crate) fn columns<T: Real>(m: &Matrix3<T>) -> [Vector3<T>; 3] {
    m.data.0.map(Vector3::from)
}

/// `||v||` without overflow or underflow (hand-written: nalgebra's `norm()` squares the
/// components, which overflows above `sqrt(MAX)` and underflows below `sqrt(MIN_POSITIVE)`).
/// The plain `sqrt(v . v)` when `v . v` lies where squaring lost nothing, else scaled by
/// `m = max |v_i|`: `m ||v / m||` (a max and a division per component, only then). Zero for
/// `v = 0`; `+inf` only when the true norm exceeds `MAX`; NaN for a non-finite `v`.
pub(crate) fn norm<T: Real, const D: usize>(v: &SVector<T, D>) -> T {
    let squared = v.norm_squared();
    if plain_is_exact(squared) {
        return sqrt(squared);
    }
    let m = max_abs(v);
    if m == T::zero() {
        return m;
    }
    // Divided, not multiplied by `1 / m`, which overflows for a subnormal `m`.
    (v / m).euclidean_norm() * m
}

/// `||v||` in the same bits as nalgebra's `norm()` (the root of `norm_squared()`), the root
/// taken by [`sqrt`]: the FPU's on a hard-float Arm target, where nalgebra's is software.
pub(crate) trait EuclideanNorm<T> {
    /// `sqrt(sum v_i^2)`, unscaled (it overflows as nalgebra's `norm` does; see [`norm`]).
    fn euclidean_norm(&self) -> T;
}

impl<T: Real, R: Dim, C: Dim, S: Storage<T, R, C>> EuclideanNorm<T> for Matrix<T, R, C, S> {
    #[inline]
    fn euclidean_norm(&self) -> T {
        sqrt(self.norm_squared())
    }
}

/// `v / ||v||` through [`norm`]'s scaling (zero for `v = 0`, NaN for a non-finite `v`).
pub(crate) fn normalize<T: Real, const D: usize>(v: &SVector<T, D>) -> SVector<T, D> {
    let squared = v.norm_squared();
    if plain_is_exact(squared) {
        return v / sqrt(squared);
    }
    let m = max_abs(v);
    if m == T::zero() {
        return *v;
    }
    let u = v / m;
    u / u.euclidean_norm()
}

/// `v` scaled onto the ball `||v|| <= bound` when it lies outside (its direction kept); zero
/// for a non-finite `v` or a non-finite norm, so the result is always finite for a finite
/// `bound >= 0`. The one clamp of the offset-free state and the planned rates.
pub(crate) fn clamp_norm<T: Real, const D: usize>(v: &SVector<T, D>, bound: T) -> SVector<T, D> {
    let n = norm(v);
    if !n.is_finite() {
        return SVector::zeros();
    }
    if n <= bound {
        return *v;
    }
    // `bound / n < 1`; the product cannot overflow.
    v * (bound / n)
}

/// Whether a sum of squares `s` is finite and at least `MIN_POSITIVE / eps`: then no square
/// that matters to `sqrt(s)` to round-off was subnormal, and none overflowed.
pub(crate) fn plain_is_exact<T: Real>(s: T) -> bool {
    // `MIN_POSITIVE` of `T` (the crate's floats are `f32` or `f64`, told apart by `eps`).
    let min_positive: T = if eps::<T>() < lit(1e-10) {
        lit(f64::MIN_POSITIVE)
    } else {
        lit(f64::from(f32::MIN_POSITIVE))
    };
    let min = min_positive / eps::<T>();
    s >= min && s <= T::max_value().unwrap_or_else(T::zero)
}

/// `max |v_i|`; non-finite (the first non-finite `|v_i|`) if a component is, so callers'
/// finiteness checks see it.
pub(crate) fn max_abs<T: Real, const D: usize>(v: &SVector<T, D>) -> T {
    let mut m = T::zero();
    for x in v.iter() {
        let a = x.abs();
        if !a.is_finite() {
            return a;
        }
        // `a >= +0` and finite, `m` too: the larger by one comparison (as `T::max`).
        if a > m {
            m = a;
        }
    }
    m
}

/// `A = L D L^T` of a symmetric 6x6 matrix, without pivoting. `None` unless every pivot is
/// above `tol` (so `A` is numerically positive definite).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Ldlt<T: Real> {
    l: [[T; 6]; 6],
    d: [T; 6],
}

impl<T: Real> Ldlt<T> {
    pub(crate) fn new(a: &Matrix6<T>, tol: T) -> Option<Self> {
        let mut f = Self::zero();
        f.factor(a, tol).then_some(f)
    }

    fn zero() -> Self {
        Self {
            l: [[T::zero(); 6]; 6],
            d: [T::zero(); 6],
        }
    }

    /// [`Self::new`] into `self` (a zero factor), without moving the factor out of an
    /// `Option` (a copy of 42 floats, a fifth of a factorization on a Cortex-M4F): whether `a`
    /// is numerically positive definite.
    fn factor(&mut self, a: &Matrix6<T>, tol: T) -> bool {
        let Self { l, d } = self;
        for j in 0..6 {
            let mut dj = a[(j, j)];
            for k in 0..j {
                dj -= l[j][k] * l[j][k] * d[k];
            }
            // Written so NaN pivots fail too.
            if dj.partial_cmp(&tol) != Some(core::cmp::Ordering::Greater) {
                return false;
            }
            d[j] = dj;
            l[j][j] = T::one();
            for i in (j + 1)..6 {
                let mut s = a[(i, j)];
                for k in 0..j {
                    s -= l[i][k] * l[j][k] * d[k];
                }
                l[i][j] = s / dj;
            }
        }
        true
    }

    /// The pivots `D`.
    pub(crate) fn pivots(&self) -> &[T; 6] {
        &self.d
    }

    pub(crate) fn solve(&self, b: &Vector6<T>) -> Vector6<T> {
        let mut y = [T::zero(); 6];
        for i in 0..6 {
            let mut s = b[i];
            for k in 0..i {
                s -= self.l[i][k] * y[k];
            }
            y[i] = s;
        }
        for (yi, di) in y.iter_mut().zip(&self.d) {
            *yi /= *di;
        }
        let mut x = Vector6::zeros();
        for i in (0..6).rev() {
            let mut s = y[i];
            for k in (i + 1)..6 {
                s -= self.l[k][i] * x[k];
            }
            x[i] = s;
        }
        x
    }
}

/// `initial + sum_i B_i B_i^T / w_i`, the (weighted) Gram matrix `M W^-1 M^T` of the blocks
/// `B_i` (6x3) with weights `w_i` (`w_i = 1`: `M M^T`). The one Gram matrix of the crate:
/// [`crate::Effectiveness::weighted_gram`], the pseudo-inverses and Clarabel's least squares
/// (`initial = lambda I`) all build theirs here, in this order of additions.
pub(crate) fn weighted_gram<'a, T: Real>(
    initial: Matrix6<T>,
    blocks: impl IntoIterator<Item = (&'a Matrix6x3<T>, T)>,
) -> Matrix6<T> {
    let mut gram = initial;
    for (b, w) in blocks {
        // `B B^T / w` entry by entry as nalgebra's product computes it (`(p_0 + p_1) + p_2`,
        // `p_k = b_ik b_jk`), over the upper triangle only: the lower one has the same bits
        // (products commute), so the sum stays exactly symmetric. A unit weight divides
        // nothing (`x / 1 = x` exactly). Half the work of `b * b.transpose() / w` on a
        // Cortex-M4F, the same bits.
        let unit = w == T::one();
        for i in 0..6 {
            for j in i..6 {
                let p = b[(i, 0)] * b[(j, 0)] + b[(i, 1)] * b[(j, 1)] + b[(i, 2)] * b[(j, 2)];
                let p = if unit { p } else { p / w };
                gram[(i, j)] += p;
                if j != i {
                    gram[(j, i)] += p;
                }
            }
        }
    }
    gram
}

/// Largest diagonal entry (the scale of a Gram matrix).
pub(crate) fn max_diagonal<T: Real>(a: &Matrix6<T>) -> T {
    a.diagonal().iter().fold(T::zero(), |m, x| fmax(m, *x))
}

/// Solves `A lambda = r` for a symmetric positive semi-definite `A`: exactly when `A` is
/// definite, else with Tikhonov damping `A + delta I`, `delta = sqrt(eps) max diag(A)`
/// (damped least squares: a rank-deficient free set in the redistribution still gets the
/// nearest wrench it can make). Zero when `A = 0` or the input is not finite.
pub(crate) fn solve_gram<T: Real>(a: &Matrix6<T>, r: &Vector6<T>) -> Vector6<T> {
    // `GramSolver::new(a).solve(r)` without building the solver: the factor is solved where it
    // is made instead of moved into the enum and out (two copies of 42 floats, as much as the
    // solve itself on a Cortex-M4F). The same arithmetic, so the same bits.
    let scale = max_diagonal(a);
    if scale <= T::zero() || !scale.is_finite() {
        return Vector6::zeros();
    }
    let tol = scale * eps::<T>() * lit(1e3);
    let mut f = Ldlt::zero();
    if f.factor(a, tol) {
        return f.solve(r);
    }
    // `sqrt` is correctly rounded, as `T::sqrt`. A failed factor is overwritten entry by
    // entry (`l[i][j]`, `i >= j`, and `d` are written before they are read).
    let damped = a + Matrix6::identity() * (scale * sqrt(eps::<T>()));
    if f.factor(&damped, T::zero()) {
        f.solve(r)
    } else {
        Vector6::zeros()
    }
}

/// The factorization [`solve_gram`] uses, kept so a Gram matrix that changes only with the
/// team or its failures is factored once ([`crate::Allocator::configure`]). `repr(u8)`: the
/// tag first, checked raw by [`crate::Controller::storage_intact`].
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(u8)]
pub(crate) enum GramSolver<T: Real> {
    /// `A = L D L^T`, definite.
    Exact(Ldlt<T>),
    /// `A + delta I = L D L^T` (Tikhonov damping).
    Damped(Ldlt<T>),
    /// `A = 0`, not finite, or not factorable: every solve gives zero.
    Zero,
}

impl<T: Real> GramSolver<T> {
    /// Whether the solver at `this` has one of the three tags (its factors are numbers).
    ///
    /// # Safety
    /// `this` is aligned and points to `size_of::<Self>()` readable bytes.
    pub(crate) unsafe fn storage_intact(this: *const Self) -> bool {
        crate::foundation::stored::tag_below(this, 3)
    }

    pub(crate) fn new(a: &Matrix6<T>) -> Self {
        let scale = max_diagonal(a);
        if scale <= T::zero() || !scale.is_finite() {
            return Self::Zero;
        }
        let tol = scale * eps::<T>() * lit(1e3);
        if let Some(f) = Ldlt::new(a, tol) {
            return Self::Exact(f);
        }
        let damped = a + Matrix6::identity() * (scale * eps::<T>().sqrt());
        match Ldlt::new(&damped, T::zero()) {
            Some(f) => Self::Damped(f),
            None => Self::Zero,
        }
    }

    pub(crate) fn solve(&self, r: &Vector6<T>) -> Vector6<T> {
        match self {
            Self::Exact(f) | Self::Damped(f) => f.solve(r),
            Self::Zero => Vector6::zeros(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Matrix6x3;

    /// Blocks with entries over many magnitudes and signs (a fixed linear congruential draw).
    fn blocks<T: Real>(count: usize) -> impl Iterator<Item = Matrix6x3<T>> {
        let mut state: u64 = 0x9e37_79b9_7f4a_7c15;
        (0..count).map(move |_| {
            Matrix6x3::from_fn(|_, _| {
                state = state
                    .wrapping_mul(6_364_136_223_846_793_005)
                    .wrapping_add(1_442_695_040_888_963_407);
                let unit = (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
                lit::<T>(unit * 10f64.powi((state % 7) as i32 - 3))
            })
        })
    }

    /// The Gram matrix the crate built before: `b * b.transpose() / w` by nalgebra.
    fn reference<T: Real>(bs: &[Matrix6x3<T>], w: T) -> Matrix6<T> {
        bs.iter()
            .fold(Matrix6::zeros(), |g, b| g + b * b.transpose() / w)
    }

    fn same_bits_as_nalgebra<T: Real + Bits>() {
        let bs: [Matrix6x3<T>; 16] = core::array::from_fn({
            let mut it = blocks::<T>(16);
            move |_| it.next().unwrap_or_else(Matrix6x3::zeros)
        });
        for w in [T::one(), lit(0.37), lit(3.0)] {
            for n in [1, 3, 4, 16] {
                let slice = bs.get(..n).unwrap_or(&[]);
                let ours = weighted_gram(Matrix6::zeros(), slice.iter().map(|b| (b, w)));
                let theirs = reference(slice, w);
                assert!(
                    ours.iter()
                        .zip(theirs.iter())
                        .all(|(a, b)| a.to_bits() == b.to_bits()),
                    "n = {n}, w = {w:?}: {ours:?} against {theirs:?}"
                );
                assert_eq!(ours, ours.transpose());
            }
        }
    }

    trait Bits {
        fn to_bits(&self) -> u64;
    }
    impl Bits for f32 {
        fn to_bits(&self) -> u64 {
            u64::from(f32::to_bits(*self))
        }
    }
    impl Bits for f64 {
        fn to_bits(&self) -> u64 {
            f64::to_bits(*self)
        }
    }

    #[test]
    fn weighted_gram_has_the_bits_of_the_product() {
        same_bits_as_nalgebra::<f32>();
        same_bits_as_nalgebra::<f64>();
    }

    #[test]
    fn solve_gram_has_the_bits_of_the_solver() {
        let bs: [Matrix6x3<f32>; 4] = core::array::from_fn({
            let mut it = blocks::<f32>(4);
            move |_| it.next().unwrap_or_else(Matrix6x3::zeros)
        });
        let r = Vector6::new(1.0f32, -2.0, 0.5, 3.0, -0.25, 9.81);
        // Definite (four blocks), singular (one block: rank 3, damped) and zero.
        for n in [4, 1, 0] {
            let a = weighted_gram(
                Matrix6::zeros(),
                bs.get(..n).unwrap_or(&[]).iter().map(|b| (b, 1.0)),
            );
            let ours = solve_gram(&a, &r);
            let theirs = GramSolver::new(&a).solve(&r);
            assert_eq!(ours.map(f32::to_bits), theirs.map(f32::to_bits), "n = {n}");
            assert_eq!(ours == Vector6::zeros(), n == 0);
        }
    }
}
