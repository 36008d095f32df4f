//! Eigen-decomposition of a symmetric 3×3 matrix: cyclic Jacobi rotations in `f64`.
//!
//! The matrix is first divided by its largest entry, so the iteration sees entries in
//! `[-1, 1]` whatever the scale of the points. Each rotation zeroes one off-diagonal entry
//! and keeps the matrix symmetric; the off-diagonal mass falls quadratically after the first
//! sweep, so a handful of sweeps reach `f64` precision and [`MAX_SWEEPS`] bounds the work
//! on any input. Degenerate spectra (planar or collinear points, repeated or zero
//! eigenvalues) need no special case: the rotations stay orthogonal, so the eigenvectors of
//! a repeated eigenvalue are some orthonormal basis of its eigenspace.

use crate::num::hypot;
use glam::DMat3;

/// The cap on Jacobi sweeps (3 rotations each); convergence takes about 5.
const MAX_SWEEPS: usize = 32;

/// Eigenvalues in descending order and their eigenvectors as the columns of a rotation.
#[derive(Clone, Copy, Debug)]
pub(crate) struct SymmetricEigen {
    /// `λ0 >= λ1 >= λ2` (the fits need only the vectors; the tests check both).
    #[cfg_attr(not(test), allow(dead_code))]
    pub values: [f64; 3],
    /// Orthonormal, right-handed: column `k` belongs to `values[k]`.
    pub vectors: DMat3,
}

/// The eigenvalues and eigenvectors of a symmetric `m` (only its upper triangle is read).
pub(crate) fn symmetric_eigen(m: DMat3) -> SymmetricEigen {
    let scale = m.to_cols_array().iter().fold(0.0f64, |s, x| s.max(x.abs()));
    if !(scale > 0.0 && scale.is_finite()) {
        return SymmetricEigen {
            values: [0.0; 3],
            vectors: DMat3::IDENTITY,
        };
    }
    let mut a = symmetrized(m * (1.0 / scale));
    let mut v = DMat3::IDENTITY;
    for _ in 0..MAX_SWEEPS {
        if off_diagonal(&a) <= f64::EPSILON * f64::EPSILON * diagonal(&a) {
            break;
        }
        for (p, q) in [(0, 1), (0, 2), (1, 2)] {
            let j = jacobi_rotation(&a, p, q);
            a = symmetrized(j.transpose() * a * j);
            v *= j;
        }
    }
    sorted(a, v, scale)
}

/// `(m + mᵀ) / 2`: removes the asymmetry rounding leaves after each rotation.
fn symmetrized(m: DMat3) -> DMat3 {
    (m + m.transpose()) * 0.5
}

/// The sum of squares of the off-diagonal entries above the diagonal.
fn off_diagonal(a: &DMat3) -> f64 {
    a.y_axis.x * a.y_axis.x + a.z_axis.x * a.z_axis.x + a.z_axis.y * a.z_axis.y
}

/// The sum of squares of the diagonal entries.
fn diagonal(a: &DMat3) -> f64 {
    a.x_axis.x * a.x_axis.x + a.y_axis.y * a.y_axis.y + a.z_axis.z * a.z_axis.z
}

/// The plane rotation `J` in `(p, q)` with `(Jᵀ a J)_pq = 0` (Golub & Van Loan 8.5.2):
/// `θ = (a_qq − a_pp) / 2a_pq`, `t = sign(θ) / (|θ| + √(θ² + 1))` the smaller root of
/// `t² + 2θt − 1 = 0`, so the rotation angle is at most π/4; `c = 1/√(t² + 1)`, `s = t·c`.
fn jacobi_rotation(a: &DMat3, p: usize, q: usize) -> DMat3 {
    let apq = a.col(q)[p];
    let mut j = DMat3::IDENTITY;
    if apq == 0.0 {
        return j;
    }
    let theta = (a.col(q)[q] - a.col(p)[p]) / (2.0 * apq);
    let t = theta.signum() / (theta.abs() + hypot(theta, 1.0));
    let c = 1.0 / hypot(t, 1.0);
    let s = t * c;
    j.col_mut(p)[p] = c;
    j.col_mut(q)[q] = c;
    j.col_mut(q)[p] = s;
    j.col_mut(p)[q] = -s;
    j
}

