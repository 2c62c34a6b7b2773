//! The scan-matching stage: ŝ for every synchronized pair, in parallel.

use crate::health::scan_jitter::median;
use crate::parallel::match_chain;
use crate::rejection::{MatchFailure, Rejection};
use odocal_geom::Pose2;
use odocal_icp::{IcpParams, Matcher, PreparedScan, RayDirections};
use odocal_log::ScanStore;
use rayon::prelude::*;
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
    /// Matches composed into ŝ: 1 for the pair's own match, more when the pair was
    /// matched through the scans between its two (see [`crate::chained`]).
    pub links: u32,
    /// Scans besides the pair's own two that the pair was matched with: its scans
    /// densified by their neighbours (see [`crate::local_map`]); 0 for a match of
    /// the two scans alone.
    pub neighbours: u32,
    /// The motion `(x, y, θ)` along which the scans fix nothing (a corridor: see
    /// [`odocal_icp::IcpResult::free_direction`]); ŝ keeps the first guess there and
    /// the calibration gives it no weight. `None` when the match fixes every
    /// direction.
    pub free_direction: Option<[f64; 3]>,
}

impl MatchStats {
    /// One match of a pair's own two scans: `result`'s pose, covariance and
    /// statistics.
    pub(crate) fn of(result: &odocal_icp::IcpResult) -> MatchStats {
        MatchStats {
            pose: result.pose,
            covariance: result.covariance,
            iterations: result.iterations,
            correspondences: result.correspondences,
            mean_residual: result.mean_residual,
            links: 1,
            neighbours: 0,
            free_direction: result.free_direction,
        }
    }

    /// Does the match fix every direction of ŝ (no [`MatchStats::free_direction`])?
    pub fn fixes_every_direction(&self) -> bool {
        self.free_direction.is_none()
    }
}

/// Scans sampled to estimate the log's typical range noise.
pub const NOISE_SAMPLE_SCANS: usize = 64;

/// How many readings a log's scans return (see [`scan_returns`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ScanReturns {
    /// The median count of readings within the scan's range limits.
    pub median: u32,
    /// The median count of rays per scan.
    pub rays: u32,
}

/// The median count of readings within each scan's range limits, over every
/// (len / [`NOISE_SAMPLE_SCANS`])-th scan of the store, and the median rays per scan
/// of the same scans; `None` without scans.
pub fn scan_returns(scans: &ScanStore) -> Option<ScanReturns> {
    let every = (scans.len() / NOISE_SAMPLE_SCANS).max(1);
    let (mut returns, mut rays): (Vec<usize>, Vec<usize>) = (0..scans.len())
        .step_by(every)
        .filter_map(|i| scans.get(i))
        .map(|s| {
            let (lo, hi) = (s.geometry.min_range, s.geometry.max_range);
            let valid = s
                .ranges
                .iter()
                .filter(|&&r| {
                    let r = f64::from(r);
                    r.is_finite() && r > lo && r < hi
                })
                .count();
            (valid, s.ranges.len())
        })
        .unzip();
    if returns.is_empty() {
        return None;
    }
    let mid = returns.len() / 2;
    returns.select_nth_unstable(mid);
    rays.select_nth_unstable(mid);
    Some(ScanReturns {
        median: u32::try_from(returns[mid]).unwrap_or(u32::MAX),
        rays: u32::try_from(rays[mid]).unwrap_or(u32::MAX),
    })
}

/// The ray directions of each of the store's geometries (indexed as
/// [`ScanStore::geometries`]), for [`prepare_scan`].
pub(crate) fn store_rays(scans: &ScanStore) -> Vec<RayDirections> {
    scans
        .geometries
        .iter()
        .map(|g| RayDirections::new(&g.angles))
        .collect()
}

/// Scan `i` of `scans` prepared for matching with `params`, along the rays of its
/// geometry in `rays` ([`store_rays`] of `scans`); `None` when the store has no scan
/// `i`.
pub(crate) fn prepare_scan(
    scans: &ScanStore,
    rays: &[RayDirections],
    i: usize,
    params: &IcpParams,
) -> Option<Result<PreparedScan, odocal_icp::IcpError>> {
    let s = scans.get(i)?;
    let (min_range, max_range) = (s.geometry.min_range, s.geometry.max_range);
    let geometry = scans.scans.get(i)?.geometry as usize;
    Some(match rays.get(geometry) {
        Some(r) => PreparedScan::with_rays(s.ranges, r, min_range, max_range, params),
        None => PreparedScan::new(s.ranges, &s.geometry.angles, min_range, max_range, params),
    })
}

/// A log's typical scan noise (see [`typical_scan_noise`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScanNoise {
    /// The median range noise (σ, m) of the scans whose noise shows; 0 when none
    /// does.
    pub range_sigma_m: f64,
    /// The median of the scans' [`odocal_icp::PreparedScan::typical_tilt_sigma`]
    /// (rad): how noisy the tilt of their local lines is; `None` when no scan has
    /// enough usable lines.
    pub tilt_sigma_rad: Option<f64>,
}

/// The median range noise (σ, m) of up to [`NOISE_SAMPLE_SCANS`] scans spread evenly
/// over the store, among those whose noise shows (straight stretches); 0 when none
/// does. What the matcher's consistency test assumes for scans too cluttered or
/// sparse to show their own.
pub fn typical_noise_sigma(scans: &ScanStore, params: &IcpParams) -> f64 {
    typical_scan_noise(scans, params).range_sigma_m
}

