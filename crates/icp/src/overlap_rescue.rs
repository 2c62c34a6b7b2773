//! A second look at a pair refused for its small overlap: accepted when its match is
//! the only minimum around it.
//!
//! The overlap test refuses a result that uses less than
//! [`IcpParams::min_matched_share`] of the current scan's points: on the URG-04LX
//! pairs it was set on, wrong alignments slid along a wall use 29–60 %. On real and
//! realistic scans a right match uses that little too: clutter and people that moved,
//! surfaces seen by one scan only, sparse returns. Measured against the simulator's
//! truth (three 120 s seeds of each realistic preset), taking the overlap floor down
//! to 40 % matched 275 more TurtleBot 4 pairs, 88 % of them within 5 mm / 0.5° of the
//! truth; the wrong 12 % must be told apart.
//!
//! A wrong alignment slid along a wall is one of several nearby minima: started a
//! little away, the iterations end elsewhere. So a pair refused for its overlap is
//! matched again with the floor at [`RESCUE_SHARE`], and that result is kept only
//! when the iterations come back to it from starts displaced by [`RESTART_XY`]
//! along x and y and by [`RESTART_THETA`] in rotation, each within the result's
//! covariance (χ²(3)'s 99.7 % level, with the convergence tolerance added), and it is
//! well conditioned after the basin test. Otherwise the pair stays refused for its
//! overlap.

use crate::basin_check::{judged_covariance, mahalanobis_sq, CHI2_3_997};
use crate::{IcpError, IcpParams, IcpResult, Matcher, NeighbourSearch, PreparedScan};
use odocal_geom::{wrap_angle, Pose2};

/// Lowest share of the current scan's lined points a rescued match may use.
pub(crate) const RESCUE_SHARE: f64 = 0.6;
/// Displacement of the restarts along x and y (m).
pub(crate) const RESTART_XY: f64 = 0.02;
/// Displacement of the restarts in rotation (rad, 1°).
pub(crate) const RESTART_THETA: f64 = 0.017_453_292_519_943_295;

/// The restarts around `pose`: ± [`RESTART_XY`] along x and y, ± [`RESTART_THETA`].
fn restarts(pose: &Pose2) -> [Pose2; 6] {
    let d = |x: f64, y: f64, t: f64| Pose2::new(pose.x + x, pose.y + y, pose.theta + t);
    [
        d(RESTART_XY, 0.0, 0.0),
        d(-RESTART_XY, 0.0, 0.0),
        d(0.0, RESTART_XY, 0.0),
        d(0.0, -RESTART_XY, 0.0),
        d(0.0, 0.0, RESTART_THETA),
        d(0.0, 0.0, -RESTART_THETA),
    ]
}

/// Whether `again` is `result` within `judged` (see [`judged_covariance`]).
pub(crate) fn comes_back(result: &Pose2, again: &Pose2, judged: &[[f64; 3]; 3]) -> bool {
    let d = [
        again.x - result.x,
        again.y - result.y,
        wrap_angle(again.theta - result.theta),
    ];
    mahalanobis_sq(d, judged) <= CHI2_3_997
}

/// The covariance of the inverse of a pose `pose` with covariance `cov`.
fn inverse_covariance(pose: &Pose2, cov: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let inv = pose.inverse();
    let (s, c) = pose.theta.sin_cos();
    let j = [[-c, -s, inv.y], [s, -c, -inv.x], [0.0, 0.0, -1.0]];
    let mut out = [[0.0; 3]; 3];
    for (r, row) in out.iter_mut().enumerate() {
        for (k, v) in row.iter_mut().enumerate() {
            for a in 0..3 {
                for b in 0..3 {
                    *v += j[r][a] * cov[a][b] * j[k][b];
                }
            }
        }
    }
    out
}

impl Matcher {
    /// Whether the scans matched the other way round (the current scan as the
    /// reference), from the inverse of `result`, come back to it.
    fn reverse_agrees(
        &mut self,
        reference: &PreparedScan,
        current: &PreparedScan,
        result: &IcpResult,
        params: &IcpParams,
    ) -> bool {
        let use_tree = params.search == NeighbourSearch::KdTree || !current.angles_increasing;
        if use_tree && current.tree.is_none() {
            return false;
        }
        let start = result.pose.inverse();
        let Ok(reverse) = self.refine(current, reference, start, start, params, use_tree) else {
            return false;
        };
        let back = reverse.pose.inverse();
        let mut judged = judged_covariance(result, params);
        let theirs = inverse_covariance(&reverse.pose, &reverse.covariance);
        for (row, other) in judged.iter_mut().zip(&theirs) {
            for (v, o) in row.iter_mut().zip(other) {
                *v += o;
            }
        }
        comes_back(&result.pose, &back, &judged)
    }

    /// The pair refused with `refusal` (its overlap) matched again as the module
    /// documentation says; `refusal` again when the second look does not hold.
    pub(crate) fn overlap_rescued(
        &mut self,
        reference: &PreparedScan,
        current: &PreparedScan,
        first_guess: Pose2,
        refusal: IcpError,
    ) -> Result<IcpResult, IcpError> {
        let strict = self.params().clone();
        if strict.min_matched_share <= RESCUE_SHARE {
            return Err(refusal);
        }
        let relaxed = IcpParams {
            min_matched_share: RESCUE_SHARE,
            ..strict.clone()
        };
        let use_tree = relaxed.search == NeighbourSearch::KdTree || !reference.angles_increasing;
        self.set_params(relaxed.clone());
        let outcome = self.match_scans_once(reference, current, first_guess);
        let verdict = match outcome {
            Ok(result) if !result.ill_conditioned => {
                let judged = judged_covariance(&result, &relaxed);
                let holds = restarts(&result.pose).iter().all(|start| {
                    self.refine(reference, current, *start, first_guess, &relaxed, use_tree)
                        .is_ok_and(|again| comes_back(&result.pose, &again.pose, &judged))
                });
                if holds && self.reverse_agrees(reference, current, &result, &relaxed) {
                    Ok(result)
                } else {
                    Err(refusal)
                }
            }
            _ => Err(refusal),
        };
        self.set_params(strict);
        verdict
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn restarts_are_displaced_by_the_stated_steps() {
        let pose = Pose2::new(1.0, -0.5, 0.3);
        for s in restarts(&pose) {
            let moved = (s.x - pose.x).abs() + (s.y - pose.y).abs();
            let turned = (s.theta - pose.theta).abs();
            assert!(
                (moved - RESTART_XY).abs() < 1e-12 && turned == 0.0
                    || moved == 0.0 && (turned - RESTART_THETA).abs() < 1e-12
            );
        }
    }

    #[test]
    fn coming_back_is_judged_by_the_covariance() {
        let cov = [[1e-6, 0.0, 0.0], [0.0, 1e-6, 0.0], [0.0, 0.0, 1e-6]];
        let p = Pose2::new(0.0, 0.0, 0.0);
        assert!(comes_back(&p, &Pose2::new(0.003, 0.0, 0.0), &cov));
        assert!(!comes_back(&p, &Pose2::new(0.004, 0.0, 0.0), &cov));
    }
}
