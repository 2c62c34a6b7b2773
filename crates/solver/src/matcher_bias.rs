//! A scan-matching error common to every sample: the matcher's residual bias on
//! rotations, in the covariance as a systematic term.
//!
//! On noisy scans the point-to-line matcher turns a rotation `θ` into slightly
//! less (the local lines' tilt noise, only partly removed by its
//! errors-in-variables correction) and moves the translation with it, by
//! `β·θ` with `β = (β_x, β_y, β_θ)` in the sensor frame. The same `β` enters every
//! sample: it does not average out over a log, and at several thousand samples it
//! is as large as the random part of σ (docs/table-i.md, "Findings"). Its effect on
//! the estimate is `δp = H⁻¹ Q β` with `Q = Σ_k θ_k G_kᵀ W_k` (`ŝ_k` moved by
//! `θ_k β`); with `β` of standard deviation `s` per component, the covariance
//! gains `H⁻¹ Q diag(s²) Qᵀ H⁻¹`.

use crate::kinematics::Predictor;
use crate::noise::NoiseWeights;
use crate::packed::Packed;
use crate::params::Params;
use crate::shared_scans::weight;
use nalgebra::SMatrix;

type Matrix6x3 = SMatrix<f64, 6, 3>;
type Matrix6 = SMatrix<f64, 6, 6>;

/// `H⁻¹ Q diag(sd²) Qᵀ H⁻¹`: the covariance a bias `β·θ` common to every sample's
/// `ŝ` adds, `sd` the standard deviations of `β` (x, y in m/rad, θ in rad/rad) and
/// `h_inv` the inverse information of the fit (held parameters' rows zero). Zero
/// when `sd` is.
pub(crate) fn bias_covariance(
    samples: &[Packed],
    params: &Params,
    weights: &NoiseWeights,
    h_inv: &[[f64; 6]; 6],
    sd: [f64; 3],
) -> [[f64; 6]; 6] {
    if sd.iter().all(|s| *s == 0.0) {
        return [[0.0; 6]; 6];
    }
    let pred = Predictor::new(params, true);
    let q = samples.iter().fold(Matrix6x3::zeros(), |q, s| {
        let (_, jac) = pred.predict_with_jacobian_pieces(s.pieces());
        let g = SMatrix::<f64, 3, 6>::from_fn(|i, j| jac[i][j]);
        q + g.transpose() * weight(weights, s.index) * s.sm[2]
    });
    let h_inv = Matrix6::from_fn(|i, j| h_inv[i][j]);
    let effect = h_inv * q;
    let variance = SMatrix::<f64, 3, 3>::from_diagonal(&sd.map(|s| s * s).into());
    let c = effect * variance * effect.transpose();
    std::array::from_fn(|i| std::array::from_fn(|j| 0.5 * (c[(i, j)] + c[(j, i)])))
}
