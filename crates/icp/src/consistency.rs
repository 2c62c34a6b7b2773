//! The consistency test of a result: its residuals must look like the scans' noise.
//!
//! ICP converges to *a* minimum; from a guess far off it can be a wrong one, where
//! walls are matched to the wrong walls. Such a minimum shows in two ways, whatever the
//! sensor: the residual spread over the matched points is many times the range noise
//! the scans show about their own local lines (a right match leaves only that noise),
//! or the result explains only a small part of the current scan. Both are measured
//! relative to the data, not as fixed distances: the spread against the scans' own
//! noise estimate, the matches against the scan's valid points.

use crate::{IcpError, IcpParams, IcpResult, PreparedScan};

/// Consistency constant of the median absolute deviation for a Gaussian.
const MAD_TO_SIGMA: f64 = 1.482_602_218_505_602;

/// Noise floor relative to the largest range: exact (noise-free) scans still carry
/// the rounding of ranges stored as `f32` and of the local-line fits, and a right
/// match of them leaves residuals of that size.
pub(crate) const EXACT_NOISE_SHARE: f64 = 1e-5;

/// `1.4826 · √median` of the squared weighted residuals (reordered; 0 when empty).
pub(crate) fn robust_spread(squared_residuals: &mut [f64]) -> f64 {
    if squared_residuals.is_empty() {
        return 0.0;
    }
    let mid = squared_residuals.len() / 2;
    let (_, median, _) = squared_residuals.select_nth_unstable_by(mid, f64::total_cmp);
    MAD_TO_SIGMA * median.sqrt()
}

/// The range noise the two scans show themselves: the larger of their estimates; when
/// neither scan has enough straight stretches to show its noise, the noise typical of
/// the log ([`IcpParams::typical_noise_sigma`]); at least the floor of exact data.
pub(crate) fn scans_noise(
    reference: &PreparedScan,
    current: &PreparedScan,
    params: &IcpParams,
) -> f64 {
    let range = reference.max_valid_range.max(current.max_valid_range);
    let own = match (reference.noise_sigma, current.noise_sigma) {
        (Some(a), Some(b)) => a.max(b),
        (Some(a), None) | (None, Some(a)) => a,
        (None, None) => params.typical_noise_sigma,
    };
    own.max(EXACT_NOISE_SHARE * range)
}

/// Refuses a result whose residual spread is far above the scans' noise, or that
/// matches too small a share of the current scan.
pub(crate) fn check_consistency(result: &IcpResult, params: &IcpParams) -> Result<(), IcpError> {
    let ratio = result.residual_spread / result.noise_sigma;
    // NaN (a non-finite spread) is refused too.
    if ratio.is_nan() || ratio > params.max_residual_to_noise {
        return Err(IcpError::ResidualAboveNoise {
            spread_mm: result.residual_spread * 1e3,
            noise_mm: result.noise_sigma * 1e3,
            ratio,
            max_ratio: params.max_residual_to_noise,
        });
    }
    if result.matched_share < params.min_matched_share {
        return Err(IcpError::SmallOverlap {
            share_percent: 100.0 * result.matched_share,
            min_percent: 100.0 * params.min_matched_share,
        });
    }
    Ok(())
}
