//! Step 2 of the closed form: `b` and `ℓ` from the constraint `ℓ ⊕ ŝ = o ⊕ ℓ`,
//! minimising `xᵀMx` over `x = [b, ℓx, ℓy, cos ℓθ, sin ℓθ]` with `x4² + x5² = 1`
//! through the Schur complement of the 3×3 block `A` of `M`.

use crate::kinematics::{odometry_raw, RawOdometry};
use crate::linalg::{
    condition_from_eigenvalues, symmetric_eigen2, symmetric_eigen_sorted, unit_diagonal,
};
use crate::packed::Packed;
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

/// Builds `M` over `samples` for the given `J21`, `J22` and returns it with the
/// per-sample odometry for `b = 1` (`c_x`, `c_y`, `oθ`; same order as `samples`),
/// so that the robot displacement is `(b·c_x, b·c_y, oθ)`.
pub(crate) fn build_m(
    samples: &[Packed],
    j21: f64,
    j22: f64,
    unit: &mut Vec<RawOdometry>,
) -> [[f64; 5]; 5] {
    // With r1 = [−c_x, 1−cos, sin, ŝx, −ŝy] and r2 = [−c_y, −sin, 1−cos, ŝy, ŝx],
    // r1ᵀr1 + r2ᵀr2 has M11 = M22 = 2(1 − cos), M12 = M34 = 0, M33 = M44; the other
    // entries are the eleven sums below.
    let mut sum = [0.0; 11];
    unit.clear();
    unit.reserve(samples.len());
    for s in samples {
        let o = odometry_raw(-j21, j22, 1.0, s.pieces());
        unit.push(o);
        let (sn, omc) = (o.sin, o.one_minus_cos());
        let (cx, cy) = (o.x, o.y);
        let (sx, sy) = (s.sm[0], s.sm[1]);
        sum[0] += cx * cx + cy * cy;
        sum[1] += cy * sn - cx * omc;
        sum[2] += -cx * sn - cy * omc;
        sum[3] += -cx * sx - cy * sy;
        sum[4] += cx * sy - cy * sx;
        sum[5] += 2.0 * omc;
        sum[6] += omc * sx - sn * sy;
        sum[7] += -omc * sy - sn * sx;
        sum[8] += sn * sx + omc * sy;
        sum[9] += omc * sx - sn * sy;
        sum[10] += sx * sx + sy * sy;
    }
    [
        [sum[0], sum[1], sum[2], sum[3], sum[4]],
        [sum[1], sum[5], 0.0, sum[6], sum[7]],
        [sum[2], 0.0, sum[5], sum[8], sum[9]],
        [sum[3], sum[6], sum[8], sum[10], 0.0],
        [sum[4], sum[7], sum[9], 0.0, sum[10]],
    ]
}

/// Condition numbers of the block `A` of `M` (raw and with unit diagonal) and the
/// direction of `(b, ℓx, ℓy)` it excites least.
pub(crate) fn a_conditions(m: &[[f64; 5]; 5]) -> (f64, f64, [f64; 3]) {
    let a = Matrix3::from_fn(|i, j| m[i][j]);
    let (a_scaled, _) = unit_diagonal(&a);
    let (raw_eigs, _) = symmetric_eigen_sorted(&a);
    let (scaled_eigs, scaled_vecs) = symmetric_eigen_sorted(&a_scaled);
    (
        condition_from_eigenvalues(&raw_eigs),
        condition_from_eigenvalues(&scaled_eigs),
        [scaled_vecs[0][0], scaled_vecs[0][1], scaled_vecs[0][2]],
    )
}

/// Minimises `xᵀMx` subject to `x4² + x5² = 1`, `x1 > 0`. Returns `None` only
/// when `A` is not positive definite at all; ill-conditioning is reported in the
/// result's condition numbers.
pub fn solve_m(m: &[[f64; 5]; 5]) -> Option<Step2> {
    let a = Matrix3::from_fn(|i, j| m[i][j]);
    let bm = Matrix3x2::from_fn(|i, j| m[i][j + 3]);
    let c = Matrix2::from_fn(|i, j| m[i + 3][j + 3]);

    let (a_scaled, scale) = unit_diagonal(&a);
    let (a_condition, a_condition_scaled, a_weakest_direction) = a_conditions(m);
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
    use crate::sample::Sample;

    #[test]
    fn m_equals_sum_of_row_outer_products() {
        let samples: Vec<Sample> = [
            (1.0, 2.0, 0.1, -0.02, 0.3),
            (-1.0, 1.0, 0.0, 0.05, -1.0),
            (3.0, 3.1, 0.3, 0.01, 0.02),
        ]
        .iter()
        .map(|&(l, r, x, y, t)| Sample::from_rotations(1.0, l, r, Pose2::new(x, y, t)))
        .collect();
        let packed = Packed::all(&samples, true);
        let (j21, j22) = (-0.2, 0.19);
        let m = build_m(&packed, j21, j22, &mut Vec::new());
        let mut want = [[0.0; 5]; 5];
        for s in &packed {
            let o = odometry_raw(-j21, j22, 1.0, s.pieces());
            let (sn, omc) = (o.theta.sin(), 1.0 - o.theta.cos());
            let r1 = [-o.x, omc, sn, s.sm[0], -s.sm[1]];
            let r2 = [-o.y, -sn, omc, s.sm[1], s.sm[0]];
            for i in 0..5 {
                for j in 0..5 {
                    want[i][j] += r1[i] * r1[j] + r2[i] * r2[j];
                }
            }
        }
        for i in 0..5 {
            for j in 0..5 {
                assert!((m[i][j] - want[i][j]).abs() < 1e-12, "M[{i}][{j}]");
            }
        }
    }

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
        let j = truth.j();
        let m = build_m(
            &Packed::all(&samples, true),
            j[1][0],
            j[1][1],
            &mut Vec::new(),
        );
        let s2 = solve_m(&m).unwrap();
        assert!((s2.b - truth.b).abs() < 1e-12);
        assert!((s2.laser.x - truth.laser.x).abs() < 1e-12);
        assert!((s2.laser.y - truth.laser.y).abs() < 1e-12);
        assert!((s2.laser.theta - truth.laser.theta).abs() < 1e-12);
        let trace: f64 = (0..5).map(|i| m[i][i]).sum();
        assert!(s2.residual.abs() < 1e-12 * trace);
    }
}
