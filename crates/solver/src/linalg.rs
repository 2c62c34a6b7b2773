//! Small dense linear-algebra helpers (symmetric eigenvalues, condition numbers,
//! scaled inverses) built on nalgebra.

use nalgebra::{DMatrix, Matrix3, SMatrix};

/// Inverse of a symmetric positive definite 3×3 covariance, or `None` when it is
/// not symmetric (to 1e-9 relative) or not positive definite.
pub(crate) fn information_from_covariance(cov: &[[f64; 3]; 3]) -> Option<[[f64; 3]; 3]> {
    let m = Matrix3::from_fn(|i, j| cov[i][j]);
    let scale = m.abs().max();
    if scale.is_nan() || scale <= 0.0 || (m - m.transpose()).abs().max() > 1e-9 * scale {
        return None;
    }
    let inv = m.cholesky()?.inverse();
    let mut out = [[0.0; 3]; 3];
    for (i, row) in out.iter_mut().enumerate() {
        for (j, v) in row.iter_mut().enumerate() {
            *v = 0.5 * (inv[(i, j)] + inv[(j, i)]);
        }
    }
    Some(out)
}

/// Eigenvalues (ascending) and unit eigenvectors of a symmetric 2×2 matrix.
pub(crate) fn symmetric_eigen2(m: [[f64; 2]; 2]) -> ([f64; 2], [[f64; 2]; 2]) {
    let (a, b, d) = (m[0][0], 0.5 * (m[0][1] + m[1][0]), m[1][1]);
    let mean = 0.5 * (a + d);
    let radius = (0.25 * (a - d) * (a - d) + b * b).sqrt();
    let (lo, hi) = (mean - radius, mean + radius);
    // Eigenvector of the larger eigenvalue, from the better-conditioned row.
    let v_hi = if a >= d {
        normalize2([hi - d, b])
    } else {
        normalize2([b, hi - a])
    };
    let v_hi = if v_hi[0] == 0.0 && v_hi[1] == 0.0 {
        [1.0, 0.0]
    } else {
        v_hi
    };
    let v_lo = [-v_hi[1], v_hi[0]];
    ([lo, hi], [v_lo, v_hi])
}

fn normalize2(v: [f64; 2]) -> [f64; 2] {
    let n = v[0].hypot(v[1]);
    if n > 0.0 {
        [v[0] / n, v[1] / n]
    } else {
        [0.0, 0.0]
    }
}

/// Ratio of the largest to the smallest eigenvalue of a symmetric positive
/// semi-definite matrix (∞ when the smallest is not positive).
pub(crate) fn condition_from_eigenvalues(eigs: &[f64]) -> f64 {
    let max = eigs.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
    let min = eigs.iter().cloned().fold(f64::INFINITY, f64::min);
    if min > 0.0 && max.is_finite() {
        max / min
    } else {
        f64::INFINITY
    }
}

/// The matrix with its diagonal scaled to one (`D^{-1/2} M D^{-1/2}`), and the
/// scale factors `D^{-1/2}`; zero diagonal entries get a factor of zero.
pub(crate) fn unit_diagonal<const N: usize>(
    m: &SMatrix<f64, N, N>,
) -> (SMatrix<f64, N, N>, [f64; N]) {
    let mut s = [0.0; N];
    for (i, si) in s.iter_mut().enumerate() {
        let d = m[(i, i)];
        *si = if d > 0.0 { 1.0 / d.sqrt() } else { 0.0 };
    }
    (
        SMatrix::<f64, N, N>::from_fn(|i, j| m[(i, j)] * s[i] * s[j]),
        s,
    )
}

/// Eigen-decomposition of a symmetric matrix: eigenvalues ascending, with their
/// eigenvectors as columns in the same order.
pub(crate) fn symmetric_eigen_sorted<const N: usize>(
    m: &SMatrix<f64, N, N>,
) -> (Vec<f64>, Vec<Vec<f64>>) {
    let dm = DMatrix::from_fn(N, N, |i, j| 0.5 * (m[(i, j)] + m[(j, i)]));
    let eig = dm.symmetric_eigen();
    let mut order: Vec<usize> = (0..N).collect();
    order.sort_by(|&a, &b| eig.eigenvalues[a].total_cmp(&eig.eigenvalues[b]));
    let values = order.iter().map(|&k| eig.eigenvalues[k]).collect();
    let vectors = order
        .iter()
        .map(|&k| (0..N).map(|i| eig.eigenvectors[(i, k)]).collect())
        .collect();
    (values, vectors)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn eigen2_reconstructs() {
        for m in [
            [[2.0, 1.0], [1.0, 3.0]],
            [[1.0, 0.0], [0.0, 1.0]],
            [[5.0, -2.0], [-2.0, 0.5]],
            [[1.0, 1.0], [1.0, 1.0]],
        ] {
            let (l, v) = symmetric_eigen2(m);
            assert!(l[0] <= l[1]);
            for k in 0..2 {
                for i in 0..2 {
                    let mv = m[i][0] * v[k][0] + m[i][1] * v[k][1];
                    assert!((mv - l[k] * v[k][i]).abs() < 1e-12, "{m:?}");
                }
            }
        }
    }

    #[test]
    fn covariance_inverse() {
        let cov = [[4.0, 1.0, 0.0], [1.0, 2.0, 0.0], [0.0, 0.0, 1.0]];
        let inf = information_from_covariance(&cov).unwrap();
        for i in 0..3 {
            for j in 0..3 {
                let p: f64 = (0..3).map(|k| cov[i][k] * inf[k][j]).sum();
                assert!((p - if i == j { 1.0 } else { 0.0 }).abs() < 1e-12);
            }
        }
        let asym = [[4.0, 1.0, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 1.0]];
        assert!(information_from_covariance(&asym).is_none());
    }
}
