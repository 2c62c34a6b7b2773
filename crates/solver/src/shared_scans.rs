//! The noise of samples that share a scan, and what it does to the covariance of
//! the estimate.
//!
//! A log's samples chain: sample `k` matches scans `(j, j+1)`, sample `k+1` scans
//! `(j+1, j+2)`. Whatever error scan `j+1` brings — its own range noise as seen by
//! the matcher, the encoder reading interpolated at its timestamp — enters both
//! samples, with opposite signs: the residuals of consecutive samples are
//! negatively correlated (measured on simulated Khepera logs: −0.4 to −0.5 in each
//! of x, y, θ). Treating the samples as independent then overstates the variance
//! of everything that sums over many samples (the radii and `b` most), by a factor
//! 2–3 on those logs.
//!
//! The model: `ŝ_k = ŝ_k,true ⊖δ_start ⊕ … ⊕δ_end + n_k`, i.e. to first order
//! `e_k = A_k δ_end(k) + B_k δ_start(k) + n_k` with one error `δ_j` per scan
//! (covariance `D`, in the scan's sensor frame) and one per sample (`N`):
//! `A_k = diag(R(ŝθ), 1)` maps the end scan's error into `ŝ_k`, `B_k` (−1 on the
//! diagonal, `(ŝy, −ŝx)` in the θ column) the start scan's. Then
//! `E[e_{k+1} e_kᵀ] = B_{k+1} D A_kᵀ` gives `D` from the pairs of consecutive
//! residuals, and `E[e_k e_kᵀ] = N + A_k D A_kᵀ + B_k D B_kᵀ` gives `N`. The
//! estimator is unchanged (weighted least squares); its covariance is the sandwich
//! `H⁻¹ Var(Σ GᵀWe) H⁻¹` with `Var(Σ GᵀWe) = Σ_k GᵀWNWG + Σ_j U_j D U_jᵀ`,
//! `U_j` summing `GᵀWA` and `GᵀWB` over the samples that use scan `j`.
//!
//! `N` is a small difference of large moments (70–90 % of the residual variance is
//! shared on simulated logs), so its estimate is noisy, and a chance low estimate
//! would make everything that sums over samples look far too certain: it enters at
//! its estimate plus one standard error (σ lean large by up to ~30 %, measured).

use crate::kinematics::{residual_of, Predictor};
use crate::noise::NoiseWeights;
use crate::packed::Packed;
use crate::params::Params;
use nalgebra::{Matrix3, SMatrix, Vector3};
use serde::Serialize;
use std::collections::{BTreeMap, HashMap};

type Matrix6x3 = SMatrix<f64, 6, 3>;
type Matrix6 = SMatrix<f64, 6, 6>;

/// Fewest scans shared by two samples used for the shared-scan model to be
/// estimated (below, the samples are treated as independent).
pub const MIN_SHARED_SCANS: usize = 20;

/// The estimated noise of samples that share scans.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SharedScanNoise {
    /// Covariance `D` of the error each scan brings into both samples that use
    /// it (x, y, θ in the scan's sensor frame; m², rad²).
    pub per_scan: [[f64; 3]; 3],
    /// Covariance `N` of the error each sample has alone.
    pub per_sample: [[f64; 3]; 3],
    /// Scans shared by two of the samples used (the pairs `D` was estimated from).
    pub shared_scans: usize,
    /// Per component (x, y, θ): the part of a residual's variance that comes
    /// from its two scans, `2·D_ii / (N_ii + 2·D_ii)`.
    pub shared_fraction: [f64; 3],
}

/// How the end scan's error enters `ŝ`: `ŝ ⊕ δ`.
fn end_map(sm: &[f64; 3]) -> Matrix3<f64> {
    let (s, c) = sm[2].sin_cos();
    Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)
}

/// How the start scan's error enters `ŝ`: `⊖δ ⊕ ŝ`.
fn start_map(sm: &[f64; 3]) -> Matrix3<f64> {
    Matrix3::new(-1.0, 0.0, sm[1], 0.0, -1.0, -sm[0], 0.0, 0.0, -1.0)
}

/// The symmetric part of `m` with negative eigenvalues set to zero.
fn nearest_psd(m: &Matrix3<f64>) -> Matrix3<f64> {
    let sym = 0.5 * (m + m.transpose());
    let eig = sym.symmetric_eigen();
    let clamped = eig.eigenvalues.map(|v| v.max(0.0));
    eig.eigenvectors * Matrix3::from_diagonal(&clamped) * eig.eigenvectors.transpose()
}

fn weight(weights: &NoiseWeights, index: usize) -> Matrix3<f64> {
    match weights {
        NoiseWeights::Shared(w) => Matrix3::from_diagonal(&Vector3::new(w[0], w[1], w[2])),
        NoiseWeights::PerSample(info) => Matrix3::from_fn(|i, j| info[index][i][j]),
    }
}

/// Per component: standard error of the mean of every other entry of `v`.
fn standard_error(v: &[Vector3<f64>]) -> Vector3<f64> {
    let every_other: Vec<&Vector3<f64>> = v.iter().step_by(2).collect();
    let m = every_other.len() as f64;
    if m < 2.0 {
        return Vector3::zeros();
    }
    let mean = every_other.iter().fold(Vector3::zeros(), |acc, x| acc + *x) / m;
    let var = every_other.iter().fold(Vector3::zeros(), |acc, x| {
        acc + (*x - mean).component_mul(&(*x - mean))
    }) / (m - 1.0);
    var.map(|v| (v / m).sqrt())
}

