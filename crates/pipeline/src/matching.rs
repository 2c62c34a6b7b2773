//! The scan-matching stage: ŝ for every synchronized pair, in parallel.

use crate::parallel::match_chain;
use odocal_geom::Pose2;
use odocal_icp::{IcpParams, Matcher, PreparedScan};
use odocal_log::ScanStore;
use serde::Serialize;

/// What the scan matcher returned for one pair, kept for the tuples and the report.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MatchStats {
    /// ŝ: the second scan's sensor pose in the first's frame.
    pub pose: Pose2,
    /// Covariance of ŝ (x, y, θ).
    pub covariance: [[f64; 3]; 3],
    /// ICP iterations.
    pub iterations: u32,
    /// Correspondences used in the last iteration.
    pub correspondences: usize,
    /// Mean point-to-line residual (m).
    pub mean_residual: f64,
}

/// Matches the pairs `(first, second)` of scan indices, each with its first guess,
/// in parallel (rayon's current pool). Results come back in pair order and do not
/// depend on the number of threads. `done` is called once per pair (progress).
pub fn match_pairs(
    scans: &ScanStore,
    pairs: &[(usize, usize)],
    first_guesses: &[Pose2],
    params: &IcpParams,
    done: impl Fn() + Sync + Send,
) -> Vec<Result<MatchStats, String>> {
    debug_assert_eq!(pairs.len(), first_guesses.len());
    let prepare = |i: usize| match scans.get(i) {
        Some(s) => PreparedScan::new(
            s.ranges,
            &s.geometry.angles,
            s.geometry.min_range,
            s.geometry.max_range,
            params,
        )
        .map_err(|e| format!("scan {i} (line {}): {e}", s.line)),
        None => Err(format!("scan {i} does not exist")),
    };
    match_chain(
        pairs,
        prepare,
        || Matcher::new(params.clone()),
        |matcher, k, reference, current| {
            let (reference, current) = match (reference, current) {
                (Ok(r), Ok(c)) => (r, c),
                (Err(e), _) | (_, Err(e)) => return Err(e.clone()),
            };
            let r = matcher
                .match_scans(reference, current, first_guesses[k])
                .map_err(|e| e.to_string())?;
            if r.ill_conditioned {
                return Err("the scans do not constrain the displacement (ill-conditioned)".into());
            }
            Ok(MatchStats {
                pose: r.pose,
                covariance: r.covariance,
                iterations: r.iterations,
                correspondences: r.correspondences,
                mean_residual: r.mean_residual,
            })
        },
        done,
    )
}
