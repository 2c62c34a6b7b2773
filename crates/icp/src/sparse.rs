//! Sparse scans: many readings without a return, and what matching does about them.
//!
//! Dark, glancing or distant surfaces return nothing on many rays of real range
//! finders (55 % of a real URG-04LX's readings on the MinesRover logs; an RPLIDAR or a
//! Neato LDS loses returns at random along a wall). The scan then falls apart into
//! short runs and isolated points, and a right match loses most of its points at their
//! ends. A scan is **sparse** when readings without a return are common (at least
//! [`SPARSE_SCAN_SHARE`] of them) or scattered along the surfaces (at least
//! [`SCATTERED_SHARE`] of the readings in gaps of at most [`MAX_BRIDGED_GAP`]
//! between returns). A sparse scan is prepared with its own lines as any scan (runs
//! followed a little past an end at a reading without a return only when such
//! readings are common) and also in a *bridged* form (`PreparedScan::bridged`) where
//! - a run that ends at a reading without a return is followed a little past its end
//!   (`correspondence::segment_for`),
//! - an isolated point (on no usable segment) gets the line through it and its nearest
//!   returns across such short gaps, when they lie on one surface ([`isolated_lines`]),
//! - the segments of a run shorter than the line-fit window get the line through the
//!   run and those returns ([`widen_short_runs`]): two or three noisy points fix a
//!   direction poorly, and such chance directions also make a featureless pair look
//!   well conditioned.
//!
//! A pair is matched with the bridged forms only when its own lines explain too small
//! a share of the current scan ([`worth_bridging`]); a pair they match keeps that
//! result. Used on every pair of a sparse scan, the bridged lines moved matches that
//! were right (the simulated Pioneer's scans are sparse, and its calibrations then
//! disagreed beyond their σ in the fast-robot Monte Carlo). Measured on the realistic
//! presets (120 s, seeds 1–3, docs/benchmarks.md): pairs with a true overlap of at
//! least half matched 88 → 93 % (mines-rover), 28 → 30 % (neato-lds), 57 → 84 %
//! (turtlebot4-rplidar); of the accepted matches, about as large a share as before is
//! beyond 5 mm / 0.5° of the truth (31, 57, 14 %; 30, 57, 16 % before).
//!
//! Elsewhere nothing changes: scans that are not sparse have no bridged form, and the
//! simulator's rare dropouts (0.1 %) and readings beyond the range (open space: long
//! gaps) do not make a scan sparse.

use crate::preprocess::{Moments, SegmentLine};
use crate::{IcpError, IcpParams};

/// Share of readings without a return from which a scan is sparse.
const SPARSE_SCAN_SHARE: f64 = 0.45;

/// Share of the readings in short gaps (dropouts between returns) from which a scan
/// is sparse: measured 5–10 % on the realistic presets, at most 0.9 % on the clean
/// ones (TurtleBot class 0.9 %, Khepera, office, Pioneer 0.1 %).
const SCATTERED_SHARE: f64 = 0.03;

/// Longest gap of readings without a return bridged (rays).
pub(crate) const MAX_BRIDGED_GAP: usize = 3;

/// Returns taken on each side of an isolated point for its line.
const SIDE_POINTS: usize = 2;

/// Whether a pair whose scans' own lines end in `error` is matched again with the
/// lines across short gaps: only when the own lines converged, consistently with the
/// scans' noise, but explained too small a share of the current scan (a scan fallen
/// apart into short runs loses the points at their ends). Not after too few
/// correspondences: there the lines across the gaps would be the whole evidence (on
/// the Neato preset 36 of the 42 pairs they matched were beyond 5 mm / 0.5° of the
/// truth); nor after residuals above the noise, no convergence, an ambiguity, a
/// correction too large or a numerical failure: the lines do not remove their cause.
pub(crate) fn worth_bridging(error: &IcpError) -> bool {
    matches!(error, IcpError::SmallOverlap { .. })
}

