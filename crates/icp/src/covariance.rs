//! Uncertainty of the result: a sandwich covariance with the residual noise by range.
//!
//! At the solution, each used correspondence contributes the row
//! `J_i = [n_x, n_y, n_iᵀ R'(θ) q_i]` (derivative of its residual with respect to
//! `(x, y, θ)`), and the information matrix is `I = Σ J_iᵀ J_i` — the Gauss–Newton
//! Hessian of the point-to-line cost. With the weights `w_i` of the step
//! (inverse residual variances up to a common factor σ̂²), `I = Σ w_i J_iᵀ J_i` and the
//! first-order covariance is `σ̂² I⁻¹`, `σ̂² = Σ w_i e_i² / (m − 3)` — the estimate
//! for independent residuals (it does not propagate the noise of the reference points
//! through the local lines, as Censi's ICRA 2007 closed form does).
//!
//! That single σ̂ is the noise of the bulk of the points, the near ones; on lasers
//! whose noise grows with the range, a displacement only far points determine came
//! out many times too certain. So the covariance is the sandwich `I⁻¹ S I⁻¹`,
//! `S = Σ w_i v_i J_iᵀ J_i`, `v_i` the robust residual variance of the correspondences
//! at about the range of point `i` (module `range_noise`), times `m / (m − 3)`; with
//! equal noise at every range it is the `σ̂² I⁻¹` above (σ̂ median-based). A singular
//! information matrix keeps `σ̂² I⁻¹` (infinite along the singular direction).
//!
//! Residuals of neighbouring rays are not independent: the range noise of a real
//! sensor is correlated over a few rays, and neighbouring matches share the local
//! line they are measured against. The covariance is therefore multiplied by the
//! variance inflation factor `1 + 2 Σ_k ρ_k` of the residual sequence, with `ρ_k` the
//! autocorrelation of the weighted residuals `√w_i e_i` at lag `k` rays, estimated
//! from the match itself and summed over the initial positive lags (k ≤ 8). For
//! independent residuals it is ≈ 1. See `docs/benchmarks.md` for the ratio of the
//! reported to the empirical scatter.
//!
//! Conditioning is judged on the information matrix with the rotation scaled by the
//! RMS distance `ρ` of the used points (so all three axes are lengths):
//! `condition_number = λ_max / λ_min` of `D I D`, `D = diag(1, 1, 1/ρ)`.

use nalgebra::{Matrix3, SymmetricEigen, U3};
use odocal_geom::Pose2;

/// Covariance and conditioning of a match.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Uncertainty {
    pub covariance: [[f64; 3]; 3],
    pub condition_number: f64,
    pub weakest_direction: [f64; 3],
    pub residual_sigma: f64,
    pub inflation: f64,
}

/// Condition number of the scale-normalised information matrix and its least
/// constrained direction `(x, y, ρθ)` (unit vector).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Conditioning {
    pub condition_number: f64,
    pub weakest_direction: [f64; 3],
}

/// Conditioning of the information matrix `info` in `(x, y, θ)`, with the rotation
/// scaled by `rho` (m) so that the three axes are lengths.
pub(crate) fn conditioning(info: &[[f64; 3]; 3], rho: f64) -> Option<Conditioning> {
    let rho = if rho.is_finite() && rho > 1e-6 {
        rho
    } else {
        1.0
    };
    let info = Matrix3::from_fn(|r, c| info[r][c]);
    scaled_eigen(&info, rho).map(|(_, cond)| cond)
}

