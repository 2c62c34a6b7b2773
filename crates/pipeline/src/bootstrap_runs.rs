//! The bootstrap's matches without a nominal: runs of consecutive pairs, each pair
//! guessed by the motion the pair before it in its run measured.
//!
//! Without parameters there is no odometry to guess a pair by, and matching from the
//! identity asks the matcher to find the whole motion: more iterations (4.1 against
//! 2.2 from an odometry guess on a 10-minute Khepera log), and at speed more motion
//! than it may correct (a real MinesRover at 0.6 m/s moves 24 cm between the scans of
//! a pair). The wheels still say how the motion changes from one pair to the next:
//! for small motions the sensor's displacement is about linear in the wheel rotations
//! `(Δφ_L, Δφ_R)`, so the previous pair's measured displacement, scaled by how much of
//! the previous pair's wheel rotation the next pair repeats, is a guess close to the
//! next pair's ([`predicted`]).
//!
//! A run's first pair, a pair after a failed one and a pair whose wheels turned in a
//! direction the previous pair's did not (a turn after a straight) start from the
//! identity as before; a pair that fails from its predicted guess is matched again
//! from the identity, so no pair is refused that the identity would have matched.
//! Runs are cut at fixed places (every [`BOOTSTRAP_RUN`] pairs of the kept pairs, and
//! wherever the chain breaks), so the results do not depend on the thread count.

use crate::matching::{match_prepared, prepared_or_failure, store_rays, MatchStats};
use crate::options::BOOTSTRAP_RUN;
use crate::rejection::MatchFailure;
use odocal_geom::Pose2;
use odocal_icp::{IcpParams, Matcher};
use odocal_log::ScanStore;
use rayon::prelude::*;
use std::ops::Range;

/// Smallest cosine of the angle between two consecutive pairs' wheel rotations
/// `(Δφ_L, Δφ_R)` for the first pair's displacement to guess the second's. Below it
/// (a spin after a straight, a reversal) the motion changed shape and the identity
/// is the guess.
pub const MIN_SAME_MOTION_COSINE: f64 = 0.9;

/// Largest ratio of the next pair's wheel rotation to the previous pair's that the
/// previous displacement is scaled by; beyond it the identity is the guess.
pub const MAX_SCALE: f64 = 3.0;

/// One bootstrap pair: its scans and its wheel rotations `(Δφ_L, Δφ_R)` (rad).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BootstrapPair {
    /// Index of the pair among the kept pairs (the runs are cut every
    /// [`BOOTSTRAP_RUN`] of them).
    pub kept: usize,
    /// The reference scan.
    pub first: usize,
    /// The current scan.
    pub second: usize,
    /// Wheel rotations `(Δφ_L, Δφ_R)` over the pair (rad).
    pub wheels: [f64; 2],
}

impl BootstrapPair {
    /// Synchronized samples as bootstrap pairs, the kept index being each one's
    /// position (to match a log's pairs again as the bootstrap would: benches, tests).
    pub fn of_samples(samples: &[crate::samples::PairSample]) -> Vec<BootstrapPair> {
        samples
            .iter()
            .enumerate()
            .map(|(k, s)| BootstrapPair {
                kept: k,
                first: s.pair.first,
                second: s.pair.second,
                wheels: [s.wheel.dphi_l, s.wheel.dphi_r],
            })
            .collect()
    }
}

/// The guess for a pair with wheel rotations `next` from the displacement
/// `previous` measured over the pair before it, whose wheels turned `by`: `previous`
/// scaled by the projection of `next` on `by`; `None` (the identity is the guess)
/// when the wheels did not turn before, or turned differently
/// ([`MIN_SAME_MOTION_COSINE`], [`MAX_SCALE`]).
pub fn predicted(previous: &Pose2, by: [f64; 2], next: [f64; 2]) -> Option<Pose2> {
    let dot = by[0] * next[0] + by[1] * next[1];
    let (n_by, n_next) = (by[0].hypot(by[1]), next[0].hypot(next[1]));
    if !(n_by > 0.0 && n_next > 0.0) || dot < MIN_SAME_MOTION_COSINE * n_by * n_next {
        return None;
    }
    let scale = dot / (n_by * n_by);
    (scale <= MAX_SCALE && previous.is_finite()).then(|| {
        Pose2::new(
            scale * previous.x,
            scale * previous.y,
            scale * previous.theta,
        )
    })
}

/// The runs of `pairs`: ranges of consecutive entries whose kept indices fall in one
/// block of [`BOOTSTRAP_RUN`] and which chain (each pair's first scan is the previous
/// pair's second).
pub fn runs(pairs: &[BootstrapPair]) -> Vec<Range<usize>> {
    let mut out = Vec::new();
    let mut start = 0;
    for k in 1..=pairs.len() {
        let cut = pairs.get(k).is_none_or(|p| {
            let q = &pairs[k - 1];
            p.kept / BOOTSTRAP_RUN != q.kept / BOOTSTRAP_RUN || p.first != q.second
        });
        if cut {
            out.push(start..k);
            start = k;
        }
    }
    out
}

