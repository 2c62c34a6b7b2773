//! Step 1 of the closed form: `J21`, `J22` by linear least squares on
//! `[Δθ_L, Δθ_R]·[J21, J22]ᵀ = ŝθ`.

use crate::linalg::{condition_from_eigenvalues, symmetric_eigen2};
use crate::packed::Packed;
use serde::Serialize;

/// Result of step 1.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Step1 {
    /// `J21 = −r_L/b` (rad⁻¹·rad, i.e. robot rotation per left wheel rotation).
    pub j21: f64,
    /// `J22 = r_R/b`.
    pub j22: f64,
    /// The 2×2 normal matrix `Σ w_k a_k a_kᵀ`, `a_k = (Δθ_L, Δθ_R)`.
    pub normal: [[f64; 2]; 2],
    /// Condition number of the normal matrix (∞ when singular).
    pub condition: f64,
    /// Unit vector of wheel-rotation space the data excite least (eigenvector of the
    /// normal matrix's smallest eigenvalue).
    pub weakest_direction: [f64; 2],
}

/// Solves step 1 over `samples`. With `theta_weights`, the row of sample `k` (its
/// index in the caller's slice) is weighted by `theta_weights[k]` (1/σθ²); otherwise
/// all rows weigh the same. When the normal matrix is singular, `j21`/`j22` are NaN
/// and `condition` is ∞.
pub(crate) fn step1(samples: &[Packed], theta_weights: Option<&[f64]>) -> Step1 {
    let (mut n11, mut n12, mut n22, mut g1, mut g2) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for s in samples {
        let w = theta_weights.map_or(1.0, |w| w[s.index]);
        let (a1, a2) = (s.dphi_l, s.dphi_r);
        n11 += w * a1 * a1;
        n12 += w * a1 * a2;
        n22 += w * a2 * a2;
        g1 += w * a1 * s.sm[2];
        g2 += w * a2 * s.sm[2];
    }
    let normal = [[n11, n12], [n12, n22]];
    let (eigs, vecs) = symmetric_eigen2(normal);
    let condition = condition_from_eigenvalues(&eigs);
    let det = n11 * n22 - n12 * n12;
    let (j21, j22) = if condition.is_finite() && det > 0.0 {
        ((n22 * g1 - n12 * g2) / det, (n11 * g2 - n12 * g1) / det)
    } else {
        (f64::NAN, f64::NAN)
    };
    Step1 {
        j21,
        j22,
        normal,
        condition,
        weakest_direction: vecs[0],
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sample::Sample;
    use odocal_geom::Pose2;

    #[test]
    fn exact_on_consistent_rows() {
        let (j21, j22) = (-0.2, 0.19);
        let samples: Vec<Sample> = [(1.0, 2.0), (-1.0, 1.0), (3.0, 3.0), (0.5, -0.2)]
            .iter()
            .map(|&(l, r)| {
                Sample::from_rotations(1.0, l, r, Pose2::new(0.0, 0.0, j21 * l + j22 * r))
            })
            .collect();
        let s1 = step1(&Packed::all(&samples, true), None);
        assert!((s1.j21 - j21).abs() < 1e-14 && (s1.j22 - j22).abs() < 1e-14);
        assert!(s1.condition.is_finite());
    }

    #[test]
    fn spins_only_are_singular() {
        let samples: Vec<Sample> = [1.0, 2.0, -1.5]
            .iter()
            .map(|&a| Sample::from_rotations(1.0, -a, a, Pose2::new(0.0, 0.0, 0.1 * a)))
            .collect();
        let s1 = step1(&Packed::all(&samples, true), None);
        assert!(s1.condition > 1e12);
        // The unexcited direction is J21 + J22 (a straight-run direction).
        assert!((s1.weakest_direction[0] - s1.weakest_direction[1]).abs() < 1e-9);
    }
}
