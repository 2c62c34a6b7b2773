//! The scan matcher's own error on a log without ground truth: closure of scan
//! triples.
//!
//! For consecutive samples `(a, b)` and `(b, c)` matched directly (not through the
//! scans between, [`crate::chained`]) the matcher also matches `(a, c)`
//! directly, from the guess `ŝ_ab ⊕ ŝ_bc`. The closure error `ŝ_ac ⊖ (ŝ_ab ⊕ ŝ_bc)`
//! holds the errors of three matches; with errors of similar size and independent
//! (they share scans, so partly correlated: the figure is a lower bound then), its
//! variance is about three times one match's, so one match's error is the closure's
//! RMS over √3.

use crate::matching::{match_pairs, MatchStats, ScanNoise};
use crate::samples::PairSample;
use odocal_geom::{wrap_angle, Pose2};
use odocal_icp::IcpParams;
use odocal_log::ScanStore;
use serde::Serialize;

/// Triples matched at most (evenly spread over the log).
pub const MAX_TRIPLES: usize = 60;

/// Fewer closed triples than this give no figure.
pub const MIN_TRIPLES: usize = 5;

/// The matcher's error per pair, measured by the closure of scan triples.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct MatchSelfCheck {
    /// Triples whose direct match succeeded (and were used).
    pub triples: usize,
    /// Triples tried.
    pub tried: usize,
    /// One match's translation error, RMS per axis (m).
    pub xy_m: f64,
    /// One match's rotation error, RMS (rad).
    pub theta_rad: f64,
    /// The median range noise of the log's scans (m), for scale.
    pub range_noise_m: f64,
    /// The median tilt noise of the log's local lines (rad; `None` when its scans
    /// have too few, e.g. sparse scans): what the matcher's bias on rotations
    /// grows with ([`crate::matcher_bias`]).
    pub tilt_sigma_rad: Option<f64>,
    /// The angle between neighbouring rays of the log's scans (rad; 0 when unknown):
    /// with the range noise it stands for the local lines' tilt noise where that is
    /// not measured ([`crate::matcher_bias`]).
    pub ray_spacing_rad: f64,
    /// The factor by which this error multiplied the solver's σ (1: the noise model
    /// already covered it; see [`crate::match_quality::sigma_inflation`]).
    pub sigma_factor: f64,
}

/// Measures the matcher's error on `samples` (in time order) with the scans they
/// were matched on; `None` when fewer than [`MIN_TRIPLES`] triples close.
/// `noise` is the store's [`crate::matching::typical_scan_noise`], and `params`
/// those the samples were matched with, their typical noise set (see
/// [`crate::matching::with_typical_noise`]).
pub fn closure_check(
    scans: &ScanStore,
    samples: &[PairSample],
    params: &IcpParams,
    noise: ScanNoise,
) -> Option<MatchSelfCheck> {
    let triples: Vec<(&MatchStats, &MatchStats, (usize, usize))> = samples
        .windows(2)
        // Direct matches only: a pair matched through the scans between its two was
        // refused directly, and so, mostly, is the pair twice as long over it.
        // Matches that leave a direction free keep the guess there: no closure.
        .filter(|w| {
            w[0].pair.second == w[1].pair.first
                && w.iter()
                    .all(|s| s.icp.links == 1 && s.icp.fixes_every_direction())
        })
        .map(|w| (&w[0].icp, &w[1].icp, (w[0].pair.first, w[1].pair.second)))
        .collect();
    let every = (triples.len() / MAX_TRIPLES).max(1);
    let chosen: Vec<_> = triples
        .into_iter()
        .step_by(every)
        .take(MAX_TRIPLES)
        .collect();
    let chained: Vec<Pose2> = chosen
        .iter()
        .map(|(ab, bc, _)| ab.pose.compose(&bc.pose))
        .collect();
    let pairs: Vec<(usize, usize)> = chosen.iter().map(|t| t.2).collect();
    let direct = match_pairs(scans, &pairs, &chained, params, || {});
    let (mut sum_xy, mut sum_theta, mut n) = (0.0, 0.0, 0usize);
    for (d, c) in direct.iter().zip(&chained) {
        let Some(d) = d.as_ref().ok().filter(|d| d.fixes_every_direction()) else {
            continue;
        };
        let e = c.between(&d.pose);
        sum_xy += e.x * e.x + e.y * e.y;
        sum_theta += wrap_angle(e.theta).powi(2);
        n += 1;
    }
    if n < MIN_TRIPLES {
        return None;
    }
    let n_f = n as f64;
    Some(MatchSelfCheck {
        triples: n,
        tried: pairs.len(),
        // Per axis: the sum over x and y is two axes; three matches per closure.
        xy_m: (sum_xy / (2.0 * 3.0 * n_f)).sqrt(),
        theta_rad: (sum_theta / (3.0 * n_f)).sqrt(),
        range_noise_m: noise.range_sigma_m,
        tilt_sigma_rad: noise.tilt_sigma_rad,
        ray_spacing_rad: scans
            .get(pairs[0].0)
            .map_or(0.0, |s| s.geometry.resolution.abs()),
        sigma_factor: 1.0,
    })
}