/// Eigen-decomposition of the scale-normalised information `D I D`,
/// `D = diag(1, 1, 1/rho)`, and its conditioning; `None` when it is not finite.
fn scaled_eigen(info: &Matrix3<f64>, rho: f64) -> Option<(SymmetricEigen<f64, U3>, Conditioning)> {
    let d = [1.0, 1.0, 1.0 / rho];
    let scaled = Matrix3::from_fn(|r, c| d[r] * info[(r, c)] * d[c]);
    if !scaled.iter().all(|v| v.is_finite()) {
        return None;
    }
    let eig = SymmetricEigen::new(scaled);
    let (imin, imax) = extreme_indices(&eig);
    let lmin = eig.eigenvalues[imin].max(0.0);
    let lmax = eig.eigenvalues[imax];
    let condition_number = if lmin > 0.0 {
        lmax / lmin
    } else {
        f64::INFINITY
    };
    let v = eig.eigenvectors.column(imin);
    let cond = Conditioning {
        condition_number,
        weakest_direction: [v[0], v[1], v[2]],
    };
    Some((eig, cond))
}

/// Indices of the smallest and largest eigenvalues.
fn extreme_indices(eig: &SymmetricEigen<f64, U3>) -> (usize, usize) {
    let (mut imin, mut imax) = (0, 0);
    for k in 1..3 {
        if eig.eigenvalues[k] < eig.eigenvalues[imin] {
            imin = k;
        }
        if eig.eigenvalues[k] > eig.eigenvalues[imax] {
            imax = k;
        }
    }
    (imin, imax)
}

/// Per-ray scratch of [`InformationSum`]: the weighted residual of each ray of the
/// current scan (0 where none) and a bit set of the rays that have one, kept by the
/// matcher so that a match allocates nothing.
#[derive(Debug, Clone, Default)]
pub(crate) struct RayResiduals {
    residual: Vec<f64>,
    present: Vec<u64>,
}

/// `Σ_i a[i] · b[i]` with independent partial sums (so that it vectorises).
fn dot(a: &[f64], b: &[f64]) -> f64 {
    let mut partial = [0.0; 4];
    let (ca, cb) = (a.chunks_exact(4), b.chunks_exact(4));
    let tail: f64 = ca
        .remainder()
        .iter()
        .zip(cb.remainder())
        .map(|(x, y)| x * y)
        .sum();
    for (x, y) in ca.zip(cb) {
        for k in 0..4 {
            partial[k] += x[k] * y[k];
        }
    }
    partial.iter().sum::<f64>() + tail
}

/// Number of bits set in both `bits` and `bits` shifted by `lag` (< 64) positions.
fn pairs_at_lag(bits: &[u64], lag: usize) -> u32 {
    let mut count = 0;
    let mut carry = 0u64;
    for &word in bits {
        let shifted = (word << lag) | carry;
        carry = if lag == 0 { 0 } else { word >> (64 - lag) };
        count += (word & shifted).count_ones();
    }
    count
}

/// Accumulates `I = Σ JᵀJ` and the residual sum of squares at a pose.
#[derive(Debug)]
pub(crate) struct InformationSum<'a> {
    sin: f64,
    cos: f64,
    /// Upper triangle of `Σ w JᵀJ`: (0,0), (0,1), (0,2), (1,1), (1,2), (2,2).
    info: [f64; 6],
    /// Upper triangle of `Σ w v JᵀJ` (`v`: the variance of the weighted residual
    /// `√w·e`), the expected scatter of the score `Σ w e J` (same order).
    score: [f64; 6],
    sum_sq: f64,
    sum_r2: f64,
    count: usize,
    rays: &'a mut RayResiduals,
}

/// Largest lag (rays) of the residual autocorrelation.
const MAX_LAG: usize = 8;

impl<'a> InformationSum<'a> {
    /// Empty sums at `pose`, for a current scan of `ray_count` rays.
    pub fn new(pose: &Pose2, ray_count: usize, rays: &'a mut RayResiduals) -> Self {
        let (sin, cos) = pose.theta.sin_cos();
        rays.residual.clear();
        rays.residual.resize(ray_count, 0.0);
        rays.present.clear();
        rays.present.resize(ray_count.div_ceil(64), 0);
        InformationSum {
            sin,
            cos,
            info: [0.0; 6],
            score: [0.0; 6],
            sum_sq: 0.0,
            sum_r2: 0.0,
            count: 0,
            rays,
        }
    }

