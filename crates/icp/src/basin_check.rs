//! The basin test of a result: started again a step away along its least constrained
//! direction, the iterations must come back.
//!
//! The covariance is the curvature of the point-to-line cost at the result with the
//! correspondences fixed. When the correspondences follow the estimate — noisy far
//! points matched to local lines of random tilt, clutter with a line wherever one
//! looks — that curvature is not the cost's: the iterations stay wherever they start
//! along a direction the covariance calls determined to a millimetre. Measured on the
//! simulated TurtleBot 4 (RPLIDAR, σ = 3 mm + 0.5 %·r, the cluttered office): pairs
//! whose reported σ along the robot's motion is 1–3 mm end 30 mm off when started
//! 30 mm off, and 50–100 mm short of the truth when started from identity; a right
//! match comes back to within 0.01 mm.
//!
//! So a result is matched again from `result ± basin_check_step` along its weakest
//! direction (both sides: a wall may stop one). A result the iterations do not come
//! back to — the two differ by more than their own covariance allows (squared
//! Mahalanobis distance beyond χ²(3)'s 99.7 % level) — is flagged `ill_conditioned`
//! (the pipeline refuses those: "the scans do not constrain the displacement"), and
//! its covariance is widened by the spread found.

use crate::{IcpParams, IcpResult, Matcher, PreparedScan};
use odocal_geom::Pose2;

/// χ²(3)'s 99.7 % level.
const CHI2_3_997: f64 = 14.16;

/// A result comfortably well conditioned (condition number below this share of
/// [`IcpParams::max_condition_number`]) is not tested: its cost has a clear bowl in
/// every direction (clean scans of rooms and arenas; keeps the matcher's time).
pub(crate) const TESTED_CONDITION_SHARE: f64 = 0.2;

/// Two converged runs differ by up to this many times the convergence epsilons.
const CONVERGENCE_SPREAD: f64 = 3.0;

/// The squared Mahalanobis distance of `d` (x, y, θ) under `cov` (∞ when `cov` is
/// not invertible).
pub(crate) fn mahalanobis_sq(d: [f64; 3], cov: &[[f64; 3]; 3]) -> f64 {
    let m = nalgebra::Matrix3::from_fn(|r, c| cov[r][c]);
    let v = nalgebra::Vector3::from(d);
    match m.try_inverse() {
        Some(inv) => {
            let q = (v.transpose() * inv * v)[0];
            if q.is_finite() {
                q
            } else {
                f64::INFINITY
            }
        }
        None => f64::INFINITY,
    }
}

/// `to − from` in the parameters a result's covariance is of: `(x, y, θ)`, the angle
/// wrapped.
pub(crate) fn difference(from: &Pose2, to: &Pose2) -> [f64; 3] {
    [
        to.x - from.x,
        to.y - from.y,
        odocal_geom::wrap_angle(to.theta - from.theta),
    ]
}

/// `cov` widened by the spread `d` between two results: `cov + d dᵀ`.
pub(crate) fn widen(cov: &mut [[f64; 3]; 3], d: [f64; 3]) {
    for (r, row) in cov.iter_mut().enumerate() {
        for (c, v) in row.iter_mut().enumerate() {
            *v += d[r] * d[c];
        }
    }
}

/// `result.pose` moved by `step` (m) along the unit direction `weak` of `(x, y, ρθ)`.
fn moved(pose: &Pose2, weak: [f64; 3], step: f64, rho: f64) -> Pose2 {
    Pose2::new(
        pose.x + step * weak[0],
        pose.y + step * weak[1],
        pose.theta + step * weak[2] / rho,
    )
}

/// RMS range of the scan's valid points (m; 0 when none).
pub(crate) fn rms_range(scan: &PreparedScan) -> f64 {
    let n = scan.points.len().max(1) as f64;
    let sum: f64 = scan.points.iter().map(|p| p[0] * p[0] + p[1] * p[1]).sum();
    (sum / n).sqrt()
}

impl Matcher {
    /// `result` after the basin test (see the module documentation); `anchor` is the
    /// caller's first guess, `rho` the RMS range of the current scan's points.
    pub(crate) fn basin_checked(
        &mut self,
        reference: &PreparedScan,
        current: &PreparedScan,
        mut result: IcpResult,
        anchor: Pose2,
        params: &IcpParams,
        use_tree: bool,
    ) -> IcpResult {
        let step = params.basin_check_step;
        if step <= 0.0
            || result.ill_conditioned
            || result.condition_number < TESTED_CONDITION_SHARE * params.max_condition_number
        {
            return result;
        }
        let rho = rms_range(current).max(1e-3);
        // Two runs stop anywhere within the convergence tolerance of the same
        // minimum: that much difference is no flatness (noise-free scans have a
        // covariance of almost nothing).
        let mut judged = result.covariance;
        let tolerance = [
            CONVERGENCE_SPREAD * params.epsilon_xy,
            CONVERGENCE_SPREAD * params.epsilon_xy,
            CONVERGENCE_SPREAD * params.epsilon_theta,
        ];
        for (k, t) in tolerance.iter().enumerate() {
            judged[k][k] += t * t;
        }
        // Both sides: a wall may stop the iterations on one.
        for sign in [1.0, -1.0] {
            let start = moved(&result.pose, result.weakest_direction, sign * step, rho);
            // A start from which the pair fails or is refused says nothing about the
            // flatness of the cost at the result.
            let Ok(again) = self.refine(reference, current, start, anchor, params, use_tree) else {
                continue;
            };
            let d = difference(&result.pose, &again.pose);
            if mahalanobis_sq(d, &judged) > CHI2_3_997 {
                result.ill_conditioned = true;
                widen(&mut result.covariance, d);
                break;
            }
        }
        result
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mahalanobis_of_a_diagonal_covariance() {
        let cov = [[4e-6, 0.0, 0.0], [0.0, 1e-6, 0.0], [0.0, 0.0, 1e-4]];
        let q = mahalanobis_sq([0.004, 0.001, 0.01], &cov);
        assert!((q - 6.0).abs() < 1e-9, "{q}");
        let singular = [[0.0; 3]; 3];
        assert_eq!(mahalanobis_sq([1e-3, 0.0, 0.0], &singular), f64::INFINITY);
    }
}
