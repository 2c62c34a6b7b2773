//! Step 2 of the closed form: `b` and `ℓ` from the constraint `ℓ ⊕ ŝ = o ⊕ ℓ`,
//! minimising `xᵀMx` over `x = [b, ℓx, ℓy, cos ℓθ, sin ℓθ]` with `x4² + x5² = 1`
//! through the Schur complement of the 3×3 block `A` of `M`.

use crate::kinematics::{odometry_raw, pieces, RawOdometry};
use crate::linalg::{
    condition_from_eigenvalues, symmetric_eigen2, symmetric_eigen_sorted, unit_diagonal,
};
use crate::sample::Sample;
use nalgebra::{Matrix2, Matrix3, Matrix3x2, Vector2};
use odocal_geom::Pose2;
use serde::Serialize;

/// Result of step 2.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Step2 {
    /// Wheel distance `b` (m), positive.
    pub b: f64,
    /// Sensor pose ℓ.
    pub laser: Pose2,
    /// Condition number of the block `A` of `M` (rows/columns `b`, `ℓx`, `ℓy`).
    pub a_condition: f64,
    /// Condition number of `A` after scaling its diagonal to one (independent of the
    /// units and of the size of the motions; measures collinearity only).
    pub a_condition_scaled: f64,
    /// Direction of `(b, ℓx, ℓy)` the data excite least (unit eigenvector of the
    /// scaled `A` for its smallest eigenvalue).
    pub a_weakest_direction: [f64; 3],
    /// Smallest eigenvalue of the Schur complement (the minimum of `xᵀMx`).
    pub residual: f64,
}

/// Scaled condition number of `A` above which `b`, `ℓx`, `ℓy` are treated as not
/// excited by step 2 (the Schur solution would be numerically meaningless).
pub const A_SINGULAR_CONDITION: f64 = 1e12;

/// Builds `M` over `active` for the given `J21`, `J22` and returns it with the
/// per-sample odometry for `b = 1` (`c_x`, `c_y`, `oθ`; same order as `active`), so
/// that the robot displacement is `(b·c_x, b·c_y, oθ)`.
pub(crate) fn build_m(
    samples: &[Sample],
    active: &[usize],
    j21: f64,
    j22: f64,
    use_profile: bool,
) -> ([[f64; 5]; 5], Vec<RawOdometry>) {
    let mut m = [[0.0; 5]; 5];
    let mut unit = Vec::with_capacity(active.len());
    for &k in active {
        let s = &samples[k];
        let o = odometry_raw(-j21, j22, 1.0, pieces(s, use_profile));
        unit.push(o);
        let (sn, omc) = (o.sin, o.one_minus_cos());
        let (sx, sy) = (s.sm.x, s.sm.y);
        let r1 = [-o.x, omc, sn, sx, -sy];
        let r2 = [-o.y, -sn, omc, sy, sx];
        for i in 0..5 {
            for j in i..5 {
                m[i][j] += r1[i] * r1[j] + r2[i] * r2[j];
            }
        }
    }
    for i in 0..5 {
        for j in 0..i {
            m[i][j] = m[j][i];
        }
    }
    (m, unit)
}

/// Minimises `xᵀMx` subject to `x4² + x5² = 1`, `x1 > 0`. Returns `None` only
/// when `A` is not positive definite at all; ill-conditioning is reported in the
/// result's condition numbers.
pub fn solve_m(m: &[[f64; 5]; 5]) -> Option<Step2> {
    let a = Matrix3::from_fn(|i, j| m[i][j]);
    let bm = Matrix3x2::from_fn(|i, j| m[i][j + 3]);
    let c = Matrix2::from_fn(|i, j| m[i + 3][j + 3]);

    let (a_scaled, scale) = unit_diagonal(&a);
    let (raw_eigs, _) = symmetric_eigen_sorted(&a);
    let (scaled_eigs, scaled_vecs) = symmetric_eigen_sorted(&a_scaled);
    let a_condition = condition_from_eigenvalues(&raw_eigs);
    let a_condition_scaled = condition_from_eigenvalues(&scaled_eigs);
    let a_weakest_direction = [scaled_vecs[0][0], scaled_vecs[0][1], scaled_vecs[0][2]];
    if scale.contains(&0.0) {
        return None;
    }
    // A⁻¹B = D (D A D)⁻¹ D B with D = diag(scale).
    let d = Matrix3::from_diagonal(&nalgebra::Vector3::from(scale));
    let chol = a_scaled.cholesky()?;
    let a_inv_b = d * chol.solve(&(d * bm));
    let s = c - bm.transpose() * a_inv_b;
    let (eigs, vecs) = symmetric_eigen2([[s[(0, 0)], s[(0, 1)]], [s[(1, 0)], s[(1, 1)]]]);
    let xb = Vector2::new(vecs[0][0], vecs[0][1]);
    let mut xa = -(a_inv_b * xb);
    let mut xb = xb;
    if xa[0] < 0.0 {
        xa = -xa;
        xb = -xb;
    }
    if !(xa.iter().all(|v| v.is_finite()) && xb.iter().all(|v| v.is_finite())) {
        return None;
    }
    Some(Step2 {
        b: xa[0],
        laser: Pose2::new(xa[1], xa[2], xb[1].atan2(xb[0])),
        a_condition,
        a_condition_scaled,
        a_weakest_direction,
        residual: eigs[0],
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kinematics::Predictor;
    use crate::params::Params;

    #[test]
    fn recovers_b_and_laser_on_exact_data() {
        let truth = Params {
            r_l: 0.05,
            r_r: 0.052,
            b: 0.4,
            laser: Pose2::new(0.2, -0.1, -3.0),
        };
        let pred = Predictor::new(&truth, true);
        let samples: Vec<Sample> = [(1.0, 2.0), (-1.0, 1.0), (3.0, 3.0), (0.5, -0.2), (2.0, 1.0)]
            .iter()
            .map(|&(l, r)| {
                let s = Sample::from_rotations(1.0, l, r, Pose2::IDENTITY);
                Sample {
                    sm: Pose2::from_array(pred.predict(&s)),
                    ..s
                }
            })
            .collect();
        let idx: Vec<usize> = (0..samples.len()).collect();
        let j = truth.j();
        let (m, _) = build_m(&samples, &idx, j[1][0], j[1][1], true);
        let s2 = solve_m(&m).unwrap();
        assert!((s2.b - truth.b).abs() < 1e-12);
        assert!((s2.laser.x - truth.laser.x).abs() < 1e-12);
        assert!((s2.laser.y - truth.laser.y).abs() < 1e-12);
        assert!((s2.laser.theta - truth.laser.theta).abs() < 1e-12);
        let trace: f64 = (0..5).map(|i| m[i][i]).sum();
        assert!(s2.residual.abs() < 1e-12 * trace);
    }
}