    /// Adds a used correspondence: current point `q` of ray `ray` (each ray at most
    /// once), reference line normal, residual and weight (inverse residual variance up
    /// to the common factor σ̂²), and `noise_variance`, the variance of its weighted
    /// residual `√w·e` (from the residuals at its range: module `range_noise`).
    /// Returns the residual's Jacobian `∂e/∂(x, y, θ)` at the sums' pose.
    pub fn add(
        &mut self,
        ray: usize,
        q: [f64; 2],
        normal: [f64; 2],
        residual: f64,
        w: f64,
        noise_variance: f64,
    ) -> [f64; 3] {
        if let (Some(r), Some(p)) = (
            self.rays.residual.get_mut(ray),
            self.rays.present.get_mut(ray / 64),
        ) {
            *r = w.sqrt() * residual;
            *p |= 1 << (ray % 64);
        }
        let (s, c) = (self.sin, self.cos);
        let dq = [-s * q[0] - c * q[1], c * q[0] - s * q[1]];
        let j = [normal[0], normal[1], normal[0] * dq[0] + normal[1] * dq[1]];
        let wj = [w * j[0], w * j[1], w * j[2]];
        let info = &mut self.info;
        info[0] += wj[0] * j[0];
        info[1] += wj[0] * j[1];
        info[2] += wj[0] * j[2];
        info[3] += wj[1] * j[1];
        info[4] += wj[1] * j[2];
        info[5] += wj[2] * j[2];
        // E[(w e J)(w e J)ᵀ] = w · noise_variance · JJᵀ.
        let v = noise_variance;
        let score = &mut self.score;
        score[0] += v * wj[0] * j[0];
        score[1] += v * wj[0] * j[1];
        score[2] += v * wj[0] * j[2];
        score[3] += v * wj[1] * j[1];
        score[4] += v * wj[1] * j[2];
        score[5] += v * wj[2] * j[2];
        self.sum_sq += w * residual * residual;
        self.sum_r2 += q[0] * q[0] + q[1] * q[1];
        self.count += 1;
        j
    }

    /// Number of correspondences added.
    pub fn count(&self) -> usize {
        self.count
    }

    /// Variance inflation factor `1 + 2 Σ ρ_k` over the initial positive lags, `ρ_k`
    /// the autocorrelation of the weighted residuals of rays `k` apart.
    pub fn inflation(&self) -> f64 {
        let variance = self.sum_sq / self.count.max(1) as f64;
        if variance.is_nan() || variance <= 0.0 {
            return 1.0;
        }
        let (r, present) = (&self.rays.residual, &self.rays.present);
        let mut factor = 1.0;
        for lag in 1..=MAX_LAG.min(r.len()) {
            // Missing residuals are 0: they add nothing to the sum.
            let sum = dot(&r[lag..], &r[..r.len() - lag]);
            let pairs = f64::from(pairs_at_lag(present, lag));
            if pairs < 10.0 {
                break;
            }
            let rho = sum / pairs / variance;
            if rho.is_nan() || rho <= 0.0 {
                break;
            }
            factor += 2.0 * rho.min(1.0);
        }
        factor
    }