/// `missing[i]`: reading `i` got no return (zero, non-finite or at most `lo`, m).
pub(crate) fn missing_readings(ranges: &[f32], lo: f64) -> Vec<bool> {
    ranges
        .iter()
        .map(|&r| !r.is_finite() || f64::from(r) <= lo)
        .collect()
}

/// Whether the scan with these readings without a return is sparse (see the module
/// documentation).
pub(crate) fn is_sparse(missing: &[bool]) -> bool {
    missing_share_is_sparse(missing)
        || scattered(missing) as f64 >= SCATTERED_SHARE * missing.len() as f64
}

/// Whether readings without a return are common: at least [`SPARSE_SCAN_SHARE`] of
/// them (the scan's own runs are then followed past their ends at such readings even
/// in the first match of a pair).
pub(crate) fn missing_share_is_sparse(missing: &[bool]) -> bool {
    let count = missing.iter().filter(|&&m| m).count();
    count as f64 >= SPARSE_SCAN_SHARE * missing.len() as f64
}

/// Readings without a return in gaps of at most [`MAX_BRIDGED_GAP`] between readings
/// that returned (valid or beyond the range).
fn scattered(missing: &[bool]) -> usize {
    let mut count = 0;
    let mut i = 0;
    while i < missing.len() {
        if !missing[i] {
            i += 1;
            continue;
        }
        let start = i;
        while i < missing.len() && missing[i] {
            i += 1;
        }
        if start > 0 && i < missing.len() && i - start <= MAX_BRIDGED_GAP {
            count += i - start;
        }
    }
    count
}

/// Per reading, the line of an isolated valid point of a sparse scan: the
/// total-least-squares line through it and up to [`SIDE_POINTS`] returns on each
/// side, reached across gaps of at most [`MAX_BRIDGED_GAP`] readings without a return,
/// each within the distance that connects two points on one surface (as for runs,
/// scaled by the rays between them); only with at least three points and a fit within
/// `max_line_fit_rms`. `isolated[i]`: point `i` is valid and on no usable segment.
pub(crate) fn isolated_lines(
    points: &[[f64; 2]],
    angles: &[f64],
    valid: &[bool],
    missing: &[bool],
    isolated: impl Fn(usize) -> bool,
    params: &IcpParams,
) -> Vec<Option<SegmentLine>> {
    let n = points.len();
    let mut lines = vec![None; n];
    let mut chosen: Vec<usize> = Vec::with_capacity(2 * SIDE_POINTS + 1);
    for (j, line) in lines.iter_mut().enumerate() {
        if !isolated(j) {
            continue;
        }
        chosen.clear();
        chosen.push(j);
        for step in [-1isize, 1] {
            bridged_returns(points, angles, valid, missing, j, step, params, &mut chosen);
        }
        if chosen.len() >= 3 {
            *line = fit_line(points, &chosen, params)
                .map(|fitted| with_incidence(fitted, incidence(&fitted, points[j])));
        }
    }
    lines
}

/// Up to [`SIDE_POINTS`] returns beyond point `from` in direction `step` (±1),
/// reached across gaps of at most [`MAX_BRIDGED_GAP`] readings without a return, each
/// on one surface with the one before (appended to `out`). A reading beyond the
/// range, a longer gap or a jump ends the walk.
#[allow(clippy::too_many_arguments)]
fn bridged_returns(
    points: &[[f64; 2]],
    angles: &[f64],
    valid: &[bool],
    missing: &[bool],
    from: usize,
    step: isize,
    params: &IcpParams,
    out: &mut Vec<usize>,
) {
    let n = points.len() as isize;
    let mut last = from;
    let mut taken = 0;
    let mut gap = 0;
    let mut k = from as isize + step;
    while taken < SIDE_POINTS && (0..n).contains(&k) {
        let ku = k as usize;
        if valid[ku] {
            if !on_one_surface(points, angles, last, ku, params) {
                return;
            }
            out.push(ku);
            taken += 1;
            last = ku;
            gap = 0;
        } else if missing[ku] && gap < MAX_BRIDGED_GAP {
            gap += 1;
        } else {
            return;
        }
        k += step;
    }
}

