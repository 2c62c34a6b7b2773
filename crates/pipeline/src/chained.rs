//! Pairs the matcher refused, matched again through the scans between them.
//!
//! A pair `(a, b)` is refused mostly because its two scans see too little of one
//! scene (a fast robot, a turn, sparse returns, people walking through): on the real
//! MinesRover logs, scans 0.4 s apart share 60–70 % of their points, and neighbouring
//! scans 0.1 s apart match far more often. Such a pair is split at its middle scan `m` and the
//! halves `(a, m)`, `(m, b)` are matched, each from the odometry guess of its own
//! interval; a half that is refused is split again, down to [`MAX_LINKS`] links of
//! at least one scan period. When every link is accepted, the pair's ŝ is their
//! composition `ŝ_am ⊕ ŝ_mb`, with the first-order covariance of the composition
//! (the links' errors taken as independent, which they are up to the noise of the
//! scan they share). The pair keeps its interval, so the sample is the same sample
//! the direct match would have given, with the error of a few short matches instead
//! of one long one.
//!
//! Only pairs refused for what closer scans cure are tried again: not those with a
//! scan the matcher cannot use at all, nor those whose sweep the encoders do not
//! cover.

use crate::matching::{match_pairs, MatchStats};
use crate::rejection::{MatchFailure, Rejection};
use crate::samples::wheel_only_sample;
use crate::sweep::compensate_into;
use crate::sync::{DiscardReason, EncoderTrack, SyncLimits};
use odocal_geom::Pose2;
use odocal_icp::IcpParams;
use odocal_log::ScanStore;
use odocal_solver::{Params, Predictor};
use std::borrow::Cow;

/// Links a refused pair may be matched through at most: each link's error adds to
/// the pair's, so a chain of four short matches has about twice the error of one.
pub const MAX_LINKS: usize = 4;

/// Whether a pair refused for `failure` may be matched through its intermediate
/// scans: refusals that closer scans can cure (overlap, residuals, correspondences,
/// correction, conditioning, ambiguity, convergence); not an unusable scan, which
/// every chain would contain, nor a pair the sweep compensation could not cover.
pub fn worth_chaining(failure: &MatchFailure) -> bool {
    !matches!(failure.reason, Rejection::Scan | Rejection::Other)
}

/// What the links of a chain need besides the scans they are matched on: first
/// guesses by odometry over each link's own interval and, for swept scans, the sweep
/// compensation of the scans between a pair's two.
pub struct LinkSource<'a> {
    /// The log's scans as read (what compensation starts from).
    pub scans: &'a ScanStore,
    /// Each scan's reference time (s, laser clock; see [`crate::sweep::reference_time`]).
    pub scan_times: &'a [f64],
    /// The wheel counts.
    pub track: &'a EncoderTrack<'a>,
    /// The synchronization limits.
    pub limits: &'a SyncLimits,
    /// The estimate the guesses and the compensation use; `None`: identity guesses.
    pub params: Option<&'a Params>,
    /// The spread (σ of x, y, θ; m, m, rad) of the residuals `ŝ_pred − ŝ` of the solve
    /// that made `params`, over a pair's interval
    /// ([`odocal_solver::Calibration::sm_sigma`]): how wrong odometry with it is, at
    /// most. `None`: not known (a nominal given by hand, no estimate).
    pub residual_sigma: Option<[f64; 3]>,
    /// Guess with the encoder profile (non-constant speeds).
    pub use_profile: bool,
    /// Laser clock minus encoder clock (s).
    pub time_offset: f64,
}

impl LinkSource<'_> {
    /// The first guess of the displacement from scan `i` to scan `j`: odometry over
    /// the interval with the estimate, identity without one or where the wheels
    /// stood still or the counts do not cover the interval.
    pub(crate) fn guess(&self, predictor: Option<&Predictor>, i: usize, j: usize) -> Pose2 {
        predictor
            .and_then(|p| self.odometry(p, i, j))
            .unwrap_or(Pose2::IDENTITY)
    }

    /// The displacement of the sensor from scan `i` to scan `j` (either order) by
    /// odometry with `predictor`'s estimate; `None` where the counts do not cover the
    /// interval or the synchronization limits refuse it; the identity where the wheels
    /// stood still.
    pub(crate) fn odometry(&self, predictor: &Predictor, i: usize, j: usize) -> Option<Pose2> {
        let (&ti, &tj) = (self.scan_times.get(i)?, self.scan_times.get(j)?);
        let (t0, t1) = (ti.min(tj), ti.max(tj));
        let forward =
            match self
                .track
                .motion(t0 - self.time_offset, t1 - self.time_offset, self.limits)
            {
                Ok(w) => Pose2::from_array(predictor.predict(&wheel_only_sample(&w))),
                Err(DiscardReason::RobotStill) => Pose2::IDENTITY,
                Err(_) => return None,
            };
        Some(if tj >= ti { forward } else { forward.inverse() })
    }
}