/// [`typical_noise_sigma`] and, from the same scans, the median tilt noise of their
/// local lines.
pub fn typical_scan_noise(scans: &ScanStore, params: &IcpParams) -> ScanNoise {
    let every = (scans.len() / NOISE_SAMPLE_SCANS).max(1);
    let sampled: Vec<usize> = (0..scans.len()).step_by(every).collect();
    let rays = store_rays(scans);
    // On the current pool's threads; collected in scan order.
    let (noise, tilt): (Vec<Option<f64>>, Vec<Option<f64>>) = sampled
        .into_par_iter()
        .filter_map(|i| {
            let scan = prepare_scan(scans, &rays, i, params)?.ok()?;
            Some((scan.noise_sigma(), scan.typical_tilt_sigma()))
        })
        .unzip();
    ScanNoise {
        range_sigma_m: median(noise.into_iter().flatten().collect()).unwrap_or(0.0),
        tilt_sigma_rad: median(tilt.into_iter().flatten().collect()),
    }
}

/// `params` with [`IcpParams::typical_noise_sigma`] set to `store_noise` (the store's
/// [`typical_noise_sigma`]) when it is 0, i.e. not given: what [`match_pairs`] would
/// estimate itself, estimated once for several calls.
pub fn with_typical_noise(params: &IcpParams, store_noise: f64) -> IcpParams {
    IcpParams {
        typical_noise_sigma: if params.typical_noise_sigma == 0.0 {
            store_noise
        } else {
            params.typical_noise_sigma
        },
        ..params.clone()
    }
}

/// Where a scan is in its source, for a message: its line in a text log; in a bag, its
/// message number on the scan topic and its stamp (the store does not know the topic:
/// [`odocal_log::Origin::at`] names it where the log is at hand).
fn scan_place(s: &odocal_log::ScanRef<'_>) -> String {
    match s.kind {
        odocal_log::ScanKind::LaserScan => {
            format!(
                "LaserScan message {}, stamp {:.3} s",
                s.line.saturating_sub(1),
                s.t
            )
        }
        _ => format!("line {}", s.line),
    }
}

/// Scan `i` of `scans` prepared for matching ([`prepare_scan`]), or the failure its
/// pairs report: where the scan is in its source and why it could not be prepared.
pub(crate) fn prepared_or_failure(
    scans: &ScanStore,
    rays: &[RayDirections],
    i: usize,
    params: &IcpParams,
) -> Result<PreparedScan, MatchFailure> {
    match prepare_scan(scans, rays, i, params) {
        Some(Ok(scan)) => Ok(scan),
        Some(Err(e)) => {
            let place = scans.get(i).map(|s| scan_place(&s)).unwrap_or_default();
            Err(MatchFailure::new(
                Rejection::of(&e),
                format!("scan {i} ({place}): {e}"),
            ))
        }
        None => Err(MatchFailure::new(
            Rejection::Scan,
            format!("scan {i} does not exist"),
        )),
    }
}

/// One pair of prepared scans matched from `guess`: its statistics, or why it was
/// refused (a scan that could not be prepared, the matcher's error, or a result
/// that does not constrain the displacement).
pub(crate) fn match_prepared(
    matcher: &mut Matcher,
    reference: &Result<PreparedScan, MatchFailure>,
    current: &Result<PreparedScan, MatchFailure>,
    guess: Pose2,
) -> Result<MatchStats, MatchFailure> {
    let (reference, current) = match (reference, current) {
        (Ok(r), Ok(c)) => (r, c),
        (Err(e), _) | (_, Err(e)) => return Err(e.clone()),
    };
    let r = matcher
        .match_scans(reference, current, guess)
        .map_err(|e| MatchFailure::new(Rejection::of(&e), e.to_string()))?;
    if r.ill_conditioned {
        return Err(MatchFailure::new(
            Rejection::Conditioning,
            "the scans do not constrain the displacement (ill-conditioned)",
        ));
    }
    Ok(MatchStats::of(&r))
}

/// Matches the pairs `(first, second)` of scan indices, each with its first guess,
/// in parallel (rayon's current pool). Results come back in pair order and do not
/// depend on the number of threads. `done` is called once per pair (progress).
/// Without a [`IcpParams::typical_noise_sigma`], the store's own
/// ([`typical_noise_sigma`]) is used.
pub fn match_pairs(
    scans: &ScanStore,
    pairs: &[(usize, usize)],
    first_guesses: &[Pose2],
    params: &IcpParams,
    done: impl Fn() + Sync + Send,
) -> Vec<Result<MatchStats, MatchFailure>> {
    debug_assert_eq!(pairs.len(), first_guesses.len());
    let own_params;
    let mut params = params;
    if params.typical_noise_sigma == 0.0 {
        own_params = with_typical_noise(params, typical_noise_sigma(scans, params));
        params = &own_params;
    }
    let rays = store_rays(scans);
    match_chain(
        pairs,
        |i| prepared_or_failure(scans, &rays, i, params),
        || Matcher::new(params.clone()),
        |matcher, k, reference, current| {
            match_prepared(matcher, reference, current, first_guesses[k])
        },
        done,
    )
}