/// In a sparse scan, the segments of a run shorter than `line_fit_window` points get
/// the line through the run and up to [`SIDE_POINTS`] returns on each side across
/// short gaps without a return (as isolated points do), when there are such returns
/// and the line fits within `max_line_fit_rms`: a direction fixed by two or three
/// noisy points is poor, and the surface goes on across the gaps.
/// `connected[i]`: points `i` and `i + 1` are on one run.
pub(crate) fn widen_short_runs(
    points: &[[f64; 2]],
    angles: &[f64],
    valid: &[bool],
    missing: &[bool],
    connected: &[bool],
    segments: &mut [Option<SegmentLine>],
    params: &IcpParams,
) {
    let n = points.len();
    let mut chosen: Vec<usize> = Vec::with_capacity(params.line_fit_window + 2 * SIDE_POINTS);
    let mut start = 0;
    while start < n {
        if !connected[start] {
            start += 1;
            continue;
        }
        let mut end = start + 1;
        while end < n && connected[end] {
            end += 1;
        }
        if end - start + 1 < params.line_fit_window {
            chosen.clear();
            chosen.extend(start..=end);
            bridged_returns(
                points,
                angles,
                valid,
                missing,
                start,
                -1,
                params,
                &mut chosen,
            );
            bridged_returns(points, angles, valid, missing, end, 1, params, &mut chosen);
            if chosen.len() > end - start + 1 {
                if let Some(line) = fit_line(points, &chosen, params) {
                    for (i, segment) in segments.iter_mut().enumerate().take(end).skip(start) {
                        let cos =
                            0.5 * (incidence(&line, points[i]) + incidence(&line, points[i + 1]));
                        *segment = Some(with_incidence(line, cos));
                    }
                }
            }
        }
        start = end + 1;
    }
}

/// Points `a` and `b` are close enough to be on one surface: within
/// `max(discontinuity_min_gap, discontinuity_gap_factor · range · Δangle)`.
fn on_one_surface(
    points: &[[f64; 2]],
    angles: &[f64],
    a: usize,
    b: usize,
    params: &IcpParams,
) -> bool {
    let (p, q) = (points[a], points[b]);
    let r = p[0].hypot(p[1]).max(q[0].hypot(q[1]));
    let allowed = params
        .discontinuity_min_gap
        .max(params.discontinuity_gap_factor * r * (angles[b] - angles[a]).abs());
    let (dx, dy) = (q[0] - p[0], q[1] - p[1]);
    dx * dx + dy * dy <= allowed * allowed
}

/// The total-least-squares line through the points `chosen` (the first one the
/// origin of the sums), if it fits within `max_line_fit_rms`.
fn fit_line(points: &[[f64; 2]], chosen: &[usize], params: &IcpParams) -> Option<SegmentLine> {
    let origin = points[chosen[0]];
    let mut moments = Moments::default();
    for &k in chosen {
        moments.add(points[k], origin, 1.0);
    }
    let fit = moments.fit(origin, chosen.len());
    let rms2 = params.max_line_fit_rms * params.max_line_fit_rms;
    if fit.smallest > rms2 * chosen.len() as f64 {
        return None;
    }
    let line = fit.line();
    line.normal[0].is_finite().then_some(line)
}

/// `line` (as fitted: incidence 1) with the incidence `incidence_cos` of its rays.
fn with_incidence(line: SegmentLine, incidence_cos: f64) -> SegmentLine {
    SegmentLine {
        incidence_cos,
        tilt_variance: line.tilt_variance * incidence_cos * incidence_cos,
        ..line
    }
}

