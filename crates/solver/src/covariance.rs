//! Covariance of the six parameters as the inverse of the Fisher information
//! `F = Σ GᵀWG` (the Cramér–Rao bound at the estimate), computed in scaled form so
//! that parameters of very different sizes (radii, metres, radians) do not spoil it.

use crate::linalg::{symmetric_eigen_sorted, unit_diagonal};
use nalgebra::SMatrix;

/// Smallest eigenvalue, relative to the largest, of the unit-diagonal information
/// matrix below which a direction counts as not excited at all.
pub const INFORMATION_SINGULAR_RATIO: f64 = 1e-13;

/// Outcome of inverting a Fisher information matrix.
#[derive(Debug, Clone)]
pub(crate) enum Inversion {
    /// The covariance `F⁻¹`.
    Covariance(Box<[[f64; 6]; 6]>),
    /// `F` is singular: these unit vectors (in parameter space, scaled to unit
    /// diagonal) carry no information.
    Singular(Vec<[f64; 6]>),
}

/// Inverts the 6×6 information matrix, or finds its null directions.
pub(crate) fn invert_information(f: &[[f64; 6]; 6]) -> Inversion {
    let m = SMatrix::<f64, 6, 6>::from_fn(|i, j| f[i][j]);
    if m.iter().any(|v| !v.is_finite()) {
        return Inversion::Singular(Vec::new());
    }
    let (scaled, s) = unit_diagonal(&m);
    let mut null = Vec::new();
    for (i, &si) in s.iter().enumerate() {
        if si == 0.0 {
            let mut e = [0.0; 6];
            e[i] = 1.0;
            null.push(e);
        }
    }
    if !null.is_empty() {
        return Inversion::Singular(null);
    }
    let (values, vectors) = symmetric_eigen_sorted(&scaled);
    let max = values[5];
    for (v, vec) in values.iter().zip(&vectors) {
        if v.is_nan() || *v <= INFORMATION_SINGULAR_RATIO * max {
            let mut e = [0.0; 6];
            e.copy_from_slice(vec);
            null.push(e);
        }
    }
    if !null.is_empty() {
        return Inversion::Singular(null);
    }
    let mut cov = [[0.0; 6]; 6];
    for (i, row) in cov.iter_mut().enumerate() {
        for (j, c) in row.iter_mut().enumerate() {
            let mut acc = 0.0;
            for (v, vec) in values.iter().zip(&vectors) {
                acc += vec[i] * vec[j] / v;
            }
            *c = acc * s[i] * s[j];
        }
    }
    Inversion::Covariance(Box::new(cov))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inverse_of_badly_scaled_matrix() {
        let scales = [1e-2, 2e-2, 1e-1, 1.0, 3.0, 1e3];
        let mut f = [[0.0; 6]; 6];
        for i in 0..6 {
            for j in 0..6 {
                let base = if i == j {
                    2.0
                } else {
                    0.3 / (1.0 + (i as f64 - j as f64).abs())
                };
                f[i][j] = base / (scales[i] * scales[j]);
            }
        }
        let Inversion::Covariance(c) = invert_information(&f) else {
            panic!("singular")
        };
        for i in 0..6 {
            for j in 0..6 {
                let p: f64 = (0..6).map(|k| f[i][k] * c[k][j]).sum();
                let want = if i == j { 1.0 } else { 0.0 };
                assert!((p - want).abs() < 1e-10, "{i},{j}: {p}");
            }
        }
    }

    #[test]
    fn singular_direction_is_found() {
        let mut f = [[0.0; 6]; 6];
        for i in 0..6 {
            f[i][i] = 1.0;
        }
        // Parameters 0 and 1 only seen through their sum.
        f[0][1] = 1.0;
        f[1][0] = 1.0;
        let Inversion::Singular(null) = invert_information(&f) else {
            panic!("should be singular")
        };
        assert_eq!(null.len(), 1);
        assert!((null[0][0] + null[0][1]).abs() < 1e-12 && null[0][0].abs() > 0.7);
    }
}