    /// The sandwich covariance `I⁻¹ S I⁻¹` in the scaled axes (`D I D = V Λ Vᵀ`, every
    /// eigenvalue positive), `S = Σ w v JᵀJ` the scatter of the score, with the small
    /// sample factor `m / (m − 3)` and the residual correlation `inflation`.
    fn sandwich(
        &self,
        eig: &SymmetricEigen<f64, U3>,
        d: [f64; 3],
        m: usize,
        inflation: f64,
    ) -> Matrix3<f64> {
        let t = &self.score;
        let score = Matrix3::new(t[0], t[1], t[2], t[1], t[3], t[4], t[2], t[4], t[5]);
        let scaled = Matrix3::from_fn(|r, c| d[r] * score[(r, c)] * d[c]);
        let v = &eig.eigenvectors;
        // I⁻¹ S I⁻¹ in the eigenbasis: (Vᵀ S V)_kl / (λ_k λ_l).
        let mut in_basis = v.transpose() * scaled * v;
        for k in 0..3 {
            for l in 0..3 {
                in_basis[(k, l)] /= eig.eigenvalues[k] * eig.eigenvalues[l];
            }
        }
        let factor = m as f64 / (m.saturating_sub(3).max(1)) as f64 * inflation;
        v * in_basis * v.transpose() * factor
    }

    /// Covariance and conditioning; `None` when the sums are not finite.
    pub fn finish(&self) -> Option<Uncertainty> {
        let m = self.count;
        let inflation = self.inflation();
        let sigma2 = self.sum_sq / (m.saturating_sub(3).max(1)) as f64 * inflation;
        let rho = (self.sum_r2 / m.max(1) as f64).sqrt().max(1e-6);
        // Only the upper triangle was accumulated.
        let t = &self.info;
        let info = Matrix3::new(t[0], t[1], t[2], t[1], t[3], t[4], t[2], t[4], t[5]);
        let (eig, cond) = scaled_eigen(&info, rho)?;
        let d = [1.0, 1.0, 1.0 / rho];
        let cov = if eig.eigenvalues.iter().all(|&l| l > 0.0) {
            self.sandwich(&eig, d, m, inflation)
        } else {
            // Covariance: σ̂² I⁻¹ = σ̂² D (DID)⁻¹ D, inverted in the eigenbasis so that
            // a singular direction gives an infinite (not NaN) variance along it.
            let mut cov = Matrix3::<f64>::zeros();
            for k in 0..3 {
                let l = eig.eigenvalues[k];
                let inv = if l > 0.0 { 1.0 / l } else { f64::INFINITY };
                let v = eig.eigenvectors.column(k);
                for r in 0..3 {
                    for c in 0..3 {
                        let vv = v[r] * v[c];
                        if vv != 0.0 {
                            cov[(r, c)] += sigma2 * inv * vv;
                        }
                    }
                }
            }
            cov
        };
        // D·cov·D element-wise (D is diagonal; avoids 0·∞).
        let mut covariance = [[0.0; 3]; 3];
        for (r, row) in covariance.iter_mut().enumerate() {
            for (c, v) in row.iter_mut().enumerate() {
                *v = d[r] * cov[(r, c)] * d[c];
            }
        }
        Some(Uncertainty {
            covariance,
            condition_number: cond.condition_number,
            weakest_direction: cond.weakest_direction,
            residual_sigma: (self.sum_sq / (m.saturating_sub(3).max(1)) as f64).sqrt(),
            inflation,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pairs_at_lag_counts_across_words() {
        let rays = [0usize, 1, 3, 62, 63, 64, 65, 127, 128, 130];
        let mut bits = vec![0u64; 3];
        for &r in &rays {
            bits[r / 64] |= 1 << (r % 64);
        }
        for lag in 1..8 {
            let expected = rays
                .iter()
                .filter(|&&r| r >= lag && rays.contains(&(r - lag)))
                .count();
            assert_eq!(pairs_at_lag(&bits, lag) as usize, expected, "lag {lag}");
        }
    }

    #[test]
    fn dot_matches_the_plain_sum() {
        let a: Vec<f64> = (0..11).map(|i| i as f64 * 0.5 - 1.0).collect();
        let b: Vec<f64> = (0..11).map(|i| (i * i) as f64).collect();
        let plain: f64 = a.iter().zip(&b).map(|(x, y)| x * y).sum();
        assert!((dot(&a, &b) - plain).abs() < 1e-12);
    }
}