/// Matches the pairs refused in `results` (one per pair of `pairs`, in time order)
/// through their intermediate scans, and replaces each one whose chain is accepted
/// by the composed match (its `links` above 1 say so). `scans` are the scans the pairs
/// were matched on: with `compensated` (swept scans compensated with
/// `source.params`) the scans between the two of a refused pair are compensated into
/// them first, and a pair whose scans between cannot be is left refused.
pub fn rescue_refused(
    source: &LinkSource<'_>,
    scans: &mut Cow<'_, ScanStore>,
    compensated: bool,
    pairs: &[(usize, usize)],
    results: &mut [Result<MatchStats, MatchFailure>],
    params: &IcpParams,
) {
    let mut refused: Vec<usize> = (0..pairs.len())
        .filter(|&k| matches!(&results[k], Err(f) if worth_chaining(f)))
        .filter(|&k| pairs[k].1 >= pairs[k].0 + 2)
        .collect();
    if refused.is_empty() {
        return;
    }
    if compensated {
        match source.params {
            Some(p) => {
                let out = scans.to_mut();
                refused.retain(|&k| {
                    let (a, b) = pairs[k];
                    (a + 1..b).all(|i| {
                        compensate_into(
                            out,
                            source.scans,
                            i,
                            source.track,
                            source.limits,
                            p,
                            source.time_offset,
                        )
                    })
                });
            }
            None => return,
        }
    }
    let predictor = source.params.map(|p| Predictor::new(p, source.use_profile));
    let chained_pairs: Vec<(usize, usize)> = refused.iter().map(|&k| pairs[k]).collect();
    let guess = |i: usize, j: usize| source.guess(predictor.as_ref(), i, j);
    let chained = match_through_intermediate_scans(scans, &chained_pairs, &guess, params);
    for (k, m) in refused.into_iter().zip(chained) {
        if let Some(m) = m {
            results[k] = Ok(m);
        }
    }
}

/// One piece of a pair's chain: its two scans and, once matched, the result.
#[derive(Debug, Clone)]
struct Link {
    first: usize,
    second: usize,
    matched: Option<MatchStats>,
}

impl Link {
    fn pending(first: usize, second: usize) -> Self {
        Link {
            first,
            second,
            matched: None,
        }
    }
}

/// Splits `(a, b)` at its middle scan; `None` when the scans are neighbours.
fn halves(a: usize, b: usize) -> Option<[Link; 2]> {
    (b >= a + 2).then(|| {
        let m = a + (b - a) / 2;
        [Link::pending(a, m), Link::pending(m, b)]
    })
}

/// Matches each pair `(a, b)` of `pairs` (in time order) through its intermediate
/// scans, as the module says. `guess(i, j)` is the first guess of the displacement
/// from scan `i` to scan `j` (odometry over that interval); `params` are the
/// matcher's, with the store's typical noise set. Returns, per pair, the composed
/// match when every link was accepted.
pub fn match_through_intermediate_scans(
    scans: &ScanStore,
    pairs: &[(usize, usize)],
    guess: &(dyn Fn(usize, usize) -> Pose2 + Sync),
    params: &IcpParams,
) -> Vec<Option<MatchStats>> {
    let mut chains: Vec<Option<Vec<Link>>> = pairs
        .iter()
        .map(|&(a, b)| halves(a, b).map(Vec::from))
        .collect();
    loop {
        // Every pending link of the chains still alive, in time order.
        let pending: Vec<(usize, usize)> = chains
            .iter()
            .enumerate()
            .filter_map(|(c, chain)| chain.as_ref().map(|links| (c, links)))
            .flat_map(|(c, links)| {
                links
                    .iter()
                    .enumerate()
                    .filter(|(_, l)| l.matched.is_none())
                    .map(move |(k, _)| (c, k))
            })
            .collect();
        if pending.is_empty() {
            break;
        }
        let link_pairs: Vec<(usize, usize)> = pending
            .iter()
            .map(|&(c, k)| {
                let l = &chains[c].as_ref().expect("alive")[k];
                (l.first, l.second)
            })
            .collect();
        let guesses: Vec<Pose2> = link_pairs.iter().map(|&(i, j)| guess(i, j)).collect();
        let results = match_pairs(scans, &link_pairs, &guesses, params, || {});
        // Split the refused links, last first so that earlier indices stay valid.
        for (&(c, k), result) in pending.iter().zip(results).rev() {
            let Some(links) = chains[c].as_mut() else {
                continue;
            };
            // A link that leaves a direction free is split like a refused one: the
            // composition carries covariances, not free directions.
            match result.ok().filter(MatchStats::fixes_every_direction) {
                Some(m) => links[k].matched = Some(m),
                None => {
                    let split =
                        halves(links[k].first, links[k].second).filter(|_| links.len() < MAX_LINKS);
                    match split {
                        Some(two) => {
                            links.splice(k..=k, two);
                        }
                        None => chains[c] = None,
                    }
                }
            }
        }
    }
    chains
        .into_iter()
        .map(|chain| {
            let links: Vec<MatchStats> = chain?.into_iter().filter_map(|l| l.matched).collect();
            compose(&links)
        })
        .collect()
}

