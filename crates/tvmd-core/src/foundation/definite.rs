//! Whether a 3x3 matrix (an inertia or a gain) is symmetric positive (semi-)definite: the one
//! check the team, the plant and the gains share.
//!
//! The matrix is first divided by its largest entry, so the minors neither overflow nor
//! underflow for any finite input (a 3x3 determinant of entries near `1e103` would overflow
//! in f64, near `1e13` in f32).

use nalgebra::Matrix3;

use crate::foundation::real::{eps, lit, sqrt, Real};

/// `true` if `j` is finite, symmetric (to `64 eps` of its largest entry) and positive
/// semi-definite: every principal minor `>= -64 eps` after scaling (Sylvester's criterion on
/// all seven principal minors, not only the leading ones).
pub(crate) fn is_symmetric_psd<T: Real>(j: &Matrix3<T>) -> bool {
    match scaled(j) {
        Some(Scaled::Zero) => true,
        Some(Scaled::Unit(a)) => principal_minors(&a).iter().all(|m| *m >= -tolerance::<T>()),
        None => false,
    }
}

/// `true` if `j` is finite, symmetric and positive definite, judged on its correlation form
/// `C = D^-1/2 j D^-1/2` (`D = diag(j)`, every diagonal entry `> 0`): the leading principal
/// minors of `C` must exceed `8 eps`. Definiteness is invariant under this scaling, so any
/// positive diagonal matrix is accepted whatever its eigenvalue ratio (`diag(1e-2, 1, 1e2)`
/// in f32, `diag(1e-17, 1, 1)` in f64), while a dense matrix singular up to rounding is refused.
pub(crate) fn is_symmetric_pd<T: Real>(j: &Matrix3<T>) -> bool {
    let Some(Scaled::Unit(a)) = scaled(j) else {
        return false;
    };
    let d = a.diagonal();
    if !d.iter().all(|x| *x > T::zero()) {
        return false;
    }
    let inv_sqrt = d.map(|x| T::one() / sqrt(x));
    if !inv_sqrt.iter().all(|x| x.is_finite()) {
        return false;
    }
    let c = a.component_mul(&(inv_sqrt * inv_sqrt.transpose()));
    let minor2 = c.m11 * c.m22 - c.m12 * c.m12;
    let threshold = eps::<T>() * lit(8.0);
    minor2 > threshold && c.determinant() > threshold
}

fn tolerance<T: Real>() -> T {
    eps::<T>() * lit(64.0)
}

enum Scaled<T: Real> {
    Zero,
    /// Symmetric, largest entry magnitude 1.
    Unit(Matrix3<T>),
}

/// `j / max |j_ab|` if `j` is finite and symmetric; `None` otherwise.
fn scaled<T: Real>(j: &Matrix3<T>) -> Option<Scaled<T>> {
    if !j.iter().all(|x| x.is_finite()) {
        return None;
    }
    let scale = j.amax();
    if scale == T::zero() {
        return Some(Scaled::Zero);
    }
    let a = j / scale;
    if (a - a.transpose()).amax() > tolerance::<T>() {
        return None;
    }
    // Symmetrize so the minors see one matrix.
    Some(Scaled::Unit((a + a.transpose()) * lit::<T>(0.5)))
}

/// `[a11, a22, a33, |a_{12}|, |a_{13}|, |a_{23}|, det a]`.
fn principal_minors<T: Real>(a: &Matrix3<T>) -> [T; 7] {
    let minor2 = |x: T, y: T, z: T| x * y - z * z;
    [
        a.m11,
        a.m22,
        a.m33,
        minor2(a.m11, a.m22, a.m12),
        minor2(a.m11, a.m33, a.m13),
        minor2(a.m22, a.m33, a.m23),
        a.determinant(),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;

    #[test]
    fn definiteness() {
        let d = |a: f64, b: f64, c: f64| Matrix3::from_diagonal(&Vector3::new(a, b, c));
        assert!(is_symmetric_pd(&d(1.0, 2.0, 3.0)));
        assert!(is_symmetric_psd(&d(1.0, 0.0, 3.0)));
        assert!(!is_symmetric_pd(&d(1.0, 0.0, 3.0)));
        assert!(is_symmetric_psd(&Matrix3::<f64>::zeros()));
        assert!(!is_symmetric_pd(&Matrix3::<f64>::zeros()));
        assert!(!is_symmetric_psd(&d(1.0, -1.0, 1.0)));
        // Positive diagonal, indefinite: the 2x2 minor is negative.
        let indefinite = Matrix3::new(1.0, 2.0, 0.0, 2.0, 1.0, 0.0, 0.0, 0.0, 1.0);
        assert!(!is_symmetric_psd(&indefinite));
        // Not symmetric.
        let skew = Matrix3::new(1.0, 0.5, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0);
        assert!(!is_symmetric_psd(&skew) && !is_symmetric_pd(&skew));
        // Huge and tiny finite entries are judged by their ratios, not overflowed.
        assert!(is_symmetric_pd(&(d(1.0, 2.0, 3.0) * 1e300)));
        assert!(is_symmetric_pd(&(d(1.0, 2.0, 3.0) * 1e-300)));
        assert!(is_symmetric_pd(&(Matrix3::<f32>::identity() * 1e30)));
        assert!(is_symmetric_pd(&Matrix3::<f32>::from_diagonal(
            &Vector3::new(1e-6, 1.0, 1.0)
        )));
        // Positive diagonals are definite whatever their ratios (congruence-invariant test).
        assert!(is_symmetric_pd(&d(1e-17, 1.0, 1.0)));
        assert!(is_symmetric_pd(&Matrix3::<f32>::from_diagonal(
            &Vector3::new(1e-2, 1.0, 1e2)
        )));
        // Singular up to rounding: refused.
        let rank_one = Vector3::new(1.0, 2.0, 3.0) * Vector3::new(1.0, 2.0, 3.0).transpose();
        assert!(!is_symmetric_pd(&rank_one));
        assert!(!is_symmetric_pd(&(rank_one + Matrix3::identity() * 1e-17)));
        assert!(!is_symmetric_psd(&d(f64::NAN, 1.0, 1.0)));
        assert!(!is_symmetric_pd(&d(f64::INFINITY, 1.0, 1.0)));
    }
}
