//! The numbers of a finished calibration that comparisons need: the estimate, its
//! standard deviations and covariance (the data's, and with the laser's range scale),
//! J, and how many samples stood behind it.

use crate::run::{Outcome, Timing};
use serde::Serialize;

/// The core numbers of an [`Outcome`], in the solver's parameter order
/// r_L, r_R, b, ℓx, ℓy, ℓθ (m, rad).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Estimate {
    /// The estimate `[r_L, r_R, b, ℓx, ℓy, ℓθ]`.
    pub params: [f64; 6],
    /// Standard deviations from the data alone (the inverse Fisher information, widened
    /// by the matcher's own error when measured), same order.
    pub sigma: [f64; 6],
    /// Covariance 6×6 from the data alone, same order.
    pub covariance: [[f64; 6]; 6],
    /// Standard deviations the laser's range scale adds (`σ_s · p_s`, see
    /// [`odocal_solver::with_range_scale`]): 0 for ℓθ, and for all when no scale
    /// applies.
    pub sigma_range_scale: [f64; 6],
    /// Standard deviations of data and range scale together: what the error against
    /// the truth is to be compared with.
    pub sigma_total: [f64; 6],
    /// Covariance of data and range scale together.
    pub covariance_total: [[f64; 6]; 6],
    /// `J = [[r_L/2, r_R/2], [−r_L/b, r_R/b]]`.
    pub j: [[f64; 2]; 2],
    /// Samples used by the final estimate (after trimming).
    pub samples_used: usize,
    /// Samples handed to the solver (before trimming).
    pub samples_synchronized: usize,
    /// Scans between the two of a pair.
    pub stride: usize,
    /// Median interval between the two scans of a sample (s); NaN without samples.
    pub interval_s: f64,
    /// Wall time per stage (s).
    pub timing_s: Timing,
}

/// Square roots of a covariance's diagonal (negative variances read as 0).
fn diagonal_sigma(covariance: &[[f64; 6]; 6]) -> [f64; 6] {
    std::array::from_fn(|i| covariance[i][i].max(0.0).sqrt())
}

impl Estimate {
    /// The core numbers of `outcome`.
    pub fn of(outcome: &Outcome) -> Estimate {
        let c = &outcome.calibration;
        let mut intervals: Vec<f64> = outcome.synced.samples.iter().map(|s| s.wheel.dt).collect();
        let interval_s = if intervals.is_empty() {
            f64::NAN
        } else {
            let mid = intervals.len() / 2;
            *intervals.select_nth_unstable_by(mid, f64::total_cmp).1
        };
        let scale = outcome.range_scale.sigma;
        let direction = &c.scale_direction();
        let covariance_total = odocal_solver::with_scale_along(&c.covariance, direction, scale);
        let scale_only = odocal_solver::scale_covariance_along(direction, scale);
        Estimate {
            params: c.params.to_vector(),
            sigma: diagonal_sigma(&c.covariance),
            covariance: c.covariance,
            sigma_range_scale: diagonal_sigma(&scale_only),
            sigma_total: diagonal_sigma(&covariance_total),
            covariance_total,
            j: c.j,
            samples_used: c.samples_used,
            samples_synchronized: outcome.synced.samples.len(),
            stride: outcome.synced.stride,
            interval_s,
            timing_s: outcome.timing,
        }
    }

    /// The estimate as `[r_L, r_R, b, ℓx, ℓy, ℓθ]`.
    pub fn values(&self) -> [f64; 6] {
        self.params
    }
}