/// The composition of consecutive matches: ŝ = ŝ₁ ⊕ ŝ₂ ⊕ …, its first-order
/// covariance, the iterations summed, the fewest correspondences of a link, and the
/// mean residual over every link's correspondences. `None` for no link.
pub fn compose(links: &[MatchStats]) -> Option<MatchStats> {
    let (first, rest) = links.split_first()?;
    let mut out = first.clone();
    let mut residual_sum = first.mean_residual * first.correspondences as f64;
    let mut correspondence_sum = first.correspondences;
    for link in rest {
        let (j_acc, j_link) = out.pose.compose_jacobians(&link.pose);
        let a = congruence(&j_acc, &out.covariance);
        let b = congruence(&j_link, &link.covariance);
        for (r, row) in out.covariance.iter_mut().enumerate() {
            for (c, v) in row.iter_mut().enumerate() {
                *v = a[r][c] + b[r][c];
            }
        }
        out.pose = out.pose.compose(&link.pose);
        out.iterations += link.iterations;
        out.correspondences = out.correspondences.min(link.correspondences);
        residual_sum += link.mean_residual * link.correspondences as f64;
        correspondence_sum += link.correspondences;
        out.links += link.links;
        out.neighbours += link.neighbours;
    }
    out.mean_residual = residual_sum / correspondence_sum.max(1) as f64;
    Some(out)
}

