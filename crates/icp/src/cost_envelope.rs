//! The cost's envelope around a result: does the point-to-line cost, with the
//! correspondences found again, rise as steeply as the covariance says?
//!
//! The covariance is the curvature of the cost at the result with the
//! correspondences fixed. On noisy scans (range noise growing with the range, short
//! runs of clutter whose local lines tilt at random) every point finds a new line a
//! few millimetres further, and the cost along some direction is a washboard: steep
//! locally, flat overall. The iterations stop in the ripple the noise happened to
//! make — the same one from every start 10–30 mm away, so the basin test does not see
//! it — and the covariance reports the ripple's curvature. Measured on the simulated
//! TurtleBot 4 (RPLIDAR, σ = 3 mm + 0.5 %·r, cluttered office; one pair, 60 noise
//! draws at the true poses): the results scatter 8–10 mm along the robot's motion,
//! the covariance said 1.6–2.6 mm; the residuals at the result do not show it (a
//! cluster-robust covariance from their scatter by blocks of 8 to 64 rays gave
//! 1.9–2.9 mm).
//!
//! So along the principal axis of the covariance with the largest variance (in
//! `(x, y, ρθ)`, `ρ` the RMS range of the current points: the robot's motion on the
//! pairs measured) the truncated cost `Σ min(w e², τ²)` (`τ` the outlier threshold,
//! unmatched points at `τ²`) is evaluated at `±`[`STEP_SIGMAS`] times the axis's σ,
//! twice: with the result's correspondences (the rise the covariance
//! predicts) and with correspondences found again there (the rise the data make).
//! Where the second rises less, the variance along that axis is multiplied by the
//! ratio (at most [`MAX_WIDENING`]). The result itself is not changed, nor accepted
//! or refused differently: this is the covariance's honesty, not the matcher's
//! accuracy.

use crate::{IcpParams, IcpResult, Matcher, PreparedScan};
use nalgebra::{Matrix3, SymmetricEigen};
use odocal_geom::Pose2;

/// The step along each axis, in the axis's σ: far enough that the points' new
/// correspondences decide the rise, not the small changes of which segment a point
/// falls on (at 5σ, clean Khepera-arena pairs came out 4× too uncertain; from 10σ to
/// 40σ their covariance matches the scatter of 150 noise draws within 0.86–1.11).
pub(crate) const STEP_SIGMAS: f64 = 10.0;

/// A result whose condition number is below this share of
/// [`IcpParams::max_condition_number`] is not tested: clean scans of rooms and arenas
/// (the Khepera arena's pairs mostly) have a bowl. Testing all three axes of every
/// match cost 65 % more of `odocal calibrate`'s CPU on a 10-minute Khepera log
/// (0.43 → 0.71 s user), this 9 % (0.47 → 0.51 s), for a few more errors covered on
/// the realistic presets (40 / 47 / 26 uncovered against 42 / 54 / 27). The
/// washboard pairs measured were at 7–49 (of 50).
pub(crate) const TESTED_CONDITION_SHARE: f64 = 0.1;

/// Largest factor on a variance.
pub(crate) const MAX_WIDENING: f64 = 400.0;

/// The rise of the cost the covariance predicts and the one found: the variance
/// factor (≥ 1, ≤ [`MAX_WIDENING`]).
pub(crate) fn widening(predicted_rise: f64, found_rise: f64) -> f64 {
    if !(predicted_rise.is_finite() && predicted_rise > 0.0) {
        return 1.0;
    }
    if !(found_rise.is_finite() && found_rise > 0.0) {
        return MAX_WIDENING;
    }
    (predicted_rise / found_rise).clamp(1.0, MAX_WIDENING)
}

impl Matcher {
    /// `result` with its covariance widened where the cost's envelope is flatter than
    /// its curvature (see the module documentation).
    pub(crate) fn envelope_widened(
        &mut self,
        reference: &PreparedScan,
        current: &PreparedScan,
        mut result: IcpResult,
        params: &IcpParams,
        use_tree: bool,
    ) -> IcpResult {
        let tau = params.outlier_sigma_mult * result.residual_spread;
        if !(tau.is_finite() && tau > 0.0)
            || result.condition_number < TESTED_CONDITION_SHARE * params.max_condition_number
        {
            return result;
        }
        let tau_sq = tau * tau;
        let gate2 = params.max_correspondence_dist * params.max_correspondence_dist;
        let rho = crate::basin_check::rms_range(current).max(1e-3);
        let d = [1.0, 1.0, 1.0 / rho];
        // The covariance in the scaled axes, and its principal axes.
        let scaled = Matrix3::from_fn(|r, c| result.covariance[r][c] / (d[r] * d[c]));
        if !scaled.iter().all(|v| v.is_finite()) {
            return result;
        }
        let eig = SymmetricEigen::new(scaled);
        let k = (0..3)
            .max_by(|&a, &b| eig.eigenvalues[a].total_cmp(&eig.eigenvalues[b]))
            .unwrap_or(0);
        let variance = eig.eigenvalues[k];
        if !(variance.is_finite() && variance > 0.0) {
            return result;
        }
        let base = result.pose;
        let at_result =
            self.fix_correspondences(reference, current, &base, gate2, tau_sq, use_tree);
        let axis = eig.eigenvectors.column(k).into_owned();
        let h = STEP_SIGMAS * variance.sqrt();
        let (mut predicted, mut found) = (-2.0 * at_result, -2.0 * at_result);
        for sign in [1.0, -1.0] {
            let pose = Pose2::new(
                base.x + sign * h * axis[0],
                base.y + sign * h * axis[1],
                base.theta + sign * h * axis[2] * d[2],
            );
            let (fixed, again) =
                self.truncated_costs(reference, current, &pose, gate2, tau_sq, use_tree);
            predicted += fixed;
            found += again;
        }
        let factor = widening(predicted, found);
        if factor == 1.0 {
            return result;
        }
        // Σ + (f − 1) λ v vᵀ along the axis, back in (x, y, θ).
        let added = axis * axis.transpose() * (variance * (factor - 1.0));
        for (r, row) in result.covariance.iter_mut().enumerate() {
            for (c, x) in row.iter_mut().enumerate() {
                *x += d[r] * added[(r, c)] * d[c];
            }
        }
        result
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn widening_is_the_ratio_of_the_rises_within_bounds() {
        assert_eq!(widening(10.0, 10.0), 1.0);
        assert_eq!(widening(10.0, 20.0), 1.0);
        assert_eq!(widening(10.0, 2.5), 4.0);
        assert_eq!(widening(10.0, 0.0), MAX_WIDENING);
        assert_eq!(widening(10.0, -1.0), MAX_WIDENING);
        assert_eq!(widening(0.0, 1.0), 1.0);
        assert_eq!(widening(1e9, 1.0), MAX_WIDENING);
    }
}