fn to_array3(m: &Matrix3<f64>) -> [[f64; 3]; 3] {
    std::array::from_fn(|i| std::array::from_fn(|j| m[(i, j)]))
}

/// `Var(Σ GᵀWe)` at `params` under the shared-scan model, with the model; `None`
/// when some sample has no scan times or fewer than [`MIN_SHARED_SCANS`] scans
/// are shared (then the samples count as independent).
pub(crate) fn score_covariance(
    samples: &[Packed],
    params: &Params,
    weights: &NoiseWeights,
) -> Option<([[f64; 6]; 6], SharedScanNoise)> {
    let times: Vec<[f64; 2]> = samples
        .iter()
        .map(|s| s.scan_times)
        .collect::<Option<_>>()?;
    let pred = Predictor::new(params, true);
    let (mut e, mut g) = (Vec::new(), Vec::new());
    for s in samples {
        let (p, jac) = pred.predict_with_jacobian_pieces(s.pieces());
        e.push(Vector3::from(residual_of(p, &s.sm)));
        g.push(SMatrix::<f64, 3, 6>::from_fn(|i, j| jac[i][j]));
    }
    let starts: HashMap<u64, usize> = times
        .iter()
        .enumerate()
        .map(|(k, t)| (t[0].to_bits(), k))
        .collect();

    // D from consecutive residuals: B⁻¹ e_{k+1} e_kᵀ A⁻ᵀ (A is a rotation).
    let mut cross = Matrix3::zeros();
    let mut shared = 0;
    // Per shared scan, per component: (e_k² + e_next²)/2 − 2·(shared product), whose
    // mean is about N_cc: its scatter gives the standard error of N̂.
    let mut unshared: Vec<Vector3<f64>> = Vec::new();
    for (k, t) in times.iter().enumerate() {
        let Some(&next) = starts.get(&t[1].to_bits()) else {
            continue;
        };
        let b_inv = start_map(&samples[next].sm).try_inverse()?;
        let a = end_map(&samples[k].sm);
        let product = b_inv * e[next] * e[k].transpose() * a;
        cross += product;
        shared += 1;
        unshared.push(Vector3::from_fn(|c, _| {
            0.5 * (e[k][c] * e[k][c] + e[next][c] * e[next][c]) - 2.0 * product[(c, c)]
        }));
    }
    if shared < MIN_SHARED_SCANS {
        return None;
    }
    let d = nearest_psd(&(cross / shared as f64));
    let mut total = Matrix3::zeros();
    for (s, ek) in samples.iter().zip(&e) {
        let (a, b) = (end_map(&s.sm), start_map(&s.sm));
        total += ek * ek.transpose() - a * d * a.transpose() - b * d * b.transpose();
    }
    // N is a small difference of large moments: a chance low estimate would make
    // everything that sums over samples look far too certain. Use its upper bound,
    // N̂ + SE (SE from every other shared scan, which share no sample).
    let n_hat = total / samples.len() as f64 + Matrix3::from_diagonal(&standard_error(&unshared));
    let n = nearest_psd(&n_hat);

    let mut m = Matrix6::zeros();
    // Ordered by time, so that the sums (and the covariance) are reproducible.
    let mut per_scan: BTreeMap<u64, Matrix6x3> = BTreeMap::new();
    for ((s, gk), t) in samples.iter().zip(&g).zip(&times) {
        let gw = gk.transpose() * weight(weights, s.index);
        m += gw * n * gw.transpose();
        *per_scan
            .entry(t[0].to_bits())
            .or_insert_with(Matrix6x3::zeros) += gw * start_map(&s.sm);
        *per_scan
            .entry(t[1].to_bits())
            .or_insert_with(Matrix6x3::zeros) += gw * end_map(&s.sm);
    }
    for u in per_scan.values() {
        m += u * d * u.transpose();
    }
    let shared_fraction = std::array::from_fn(|i| {
        let all = n[(i, i)] + 2.0 * d[(i, i)];
        if all > 0.0 {
            2.0 * d[(i, i)] / all
        } else {
            0.0
        }
    });
    Some((
        std::array::from_fn(|i| std::array::from_fn(|j| 0.5 * (m[(i, j)] + m[(j, i)]))),
        SharedScanNoise {
            per_scan: to_array3(&d),
            per_sample: to_array3(&n),
            shared_scans: shared,
            shared_fraction,
        },
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn maps_are_the_first_order_pose_compositions() {
        use odocal_geom::Pose2;
        let s = Pose2::new(0.3, -0.1, 0.7);
        let d = Pose2::new(1e-6, -2e-6, 3e-6);
        let end = s.compose(&d);
        let start = d.inverse().compose(&s);
        let dv = Vector3::new(d.x, d.y, d.theta);
        let want_end = end_map(&s.to_array()) * dv;
        let want_start = start_map(&s.to_array()) * dv;
        for (got, want) in [(end, want_end), (start, want_start)] {
            let diff = [got.x - s.x, got.y - s.y, got.theta - s.theta];
            for i in 0..3 {
                assert!((diff[i] - want[i]).abs() < 1e-11, "{diff:?} vs {want:?}");
            }
        }
    }
}
