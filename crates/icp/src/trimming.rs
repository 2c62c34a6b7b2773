//! The adaptive outlier threshold of one iteration.
//!
//! A correspondence is used when its absolute point-to-line residual is at most
//! `τ = min(τ_previous, max(k_σ · σ̂, k_step · motion), q-quantile)`, where
//! - `σ̂ = 1.4826 · median|e|` is a robust estimate of the residual spread (the
//!   sensor noise once converged; shrinks to 0 on noise-free data, so that the few
//!   imperfect matches near corners are dropped at the end),
//! - `motion` is the largest displacement of a point caused by the previous
//!   iteration's step (the first iteration uses the correspondence gate): while the
//!   estimate still moves, residuals of good matches are of that size and must not be
//!   mistaken for outliers,
//! - the `q`-quantile (`trim_fraction`) keeps at most that fraction of the matches,
//! - taking the minimum with the previous threshold makes τ non-increasing, so that
//!   the set of used matches settles and the iterations converge.

use crate::IcpParams;

/// Consistency constant of the median absolute deviation for a Gaussian.
const MAD_TO_SIGMA: f64 = 1.482_602_218_505_602;

/// The threshold for this iteration, given the *squared* (normalised) residuals;
/// `squared_residuals` is used as scratch (reordered). Returns τ (not squared) and
/// whether the motion term raised it above what the residual spread alone gives (then
/// the next iteration, with a smaller motion, will use a smaller τ), and that smaller
/// τ (the threshold without the motion term).
pub(crate) fn threshold(
    squared_residuals: &mut [f64],
    params: &IcpParams,
    previous_motion: Option<f64>,
    previous_threshold: f64,
) -> (f64, bool, f64) {
    let m = squared_residuals.len();
    if m == 0 {
        return (0.0, false, 0.0);
    }
    // Median of the squared residuals; above 256 matches (and when no fractional
    // trimming needs the whole slice afterwards), of every k-th one only, gathered at
    // the front of the scratch slice: the spread needs no more precision.
    let stride = if params.trim_fraction < 1.0 {
        1
    } else {
        (m / 128).max(1)
    };
    let sampled = m / stride;
    for i in 1..sampled {
        squared_residuals[i] = squared_residuals[i * stride];
    }
    let (_, median_sq, _) =
        squared_residuals[..sampled].select_nth_unstable_by(sampled / 2, f64::total_cmp);
    let median_sq = *median_sq;
    let median = median_sq.sqrt();
    let sigma = MAD_TO_SIGMA * median;
    let step_term = match previous_motion {
        Some(motion) => params.step_threshold_mult * motion,
        None => params.max_correspondence_dist,
    };
    let noise_term = params.outlier_sigma_mult * sigma;
    let motion_limited = step_term > noise_term && noise_term < previous_threshold;
    let mut tau = noise_term.max(step_term).min(previous_threshold);
    let mut noise_tau = noise_term.min(previous_threshold);
    if params.trim_fraction < 1.0 {
        // Keep the ⌈q·m⌉ smallest residuals at most.
        let keep = ((params.trim_fraction * m as f64).ceil() as usize).clamp(1, m);
        let (_, q, _) = squared_residuals.select_nth_unstable_by(keep - 1, f64::total_cmp);
        tau = tau.min(q.sqrt());
        noise_tau = noise_tau.min(q.sqrt());
    }
    (tau, motion_limited, noise_tau)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gross_outliers_are_cut_and_inliers_kept() {
        let params = IcpParams {
            trim_fraction: 1.0,
            ..IcpParams::default()
        };
        // 90 inliers spread ~1 mm, 10 outliers at 5 cm.
        let mut r: Vec<f64> = (0..90)
            .map(|i| (0.001 * ((i % 9) as f64 / 4.0)).powi(2))
            .collect();
        r.extend(std::iter::repeat_n(0.05f64.powi(2), 10));
        let (tau, _, _) = threshold(&mut r.clone(), &params, Some(1e-6), f64::INFINITY);
        assert!(tau > 0.002 && tau < 0.05, "tau = {tau}");
    }

    #[test]
    fn fraction_and_monotonicity() {
        let params = IcpParams {
            trim_fraction: 0.9,
            ..IcpParams::default()
        };
        let r: Vec<f64> = (1..=100).map(|i| (i as f64 * 1e-3).powi(2)).collect();
        // A large motion would allow everything; the fraction keeps 90 of 100.
        let (tau, _, _) = threshold(&mut r.clone(), &params, Some(1.0), f64::INFINITY);
        assert!((tau - 0.090).abs() < 1e-15);
        // Never above the previous threshold.
        let (tau, _, _) = threshold(&mut r.clone(), &params, Some(1.0), 0.01);
        assert_eq!(tau, 0.01);
    }
}
