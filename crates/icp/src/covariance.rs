//! Uncertainty of the result: Hessian-based covariance scaled by the residual noise.
//!
//! At the solution, each used correspondence contributes the row
//! `J_i = [n_x, n_y, n_iᵀ R'(θ) q_i]` (derivative of its residual with respect to
//! `(x, y, θ)`), and the information matrix is `I = Σ J_iᵀ J_i` — the Gauss–Newton
//! Hessian of the point-to-line cost. With the weights `w_i` of the step
//! (inverse residual variances up to a common factor σ̂²), `I = Σ w_i J_iᵀ J_i` and the
//! covariance is `σ̂² I⁻¹`, `σ̂² = Σ w_i e_i² / (m − 3)`. This is the first-order estimate
//! for independent residuals; it does not propagate the noise of the reference
//! points through the local lines (Censi's ICRA 2007 closed form does), and it is
//! optimistic when the range noise is correlated along the scan (see
//! `docs/benchmarks.md` for the ratio measured against the empirical scatter).
//!
//! Conditioning is judged on the information matrix with the rotation scaled by the
//! RMS distance `ρ` of the used points (so all three axes are lengths):
//! `condition_number = λ_max / λ_min` of `D I D`, `D = diag(1, 1, 1/ρ)`.

use nalgebra::{Matrix3, SymmetricEigen};
use odocal_geom::Pose2;

/// Covariance and conditioning of a match.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Uncertainty {
    pub covariance: [[f64; 3]; 3],
    pub condition_number: f64,
    pub weakest_direction: [f64; 3],
    pub residual_sigma: f64,
}

/// Accumulates `I = Σ JᵀJ` and the residual sum of squares at a pose.
#[derive(Debug, Clone)]
pub(crate) struct InformationSum {
    sin: f64,
    cos: f64,
    info: Matrix3<f64>,
    sum_sq: f64,
    sum_r2: f64,
    count: usize,
}

impl InformationSum {
    /// Empty sums at `pose`.
    pub fn new(pose: &Pose2) -> Self {
        let (sin, cos) = pose.theta.sin_cos();
        InformationSum {
            sin,
            cos,
            info: Matrix3::zeros(),
            sum_sq: 0.0,
            sum_r2: 0.0,
            count: 0,
        }
    }

    /// Adds a used correspondence: current point `q`, reference line normal, residual
    /// and weight (inverse residual variance up to the common factor σ̂²).
    pub fn add(&mut self, q: [f64; 2], normal: [f64; 2], residual: f64, w: f64) {
        let (s, c) = (self.sin, self.cos);
        let dq = [-s * q[0] - c * q[1], c * q[0] - s * q[1]];
        let j = nalgebra::Vector3::new(
            normal[0],
            normal[1],
            normal[0] * dq[0] + normal[1] * dq[1],
        );
        self.info += (w * j) * j.transpose();
        self.sum_sq += w * residual * residual;
        self.sum_r2 += q[0] * q[0] + q[1] * q[1];
        self.count += 1;
    }

    /// Number of correspondences added.
    pub fn count(&self) -> usize {
        self.count
    }

    /// Covariance and conditioning; `None` when the sums are not finite.
    pub fn finish(&self) -> Option<Uncertainty> {
        let m = self.count;
        let sigma2 = self.sum_sq / (m.saturating_sub(3).max(1)) as f64;
        let rho = (self.sum_r2 / m.max(1) as f64).sqrt().max(1e-6);
        let d = Matrix3::from_diagonal(&nalgebra::Vector3::new(1.0, 1.0, 1.0 / rho));
        let scaled = d * self.info * d;
        if !scaled.iter().all(|v| v.is_finite()) {
            return None;
        }
        let eig = SymmetricEigen::new(scaled);
        let (mut imin, mut imax) = (0, 0);
        for k in 1..3 {
            if eig.eigenvalues[k] < eig.eigenvalues[imin] {
                imin = k;
            }
            if eig.eigenvalues[k] > eig.eigenvalues[imax] {
                imax = k;
            }
        }
        let lmin = eig.eigenvalues[imin].max(0.0);
        let lmax = eig.eigenvalues[imax];
        let condition_number = if lmin > 0.0 { lmax / lmin } else { f64::INFINITY };
        let v = eig.eigenvectors.column(imin);
        let weakest_direction = [v[0], v[1], v[2]];
        // Covariance: σ̂² I⁻¹ = σ̂² D (DID)⁻¹ D, inverted in the eigenbasis so that a
        // singular direction gives an infinite (not NaN) variance along it.
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
        // D·cov·D element-wise (D is diagonal; avoids 0·∞).
        let mut covariance = [[0.0; 3]; 3];
        for (r, row) in covariance.iter_mut().enumerate() {
            for (c, v) in row.iter_mut().enumerate() {
                *v = d[(r, r)] * cov[(r, c)] * d[(c, c)];
            }
        }
        Some(Uncertainty {
            covariance,
            condition_number,
            weakest_direction,
            residual_sigma: sigma2.sqrt(),
        })
    }
}
