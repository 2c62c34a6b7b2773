//! Pairs of sparse scans the matcher refused, matched again with each scan densified
//! by its neighbouring scans.
//!
//! A 1° LDS that returns 40–80 points of 361 (the Neato's) gives scans whose points on
//! a wall lie 10–30 cm apart: too few lie near each other for lines, and the pairwise
//! match of such a scan is refused (too few correspondences, too little of the scan
//! explained). The scans just before and just after see the same walls at other rays.
//! So a refused pair `(a, b)` of sparse scans is matched again as two point clouds:
//! scan `a` with the [`NEIGHBOURS`] scan before it placed in its frame, and scan `b`
//! with the one after it placed in its frame; a scan of few returns takes the next
//! one too, up to [`MAX_NEIGHBOURS`] ([`CLOUD_POINTS`]), and a scan of fewer returns
//! than a scan matched alone needs is matched in its cloud ([`MIN_OWN_POINTS`]). The
//! scans between the two are left out, so that no scan is in both clouds and no
//! odometry over the pair's own interval enters its match. The neighbours are placed
//! by odometry with the current estimate over one or two scan periods; the pair
//! keeps its own interval and its own wheel motion. The match must explain a share of
//! the second scan's own points, not of its neighbours' ([`PreparedScan::from_points`]).
//!
//! What this costs in honesty: the placement carries the odometry's error over that
//! period, and it pulls the match toward the estimate the placement used. The
//! match's covariance gets the first (`placement_covariance`): odometry's error over
//! the neighbours' periods, at most what the residuals of the solve that placed them
//! show, weighted by the share of the match that rests on placed points. So the estimate that gives the second pass its
//! guesses and placements is solved without these pairs (`run::calibrate_log`): with
//! the nominal radii 3 % off either way, the Neato's calibrated radii then move as
//! they do without the stage. Measured in docs/benchmarks.md, stop 37.
//!
//! A cloud's match may end no farther from its guess than the window of the
//! residuals of the solve whose estimate placed and guessed it
//! ([`crate::guess_window`]), in the first pass as in the second: a match beyond is one
//! the solver would trim, and a cloud's share of its own points explained (25 %) is
//! too low a bar to refuse it alone (docs/benchmarks.md, stop 49).
//!
//! Only pairs with a sparse scan (see [`odocal_icp::PreparedScan::is_sparse`]) are
//! tried, and only for refusals more points cure ([`worth_densifying`]); a pair whose
//! own scans cannot be prepared is left refused.

use crate::chained::{congruence, LinkSource};
use crate::matching::{prepare_scan, store_rays, MatchStats};
use crate::rejection::{MatchFailure, Rejection};
use crate::sweep::compensate_into;
use odocal_icp::{IcpParams, IcpResult, Matcher, PreparedScan};
use odocal_log::ScanStore;
use odocal_solver::Predictor;
use rayon::prelude::*;
use std::borrow::Cow;
use std::collections::{BTreeSet, HashMap};

/// Scans merged into each scan of a refused pair at least: the one before the first
/// scan, the one after the second (one scan period of odometry each). Two each
/// matched 2 % more of the simulated Neato's pairs, but on the real MinesRover logs
/// thinned to a Neato-like scan (a skid-steer that slips in turns) they agreed worse
/// with the full logs than one each, and than without the stage (docs/benchmarks.md,
/// stop 37).
pub const NEIGHBOURS: usize = 1;

/// Scans merged into each scan of a refused pair at most: a cloud takes the next
/// scan beyond it while it holds fewer than [`CLOUD_POINTS`] points. A scan of 20–30
/// returns (the Neato in open or dark rooms) is too sparse with one neighbour. Up to
/// four a side matched 1 % more of the simulated Neato's pairs than two, but clouds of
/// three or four neighbours a side were 5–22 mm off along the motion (the placement's
/// odometry error), and ℓx's calibration error on 30 logs went to 1.08σ RMS with two
/// values beyond 3σ (docs/benchmarks.md, stop 40).
pub const MAX_NEIGHBOURS: usize = 2;