/// Eigenpairs sorted by descending eigenvalue, rescaled, the vectors re-orthonormalised
/// (Gram–Schmidt) and made right-handed (`v2 = v0 × v1`).
fn sorted(a: DMat3, v: DMat3, scale: f64) -> SymmetricEigen {
    let mut order = [0usize, 1, 2];
    order.sort_by(|&i, &k| a.col(k)[k].total_cmp(&a.col(i)[i]));
    let values = order.map(|k| a.col(k)[k] * scale);
    let v0 = v.col(order[0]).normalize();
    let v1 = (v.col(order[1]) - v0 * v0.dot(v.col(order[1]))).normalize();
    SymmetricEigen {
        values,
        vectors: DMat3::from_cols(v0, v1, v0.cross(v1)),
    }
}

/// The principal axes of the covariance `c`, largest variance first.
pub(crate) fn principal_axes(c: DMat3) -> DMat3 {
    symmetric_eigen(c).vectors
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    fn check(m: DMat3) -> SymmetricEigen {
        let e = symmetric_eigen(m);
        let d = DMat3::from_diagonal(DVec3::from_array(e.values));
        let back = e.vectors * d * e.vectors.transpose();
        let norm = m.to_cols_array().iter().fold(0.0f64, |s, x| s.max(x.abs()));
        for (x, y) in back.to_cols_array().iter().zip(m.to_cols_array()) {
            assert!(
                (x - y).abs() <= 1e-13 * norm.max(f64::MIN_POSITIVE),
                "{m} -> {back}"
            );
        }
        let gram = e.vectors.transpose() * e.vectors;
        assert!(gram.abs_diff_eq(DMat3::IDENTITY, 1e-14));
        assert!(e.vectors.determinant() > 0.0);
        assert!(e.values[0] >= e.values[1] && e.values[1] >= e.values[2]);
        e
    }

    #[test]
    fn reconstructs_degenerate_spectra() {
        let r = DMat3::from_euler(glam::EulerRot::XYZ, 0.3, -1.1, 2.0);
        for diag in [
            [3.0, 2.0, 1.0],
            [1.0, 1.0, 1.0],
            [2.0, 2.0, 0.0],
            [5.0, 0.0, 0.0],
            [0.0, 0.0, 0.0],
            [1e-30, 1e-31, 0.0],
            [1e30, 1e30, 1.0],
            [1.0, 1.0 + 1e-15, 1.0 - 1e-15],
        ] {
            let e = check(r * DMat3::from_diagonal(DVec3::from_array(diag)) * r.transpose());
            let mut want = diag;
            want.sort_by(|a, b| b.total_cmp(a));
            for (got, want) in e.values.iter().zip(want) {
                assert!((got - want).abs() <= 1e-13 * want.abs().max(diag[0]));
            }
        }
    }

    /// Eigenvalues scale with the matrix and turn with it: checked to 1e-5 relative for
    /// scales 1e-4..1e4 and a rotation, on distinct, repeated and degenerate spectra.
    #[test]
    fn invariant_under_scale_and_rotation() {
        let base = DMat3::from_cols_array(&[4.0, 1.0, 0.5, 1.0, 3.0, 0.2, 0.5, 0.2, 1.0]);
        let planar = DMat3::from_cols_array(&[2.0, 1.0, 0.0, 1.0, 2.0, 0.0, 0.0, 0.0, 0.0]);
        let r = DMat3::from_euler(glam::EulerRot::ZYX, 1.0, 0.4, -2.2);
        for m in [base, planar, DMat3::IDENTITY] {
            let reference = symmetric_eigen(m);
            for scale in [1e-4, 0.3, 1.0, 7.0, 1e4] {
                let e = check(r * (m * scale) * r.transpose());
                for k in 0..3 {
                    let want = reference.values[k] * scale;
                    assert!((e.values[k] - want).abs() <= 1e-5 * reference.values[0] * scale);
                    // A distinct eigenvalue's vector turns with the matrix (up to sign).
                    let distinct = (0..3).all(|j| {
                        j == k || (reference.values[j] - reference.values[k]).abs() > 1e-3
                    });
                    if distinct {
                        let turned = r * reference.vectors.col(k);
                        assert!(turned.dot(e.vectors.col(k)).abs() >= 1.0 - 1e-10);
                    }
                }
            }
        }
    }
}
