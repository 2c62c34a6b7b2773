//! One pass over the samples: the weighted cost `Σ eᵀWe`, the Gauss–Newton matrix
//! `Σ GᵀWG` (the Fisher information) and the vector `Σ GᵀWe`, with `e = ŝ_pred − ŝ`
//! and `G = ∂ŝ_pred/∂(r_L, r_R, b, ℓx, ℓy, ℓθ)`.

use crate::kinematics::{residual_of, Predictor};
use crate::noise::NoiseWeights;
use crate::packed::Packed;
use crate::params::Params;

/// Sums over one pass.
#[derive(Debug, Clone, Copy)]
pub(crate) struct NormalEquations {
    /// `Σ eᵀWe`.
    pub cost: f64,
    /// `Σ GᵀWG` (symmetric).
    pub h: [[f64; 6]; 6],
    /// `Σ GᵀWe`.
    pub g: [f64; 6],
}

/// Accumulates the normal equations over `samples` at `params`.
pub(crate) fn accumulate(
    samples: &[Packed],
    params: &Params,
    weights: &NoiseWeights,
) -> NormalEquations {
    let pred = Predictor::new(params, true);
    let mut h = [[0.0; 6]; 6];
    let mut g = [0.0; 6];
    let mut cost = 0.0;
    for s in samples {
        let (p, jac) = pred.predict_with_jacobian_pieces(s.pieces());
        let e = residual_of(p, &s.sm);
        match weights {
            NoiseWeights::Shared(w) => {
                for r in 0..3 {
                    let we = w[r] * e[r];
                    cost += we * e[r];
                    for i in 0..6 {
                        let wg = w[r] * jac[r][i];
                        g[i] += jac[r][i] * we;
                        for j in i..6 {
                            h[i][j] += wg * jac[r][j];
                        }
                    }
                }
            }
            NoiseWeights::PerSample(info) => {
                let w = &info[s.index];
                // WG (3×6) and We (3).
                let mut wg = [[0.0; 6]; 3];
                let mut we = [0.0; 3];
                for r in 0..3 {
                    for c in 0..3 {
                        we[r] += w[r][c] * e[c];
                        for i in 0..6 {
                            wg[r][i] += w[r][c] * jac[c][i];
                        }
                    }
                }
                for r in 0..3 {
                    cost += e[r] * we[r];
                    for i in 0..6 {
                        g[i] += jac[r][i] * we[r];
                        for j in i..6 {
                            h[i][j] += jac[r][i] * wg[r][j];
                        }
                    }
                }
            }
        }
    }
    for i in 0..6 {
        for j in 0..i {
            h[i][j] = h[j][i];
        }
    }
    NormalEquations { cost, h, g }
}