/// `J Σ Jᵀ`.
pub(crate) fn congruence(j: &[[f64; 3]; 3], sigma: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let mut out = [[0.0; 3]; 3];
    for (r, row) in out.iter_mut().enumerate() {
        for (c, v) in row.iter_mut().enumerate() {
            *v = (0..3)
                .flat_map(|p| (0..3).map(move |q| (p, q)))
                .map(|(p, q)| j[r][p] * sigma[p][q] * j[c][q])
                .sum();
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn stats(pose: Pose2, var: f64) -> MatchStats {
        MatchStats {
            pose,
            covariance: [[var, 0.0, 0.0], [0.0, var, 0.0], [0.0, 0.0, var / 100.0]],
            iterations: 5,
            correspondences: 300,
            mean_residual: 0.002,
            links: 1,
            neighbours: 0,
            free_direction: None,
        }
    }

    /// Odometry between scans, as the neighbouring-scan clouds place them
    /// ([`crate::local_map`]): backward in time it is the inverse of forward, over
    /// two periods the composition of the two, and the identity where the wheels
    /// stood still.
    #[test]
    fn odometry_between_scans_either_way() {
        use odocal_log::EncoderRecord;
        // Left wheel 10 ticks every 10 ms, right 14: a constant arc; still after 0.5 s.
        let encoders: Vec<EncoderRecord> = (0..=100)
            .map(|k| {
                let moving = k.min(50);
                EncoderRecord {
                    t: k as f64 * 0.01,
                    left: 10 * moving,
                    right: 14 * moving,
                    line: 0,
                }
            })
            .collect();
        let track = EncoderTrack::new(&encoders, 4096.0);
        let scan_times = [0.1, 0.2, 0.3, 0.6, 0.7];
        let limits = SyncLimits {
            max_encoder_gap: 0.05,
            still_ticks: 1.0,
            max_interval: 1.0,
        };
        let params = Params {
            r_l: 0.03,
            r_r: 0.03,
            b: 0.2,
            laser: Pose2::new(0.1, 0.02, 0.05),
        };
        let source = LinkSource {
            scans: &ScanStore::default(),
            scan_times: &scan_times,
            track: &track,
            limits: &limits,
            params: Some(&params),
            residual_sigma: None,
            use_profile: true,
            time_offset: 0.0,
        };
        let predictor = Predictor::new(&params, true);
        let forward = source.odometry(&predictor, 0, 1).unwrap();
        let backward = source.odometry(&predictor, 1, 0).unwrap();
        let e = forward.compose(&backward);
        assert!(forward.translation_norm() > 1e-3, "{forward}");
        assert!(e.translation_norm() < 1e-12 && e.theta.abs() < 1e-12, "{e}");
        let two = source.odometry(&predictor, 0, 2).unwrap();
        let chained = forward.compose(&source.odometry(&predictor, 1, 2).unwrap());
        let e = two.between(&chained);
        assert!(e.translation_norm() < 1e-9 && e.theta.abs() < 1e-9, "{e}");
        assert_eq!(source.odometry(&predictor, 3, 4), Some(Pose2::IDENTITY));
        assert_eq!(source.odometry(&predictor, 0, 9), None);
    }

    #[test]
    fn halves_split_at_the_middle_scan_down_to_neighbours() {
        let [a, b] = halves(10, 14).expect("four apart");
        assert_eq!((a.first, a.second, b.first, b.second), (10, 12, 12, 14));
        let [a, b] = halves(10, 13).expect("three apart");
        assert_eq!((a.first, a.second, b.first, b.second), (10, 11, 11, 13));
        assert!(halves(10, 11).is_none());
    }

    #[test]
    fn composition_is_the_pose_chain_with_its_propagated_covariance() {
        let l1 = stats(Pose2::new(0.1, 0.0, 0.2), 1e-6);
        let l2 = stats(Pose2::new(0.1, 0.01, -0.1), 4e-6);
        let c = compose(&[l1.clone(), l2.clone()]).expect("two links");
        assert_eq!(c.pose, l1.pose.compose(&l2.pose));
        assert_eq!(c.links, 2);
        assert_eq!(c.iterations, 10);
        // The rotation variances add; the second link's translation is rotated.
        assert!((c.covariance[2][2] - (1e-8 + 4e-8)).abs() < 1e-18);
        // Monte Carlo check of the first-order covariance (small errors: near exact).
        let n = 20_000;
        let mut m = [[0.0f64; 3]; 3];
        let mut state = 12345u64;
        let mut gauss = || {
            // Box–Muller on a small LCG: deterministic, no dependency.
            let mut u = || {
                state = state
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                ((state >> 11) as f64 + 0.5) / (1u64 << 53) as f64
            };
            let (a, b) = (u(), u());
            (-2.0 * a.ln()).sqrt() * (std::f64::consts::TAU * b).cos()
        };
        for _ in 0..n {
            let e1 = [gauss() * 1e-3, gauss() * 1e-3, gauss() * 1e-4];
            let e2 = [gauss() * 2e-3, gauss() * 2e-3, gauss() * 2e-4];
            let p1 = Pose2::new(l1.pose.x + e1[0], l1.pose.y + e1[1], l1.pose.theta + e1[2]);
            let p2 = Pose2::new(l2.pose.x + e2[0], l2.pose.y + e2[1], l2.pose.theta + e2[2]);
            let d = p1.compose(&p2).to_array();
            let e = [d[0] - c.pose.x, d[1] - c.pose.y, d[2] - c.pose.theta];
            for (row, er) in m.iter_mut().zip(e) {
                for (v, ek) in row.iter_mut().zip(e) {
                    *v += er * ek / n as f64;
                }
            }
        }
        for (r, row) in m.iter().enumerate() {
            for (k, v) in row.iter().enumerate() {
                let scale = (c.covariance[r][r] * c.covariance[k][k]).sqrt();
                assert!(
                    (v - c.covariance[r][k]).abs() < 0.05 * scale,
                    "[{r}][{k}]: sampled {v} against propagated {}",
                    c.covariance[r][k]
                );
            }
        }
    }

    #[test]
    fn no_links_compose_to_nothing() {
        assert!(compose(&[]).is_none());
    }
}