/// |cos| of the incidence of the ray to point `p` on `line`.
fn incidence(line: &SegmentLine, p: [f64; 2]) -> f64 {
    (line.normal[0] * p[0] + line.normal[1] * p[1]).abs() / p[0].hypot(p[1])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::correspondence::segment_for;
    use crate::{Matcher, PreparedScan};
    use odocal_geom::Pose2;

    /// Ranges of 360 rays over a full turn from `pose` in a 5 m × 3.5 m room with a
    /// 0.6 m square pillar, the rays for which `lost(i)` got no return (0).
    fn room_scan(pose: Pose2, lost: impl Fn(usize) -> bool) -> PreparedScan {
        let angles: Vec<f64> = (0..360).map(|i| (i as f64 - 180.0).to_radians()).collect();
        let boxes = [
            ([-2.0, -1.5], [3.0, 2.0], true),
            ([0.8, 0.6], [1.4, 1.2], false),
        ];
        let ranges: Vec<f32> = angles
            .iter()
            .enumerate()
            .map(|(i, a)| {
                if lost(i) {
                    return 0.0;
                }
                let (s, c) = (pose.theta + a).sin_cos();
                let o = [pose.x, pose.y];
                let mut best = f64::INFINITY;
                for (lo, hi, inside) in boxes {
                    for axis in 0..2 {
                        let d = if axis == 0 { c } else { s };
                        for wall in [lo[axis], hi[axis]] {
                            let t = (wall - o[axis]) / d;
                            let other = 1 - axis;
                            let at = o[other] + t * if other == 0 { c } else { s };
                            let hit = t > 1e-9 && at >= lo[other] && at <= hi[other];
                            if hit && (inside || t < best) {
                                best = best.min(t);
                            }
                        }
                    }
                }
                best as f32
            })
            .collect();
        PreparedScan::new(&ranges, &angles, 0.02, 5.6, &IcpParams::default()).expect("scan")
    }

    /// A wall at y = 2 m seen by 181 rays over 90° of which every other one got no
    /// return, and a post (one return) at 1 m in front of it on ray 120.
    fn wall_every_other_ray() -> PreparedScan {
        let angles: Vec<f64> = (0..181)
            .map(|i| (45.0 + i as f64 * 0.5).to_radians())
            .collect();
        let ranges: Vec<f32> = angles
            .iter()
            .enumerate()
            .map(|(i, a)| match i {
                120 => 1.0,
                _ if i % 2 == 1 => 0.0,
                _ => (2.0 / a.sin()) as f32,
            })
            .collect();
        PreparedScan::new(&ranges, &angles, 0.02, 5.6, &IcpParams::default()).expect("scan")
    }

    #[test]
    fn scattered_dropouts_make_a_scan_sparse_and_open_space_does_not() {
        // 1 reading in 20 lost between returns: 5 % scattered.
        let dropouts: Vec<bool> = (0..400).map(|i| i % 20 == 10).collect();
        assert!(is_sparse(&dropouts));
        // 40 % of the readings missing in one block (open space): not sparse.
        let block: Vec<bool> = (0..400).map(|i| i >= 240).collect();
        assert!(!is_sparse(&block));
        // A rare dropout: not sparse.
        let rare: Vec<bool> = (0..400).map(|i| i == 200).collect();
        assert!(!is_sparse(&rare));
        // Half the readings missing: sparse whatever their pattern.
        let half: Vec<bool> = (0..400).map(|i| i >= 200).collect();
        assert!(is_sparse(&half));
    }

    #[test]
    fn isolated_points_on_a_surface_get_its_line_and_a_post_does_not() {
        let own = wall_every_other_ray();
        let scan = own.bridged();
        // No two consecutive returns: no run, no usable segment at all.
        assert_eq!(scan.usable_segment_count(), 0);
        // A point on the wall near the return of ray 90 (x = 0): before, no
        // correspondence (an isolated closest point); now the wall's line.
        let p = [0.004, 2.003];
        let seg = segment_for(scan, p, 90).expect("the line across the gaps");
        assert_eq!(seg, scan.len() + 90);
        let line = scan.line(seg).expect("a line");
        assert!(
            (line.normal[1] + 1.0).abs() < 1e-9 && (line.offset + 2.0).abs() < 1e-6,
            "{line:?}"
        );
        assert!((line.incidence_cos - 1.0).abs() < 1e-6);
        // The post's return has no neighbour on its surface: no line.
        let post = scan.point(120).expect("the post");
        assert_eq!(segment_for(scan, post, 120), None);
    }

    #[test]
    fn a_scan_that_is_not_sparse_has_no_isolated_lines() {
        // One isolated return between two long gaps in a scan whose other readings
        // are a wall: 2 % missing, not scattered: nothing changes there.
        let angles: Vec<f64> = (0..181)
            .map(|i| (45.0 + i as f64 * 0.5).to_radians())
            .collect();
        let ranges: Vec<f32> = angles
            .iter()
            .enumerate()
            .map(|(i, a)| match i {
                88 | 89 | 91 | 92 => 0.0,
                _ => (2.0 / a.sin()) as f32,
            })
            .collect();
        let scan =
            PreparedScan::new(&ranges, &angles, 0.02, 5.6, &IcpParams::default()).expect("scan");
        assert!(!scan.has_bridged() && scan.bridged().isolated_lines.is_empty());
        assert_eq!(segment_for(scan.bridged(), [0.004, 2.003], 90), None);
    }

    #[test]
    fn short_runs_of_a_sparse_scan_take_the_line_across_the_gaps() {
        // The wall y = 2 m seen as pairs of returns between single missing readings
        // (rays 3k and 3k + 1 return, 3k + 2 does not), the first of each pair 6 mm
        // long and the second 6 mm short: each pair's own segment is tilted by ≈ 33°.
        let angles: Vec<f64> = (0..181)
            .map(|i| (45.0 + i as f64 * 0.5).to_radians())
            .collect();
        let ranges: Vec<f32> = angles
            .iter()
            .enumerate()
            .map(|(i, a)| match i % 3 {
                0 => (2.0 / a.sin() + 0.006) as f32,
                1 => (2.0 / a.sin() - 0.006) as f32,
                _ => 0.0,
            })
            .collect();
        let scan =
            PreparedScan::new(&ranges, &angles, 0.02, 5.6, &IcpParams::default()).expect("scan");
        // The pair at rays 90, 91 (x ≈ 0): its segment's line is the wall's within 3°
        // (the line through the pair and two returns on each side).
        let line = scan.bridged().segments[90].expect("a line");
        let tilt = line.normal[0].atan2(-line.normal[1]).to_degrees();
        assert!(tilt.abs() < 3.0, "tilt {tilt}°: {line:?}");
        assert!((line.offset + 2.0).abs() < 0.005, "{line:?}");
    }

    #[test]
    fn a_sparse_scans_own_lines_stay_its_runs_and_the_bridged_ones_are_apart() {
        // The scan of `short_runs_of_a_sparse_scan_take_the_line_across_the_gaps`: 33 %
        // of its readings missing, all in single gaps (sparse by the scattered share
        // only).
        let angles: Vec<f64> = (0..181)
            .map(|i| (45.0 + i as f64 * 0.5).to_radians())
            .collect();
        let ranges: Vec<f32> = angles
            .iter()
            .enumerate()
            .map(|(i, a)| match i % 3 {
                0 => (2.0 / a.sin() + 0.006) as f32,
                1 => (2.0 / a.sin() - 0.006) as f32,
                _ => 0.0,
            })
            .collect();
        let scan =
            PreparedScan::new(&ranges, &angles, 0.02, 5.6, &IcpParams::default()).expect("scan");
        assert!(scan.has_bridged());
        // The scan's own segment at rays 90, 91 is the pair's chord (tilted ≈ 33°), and
        // its readings without a return are not followed past (fewer than 45 %): the
        // first match of a pair sees the scan as it did before the lines existed.
        let own = scan.segments[90].expect("the pair's segment");
        let tilt = own.normal[0].atan2(-own.normal[1]).to_degrees();
        assert!(tilt.abs() > 20.0, "tilt {tilt}°: {own:?}");
        assert!(scan.no_return.iter().all(|&m| !m));
        assert!(scan.isolated_lines.is_empty());
        // The bridged form has the wall's line and follows every missing reading.
        let bridged = scan.bridged();
        let line = bridged.segments[90].expect("a line");
        assert!(line.normal[0].atan2(-line.normal[1]).to_degrees().abs() < 3.0);
        assert!(bridged.no_return[92]);
    }

    #[test]
    fn a_pair_its_own_lines_match_keeps_that_match() {
        // A room seen with 1 reading in 12 lost (sparse: scattered dropouts): the own
        // lines match it (73 % of the points), so the bridged lines (85 %, and a pose
        // 3e-9 m apart) must not move the result at all.
        let reference = room_scan(Pose2::new(0.0, 0.0, 0.0), |i| i % 12 == 11);
        let truth = Pose2::new(0.12, -0.05, 0.04);
        let current = room_scan(truth, |i| (i + 3) % 12 == 11);
        assert!(reference.has_bridged() && current.has_bridged());
        let mut matcher = Matcher::new(IcpParams::default());
        let guess = Pose2::new(0.1, -0.04, 0.03);
        let got = matcher
            .match_scans(&reference, &current, guess)
            .expect("a match");
        let strip = |s: &PreparedScan| PreparedScan {
            bridged: None,
            ..s.clone()
        };
        let own = matcher
            .match_prepared(&strip(&reference), &strip(&current), guess)
            .expect("a match with the own lines");
        assert_eq!(got.pose, own.pose);
        assert_eq!(got.correspondences, own.correspondences);
    }

    #[test]
    fn a_pair_its_own_lines_match_too_little_of_is_matched_across_the_gaps() {
        // 1 reading in 4 lost: the own lines converge on the right pose but explain 49 %
        // of the current scan (its runs lose their ends); the lines across the gaps
        // match the pair within 5 mm / 0.3°.
        let reference = room_scan(Pose2::new(0.0, 0.0, 0.0), |i| i % 4 == 3);
        let truth = Pose2::new(0.12, -0.05, 0.04);
        let current = room_scan(truth, |i| (i + 3) % 4 == 3);
        let mut matcher = Matcher::new(IcpParams::default());
        let guess = Pose2::new(0.1, -0.04, 0.03);
        let own = matcher.match_prepared(&reference, &current, guess);
        assert!(matches!(own, Err(IcpError::SmallOverlap { .. })), "{own:?}");
        let got = matcher
            .match_scans(&reference, &current, guess)
            .expect("a match across the gaps");
        let error = truth.between(&got.pose);
        assert!(
            error.translation_norm() < 0.005 && error.theta.abs() < 0.3f64.to_radians(),
            "{:?} against {truth:?}",
            got.pose
        );
    }

    #[test]
    fn a_pair_with_too_few_correspondences_is_not_bridged() {
        // Every other reading lost: no run, no segment of its own, too few
        // correspondences. The lines across the gaps could match this noise-free pair,
        // but they would be the whole evidence: the refusal stands.
        let reference = room_scan(Pose2::new(0.0, 0.0, 0.0), |i| i % 2 == 1);
        let truth = Pose2::new(0.12, -0.05, 0.04);
        let current = room_scan(truth, |i| i % 2 == 0);
        let mut matcher = Matcher::new(IcpParams::default());
        let guess = Pose2::new(0.1, -0.04, 0.03);
        let bridged = matcher.match_prepared(reference.bridged(), current.bridged(), guess);
        assert!(bridged.is_ok(), "{bridged:?}");
        let got = matcher.match_scans(&reference, &current, guess);
        assert!(
            matches!(got, Err(IcpError::TooFewCorrespondences { .. })),
            "{got:?}"
        );
    }
}