/// Points a cloud holds before it takes another neighbour: with its 40 % share of its
/// own points and 20 correspondences, a cloud of fewer is rarely matched. A scan of 30
/// returns or more (the Neato's usual 40–80, the thinned real logs') takes its one
/// neighbour only: at 80 points the thinned real logs took a second one, gained no
/// samples and agreed worse with their full logs.
pub const CLOUD_POINTS: usize = 60;

/// Valid readings a scan of a refused pair needs here (the matcher asks
/// [`IcpParams::min_valid_points`] of a scan matched alone): a scan of 10 to 19
/// returns, refused alone, is matched with the neighbours that make its cloud.
pub const MIN_OWN_POINTS: usize = 10;

/// Whether a pair of sparse scans refused for `failure` is worth matching with its
/// neighbouring scans: refusals for too few points in common (too few
/// correspondences, too small a share of the current scan explained) or in a scan
/// (fewer valid readings than a scan matched alone needs), which more points cure; a
/// scan that cannot be read at all stays refused when the stage prepares it. Not a
/// displacement the walls do not constrain (a corridor stays one with more points
/// along it: of the Neato's pairs refused as ill-conditioned, 17 % were matched with
/// their neighbours, at the cost of a full correlative search each), nor ambiguity or
/// iterations that did not settle (4 of 45).
pub fn worth_densifying(failure: &MatchFailure) -> bool {
    matches!(
        failure.reason,
        Rejection::Correspondences | Rejection::Overlap | Rejection::Scan
    )
}

/// The shares of a cloud's match `r` that rest on placed points (reference side,
/// current side), in [0, 1]: of the reference cloud's `reference_points`, those that
/// are not its scan's `reference_own`; of the current cloud's correspondences used,
/// those that are not its scan's own (`matched_share` of its `current_own` points).
fn placed_shares(
    r: &IcpResult,
    reference_own: usize,
    reference_points: usize,
    current_own: usize,
) -> (f64, f64) {
    let reference = 1.0 - reference_own as f64 / reference_points.max(1) as f64;
    let own_used = r.matched_share * current_own as f64;
    let current = 1.0 - own_used / r.correspondences.max(1) as f64;
    (reference.clamp(0.0, 1.0), current.clamp(0.0, 1.0))
}

/// The covariance a cloud's match gets from its neighbours' placement: each side's
/// placement error, odometry's over that side's `n` scan periods (the residuals' σ
/// `sigma` of a pair of `interval` scan periods, scaled by `n / interval`), weighted
/// by the `share` of the match that rests on placed points (reference side: of the
/// cloud's points; current side: of the correspondences used). The current side's
/// error is in the second scan's frame, turned by `theta` into the first's.
///
/// The residuals' σ holds the matches' error too, so this is an upper bound of the
/// placement's: on the simulated Neato (seeds 1–3 × 120 s) the clouds' matches
/// beyond 5 mm / 0.5° of the truth were 71 where their covariances predicted 58
/// without it, 90 with it (docs/benchmarks.md, stop 40).
fn placement_covariance(
    sigma: [f64; 3],
    interval: usize,
    reference: (u32, f64),
    current: (u32, f64),
    theta: f64,
) -> [[f64; 3]; 3] {
    let (s, c) = theta.sin_cos();
    let identity = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let turn = [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]];
    let mut out = [[0.0; 3]; 3];
    for ((n, share), into_first) in [(reference, identity), (current, turn)] {
        let k = share * n as f64 / interval as f64;
        let v = sigma.map(|x| (k * x).powi(2));
        if !v.iter().all(|x| x.is_finite()) {
            continue;
        }
        let side = [[v[0], 0.0, 0.0], [0.0, v[1], 0.0], [0.0, 0.0, v[2]]];
        let cells = out.iter_mut().flatten();
        cells
            .zip(congruence(&into_first, &side).iter().flatten())
            .for_each(|(o, a)| *o += a);
    }
    out
}

/// The scans `indices` of `scans`, each prepared once (in parallel), by index.
fn prepare_all(
    scans: &ScanStore,
    indices: impl Iterator<Item = usize>,
    params: &IcpParams,
) -> HashMap<usize, PreparedScan> {
    let unique: BTreeSet<usize> = indices.collect();
    let unique: Vec<usize> = unique.into_iter().collect();
    let rays = store_rays(scans);
    unique
        .par_iter()
        .filter_map(|&i| Some((i, prepare_scan(scans, &rays, i, params)?.ok()?)))
        .collect::<Vec<_>>()
        .into_iter()
        .collect()
}