/// Matches `pairs` run by run ([`runs`]), the runs in parallel (rayon's current
/// pool), each pair from the guess its predecessor's result predicts, or the
/// identity; results in the order of `pairs`. `params` must carry the log's typical
/// noise. `done` is called once per pair.
pub fn match_runs(
    scans: &ScanStore,
    pairs: &[BootstrapPair],
    params: &IcpParams,
    done: impl Fn() + Sync + Send,
) -> Vec<Result<MatchStats, MatchFailure>> {
    let rays = store_rays(scans);
    let prepare = |i: usize| prepared_or_failure(scans, &rays, i, params);
    let per_run: Vec<Vec<Result<MatchStats, MatchFailure>>> = runs(pairs)
        .into_par_iter()
        .map_init(
            || Matcher::new(params.clone()),
            |matcher, run| {
                let mut out: Vec<Result<MatchStats, MatchFailure>> = Vec::with_capacity(run.len());
                // The previous pair's current scan: this pair's reference (a run chains).
                let mut next_reference = None;
                for k in run {
                    let pair = &pairs[k];
                    let reference = next_reference.take().unwrap_or_else(|| prepare(pair.first));
                    let current = prepare(pair.second);
                    let guess = out.last().and_then(|last| {
                        let previous = last.as_ref().ok()?;
                        predicted(&previous.pose, pairs[k - 1].wheels, pair.wheels)
                    });
                    let from_guess =
                        guess.map(|g| match_prepared(matcher, &reference, &current, g));
                    let result = match from_guess {
                        Some(Ok(m)) => Ok(m),
                        _ => match_prepared(matcher, &reference, &current, Pose2::IDENTITY),
                    };
                    out.push(result);
                    done();
                    next_reference = Some(current);
                }
                out
            },
        )
        .collect();
    per_run.into_iter().flatten().collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_repeated_motion_is_guessed_scaled_by_the_wheels() {
        let previous = Pose2::new(0.03, 0.001, 0.1);
        let same = predicted(&previous, [1.0, 1.2], [1.0, 1.2]).unwrap();
        assert_eq!(same, previous);
        let faster = predicted(&previous, [1.0, 1.2], [1.5, 1.8]).unwrap();
        assert!((faster.x - 0.045).abs() < 1e-12 && (faster.theta - 0.15).abs() < 1e-12);
        // Backwards along the same line: the previous motion reversed is no longer
        // "repeated" (cosine −1), so the identity.
        assert_eq!(predicted(&previous, [1.0, 1.2], [-1.0, -1.2]), None);
    }

    #[test]
    fn a_changed_motion_or_none_before_is_not_guessed() {
        let previous = Pose2::new(0.03, 0.0, 0.0);
        // A spin after a straight: the wheels turn in another direction.
        assert_eq!(predicted(&previous, [1.0, 1.0], [-1.0, 1.0]), None);
        // The robot stood still before.
        assert_eq!(predicted(&previous, [0.0, 0.0], [1.0, 1.0]), None);
        // Four times as far: beyond the largest scale.
        assert_eq!(predicted(&previous, [1.0, 1.0], [4.0, 4.0]), None);
        // A non-finite previous motion.
        let bad = Pose2::new(f64::NAN, 0.0, 0.0);
        assert_eq!(predicted(&bad, [1.0, 1.0], [1.0, 1.0]), None);
    }

    fn pair(kept: usize, first: usize, second: usize) -> BootstrapPair {
        BootstrapPair {
            kept,
            first,
            second,
            wheels: [1.0, 1.0],
        }
    }

    #[test]
    fn runs_are_cut_every_block_of_kept_pairs_and_where_the_chain_breaks() {
        let n = BOOTSTRAP_RUN;
        // Kept pairs 0..n+3 chained, except that pair 2 does not start where 1 ended
        // (a discarded pair between them).
        let mut pairs: Vec<BootstrapPair> = (0..n + 3).map(|k| pair(k, 4 * k, 4 * k + 4)).collect();
        pairs[2].first += 4;
        pairs[2].second += 4;
        for p in &mut pairs[3..] {
            p.first += 4;
            p.second += 4;
        }
        assert_eq!(runs(&pairs), vec![0..2, 2..n, n..n + 3]);
        // An evenly spread subset: blocks far apart are never one run.
        let spread = vec![pair(0, 0, 4), pair(1, 4, 8), pair(4 * n, 8, 12)];
        assert_eq!(runs(&spread), vec![0..2, 2..3]);
        assert!(runs(&[]).is_empty());
    }
}
