//! The scan-matching noise model: how residuals `ŝ_pred − ŝ` are weighted, either
//! by standard deviations estimated from the residuals or by each sample's own
//! covariance.

use crate::linalg::information_from_covariance;
use crate::sample::Sample;

/// Smallest standard deviation used for weighting (m or rad); residuals of
/// noise-free data would otherwise give infinite weights.
pub const SIGMA_FLOOR: f64 = 1e-12;

/// Weights of the residuals: the information matrix (inverse covariance) of `ŝ`.
#[derive(Debug, Clone)]
pub(crate) enum NoiseWeights {
    /// The same diagonal information `1/σ²` (x, y, θ) for every sample.
    Shared([f64; 3]),
    /// Each sample's own information matrix, indexed like the samples.
    PerSample(Vec<[[f64; 3]; 3]>),
}

impl NoiseWeights {
    /// Weights from standard deviations (floored at [`SIGMA_FLOOR`]).
    pub(crate) fn from_sigmas(sigma: [f64; 3]) -> Self {
        NoiseWeights::Shared(sigma.map(|s| 1.0 / s.max(SIGMA_FLOOR).powi(2)))
    }

    /// The same weights with each sample's free direction
    /// ([`Sample::free_direction`]) given none: `W − (Wδ)(Wδ)ᵀ / (δᵀWδ)`, the limit of
    /// the information of a covariance made infinitely wide along `δ`. Unchanged
    /// (and still shared) when no sample has a free direction; `samples` indexed like
    /// the weights.
    pub(crate) fn with_free_directions(self, samples: &[Sample]) -> Self {
        if samples.iter().all(|s| s.free_direction.is_none()) {
            return self;
        }
        let info = |k: usize| match &self {
            NoiseWeights::Shared(w) => [[w[0], 0.0, 0.0], [0.0, w[1], 0.0], [0.0, 0.0, w[2]]],
            NoiseWeights::PerSample(info) => info[k],
        };
        NoiseWeights::PerSample(
            samples
                .iter()
                .enumerate()
                .map(|(k, s)| match s.free_direction {
                    Some(d) => without_direction(info(k), d),
                    None => info(k),
                })
                .collect(),
        )
    }

    /// Each sample's own covariance, when every sample has one; `None` otherwise.
    /// The covariances must already have been checked (positive definite).
    pub(crate) fn from_samples(samples: &[Sample]) -> Option<Self> {
        samples
            .iter()
            .map(|s| s.sm_cov.as_ref().and_then(information_from_covariance))
            .collect::<Option<Vec<_>>>()
            .map(NoiseWeights::PerSample)
    }
}

/// The information `w` with the direction `d` taken out:
/// `w − (w d)(w d)ᵀ / (dᵀ w d)` (`w` itself when `dᵀ w d` is not positive).
fn without_direction(w: [[f64; 3]; 3], d: [f64; 3]) -> [[f64; 3]; 3] {
    let wd: [f64; 3] = std::array::from_fn(|r| (0..3).map(|c| w[r][c] * d[c]).sum());
    let dwd: f64 = (0..3).map(|r| d[r] * wd[r]).sum();
    if dwd.is_nan() || dwd <= 0.0 {
        return w;
    }
    std::array::from_fn(|r| std::array::from_fn(|c| w[r][c] - wd[r] * wd[c] / dwd))
}

/// Standard deviations (x, y, θ) of the residuals, mean removed, divided by `n − 1`
/// (zero for fewer than two residuals).
pub fn residual_sigmas(residuals: &[[f64; 3]]) -> [f64; 3] {
    let n = residuals.len();
    if n < 2 {
        return [0.0; 3];
    }
    let mut out = [0.0; 3];
    for (c, o) in out.iter_mut().enumerate() {
        let mean = residuals.iter().map(|e| e[c]).sum::<f64>() / n as f64;
        let ss: f64 = residuals.iter().map(|e| (e[c] - mean).powi(2)).sum();
        *o = (ss / (n - 1) as f64).sqrt();
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sigmas_of_known_sets() {
        let r = [[1.0, 0.0, 2.0], [3.0, 0.0, 2.0], [5.0, 0.0, 2.0]];
        let s = residual_sigmas(&r);
        assert!((s[0] - 2.0).abs() < 1e-15);
        assert_eq!(s[1], 0.0);
        assert_eq!(s[2], 0.0);
    }
}