/// The points of scan `anchor` and of those of `neighbours` (nearest first)
/// odometry can place in its frame, and how many those are; `None` when the anchor is
/// unusable or the cloud cannot be prepared. It takes at least [`NEIGHBOURS`] of
/// them, then more while it holds fewer than [`CLOUD_POINTS`] points.
fn cloud(
    source: &LinkSource<'_>,
    predictor: &Predictor,
    prepared: &HashMap<usize, PreparedScan>,
    anchor: usize,
    neighbours: impl Iterator<Item = usize>,
    params: &IcpParams,
) -> Option<(PreparedScan, u32)> {
    let own = prepared.get(&anchor)?.points();
    let mut placed_points = Vec::new();
    let mut placed = 0;
    for (taken, n) in neighbours.enumerate() {
        if taken >= NEIGHBOURS && own.len() + placed_points.len() >= CLOUD_POINTS {
            break;
        }
        let (Some(scan), Some(pose)) = (prepared.get(&n), source.odometry(predictor, anchor, n))
        else {
            continue;
        };
        placed_points.extend(scan.points().iter().map(|p| pose.transform_point(*p)));
        placed += 1;
    }
    Some((
        PreparedScan::from_points(own, &placed_points, params).ok()?,
        placed,
    ))
}

/// Matches the pairs refused in `results` (one per pair of `pairs`) with a sparse scan
/// again as clouds of their scans and neighbours (see the module documentation), and
/// replaces each one accepted (its `neighbours` above 0 say so).
/// `scans` are the scans the pairs were matched on: with `compensated` (swept scans
/// compensated with `source.params`) the neighbours are compensated into them
/// first. Without an estimate (`source.params`) nothing is placed, so nothing is
/// tried.
pub fn rescue_with_neighbours(
    source: &LinkSource<'_>,
    scans: &mut Cow<'_, ScanStore>,
    compensated: bool,
    pairs: &[(usize, usize)],
    results: &mut [Result<MatchStats, MatchFailure>],
    params: &IcpParams,
) {
    let Some(estimate) = source.params else {
        return;
    };
    // Rays closer than the sparse matcher's (every laser but a 1° LDS): no scan of
    // the pair can be sparse, and none is prepared to find out.
    let coarse = |i: usize| {
        scans
            .get(i)
            .is_some_and(|s| odocal_icp::coarse_rays(&s.geometry.angles))
    };
    let refused: Vec<usize> = (0..pairs.len())
        .filter(|&k| matches!(&results[k], Err(f) if worth_densifying(f)))
        .filter(|&k| coarse(pairs[k].0) || coarse(pairs[k].1))
        .collect();
    if refused.is_empty() {
        return;
    }
    // Every scan of the stage is prepared with as few as MIN_OWN_POINTS returns; the
    // clouds and their matches ask what `params` ask.
    let scan_params = IcpParams {
        min_valid_points: params.min_valid_points.min(MIN_OWN_POINTS),
        ..params.clone()
    };
    // The pairs' own scans (compensated already when the sweep is): is one sparse?
    let own = prepare_all(
        scans,
        refused.iter().flat_map(|&k| [pairs[k].0, pairs[k].1]),
        &scan_params,
    );
    let sparse = |i: usize| own.get(&i).is_some_and(|s| s.is_sparse(params));
    let refused: Vec<usize> = refused
        .into_iter()
        .filter(|&k| sparse(pairs[k].0) || sparse(pairs[k].1))
        .collect();
    if refused.is_empty() {
        return;
    }
    let count = source.scans.len();
    // Nearest first.
    let reference_side = |a: usize| (a.saturating_sub(MAX_NEIGHBOURS)..a).rev();
    let current_side = move |b: usize| (b + 1)..(b + 1 + MAX_NEIGHBOURS).min(count);
    let mut neighbours: BTreeSet<usize> = refused
        .iter()
        .flat_map(|&k| reference_side(pairs[k].0).chain(current_side(pairs[k].1)))
        .filter(|n| !own.contains_key(n))
        .collect();
    if compensated {
        let out = scans.to_mut();
        // A neighbour whose sweep the counts do not cover is left out: as read, its
        // points would be distorted by the sweep the others are compensated for.
        neighbours.retain(|&n| {
            compensate_into(
                out,
                source.scans,
                n,
                source.track,
                source.limits,
                estimate,
                source.time_offset,
            )
        });
    }
    let mut prepared = prepare_all(scans, neighbours.into_iter(), &scan_params);
    prepared.extend(own);
    let predictor = Predictor::new(estimate, source.use_profile);
    // The clouds are placed and guessed by odometry with the estimate: a match far
    // beyond the error its residuals show is refused, as in the second pass (the
    // first pass's clouds too: their guesses are odometry with the bootstrap's
    // estimate, whose residuals' σ is `source.residual_sigma`).
    let params = &match (&params.guess_window, source.residual_sigma) {
        (None, Some(sigma)) => IcpParams {
            guess_window: crate::guess_window::from_residuals(sigma),
            ..params.clone()
        },
        _ => params.clone(),
    };
    let rescued: Vec<Option<MatchStats>> = refused
        .par_iter()
        .map(|&k| {
            let (a, b) = pairs[k];
            let (reference, before) =
                cloud(source, &predictor, &prepared, a, reference_side(a), params)?;
            let (current, after) =
                cloud(source, &predictor, &prepared, b, current_side(b), params)?;
            if before + after == 0 {
                return None;
            }
            let guess = source.guess(Some(&predictor), a, b);
            let r = Matcher::new(params.clone())
                .match_scans(&reference, &current, guess)
                .ok()?;
            if r.ill_conditioned {
                return None;
            }
            let mut stats = MatchStats {
                neighbours: before + after,
                ..MatchStats::of(&r)
            };
            if let Some(sigma) = source.residual_sigma {
                let points = |i: usize| prepared.get(&i).map_or(0, |s| s.points().len());
                let (reference_share, current_share) =
                    placed_shares(&r, points(a), reference.valid_count(), points(b));
                let add = placement_covariance(
                    sigma,
                    b.saturating_sub(a).max(1),
                    (before, reference_share),
                    (after, current_share),
                    r.pose.theta,
                );
                let cells = stats.covariance.iter_mut().flatten();
                cells.zip(add.iter().flatten()).for_each(|(v, a)| *v += a);
            }
            Some(stats)
        })
        .collect();
    for (k, m) in refused.into_iter().zip(rescued) {
        if let Some(m) = m {
            results[k] = Ok(m);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_placement_adds_what_rests_on_placed_points() {
        let sigma = [0.004, 0.002, 0.003];
        // Nothing placed, or nothing resting on it: nothing added.
        assert_eq!(
            placement_covariance(sigma, 2, (0, 0.5), (0, 0.5), 0.3),
            [[0.0; 3]; 3]
        );
        assert_eq!(
            placement_covariance(sigma, 2, (1, 0.0), (2, 0.0), 0.3),
            [[0.0; 3]; 3]
        );
        // One neighbour a side, half of each side placed, a pair of two periods:
        // each side adds (σ / 4)².
        let c = placement_covariance(sigma, 2, (1, 0.5), (1, 0.5), 0.0);
        for (i, s) in sigma.iter().enumerate() {
            assert!((c[i][i] - 2.0 * (s / 4.0).powi(2)).abs() < 1e-15, "{c:?}");
        }
        // The current side turned by 90°: its x and y swap.
        let c = placement_covariance(sigma, 1, (0, 0.0), (1, 1.0), std::f64::consts::FRAC_PI_2);
        assert!((c[0][0] - sigma[1].powi(2)).abs() < 1e-15, "{c:?}");
        assert!((c[1][1] - sigma[0].powi(2)).abs() < 1e-15, "{c:?}");
        assert!(c[0][1].abs() < 1e-15 && c[0][1] == c[1][0], "{c:?}");
        // A σ that is not finite adds nothing.
        let c = placement_covariance([f64::NAN, 0.0, 0.0], 1, (1, 1.0), (1, 1.0), 0.0);
        assert_eq!(c, [[0.0; 3]; 3]);
    }
}
