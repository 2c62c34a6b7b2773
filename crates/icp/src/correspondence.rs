//! Correspondences: which reference segment a current point lies on.
//!
//! A current point `p` (already moved into the reference frame by the current
//! estimate) is matched to the segment between its two closest consecutive points of
//! the reference scan: first its closest valid reference point `j`, then the usable
//! segment `(j, j+1)` or `(j−1, j)` on whose side `p` projects. There is no match when
//! the closest point is farther than the gate, or when `p` projects beyond the end of
//! a run past a range discontinuity (towards an occluded or unseen part), or when
//! neither segment has a usable local line. A run that ends because the next ray got
//! no return (dark or glancing surfaces: half the readings of a real URG-04LX) is
//! followed a little further: up to [`END_EXTENSION_SEGMENTS`] lengths of its end
//! segment past its end, `p` is measured against the end segment's local line.
//!
//! The closest point is found either by the angular walk of CSM (rays are ordered by
//! bearing: start at the ray pointing closest to `p`, walk outwards, and stop as soon
//! as the distance from `p` to the ray itself exceeds the best distance found) or by
//! the kiddo k-d tree.

use crate::preprocess::PreparedScan;
use kiddo::SquaredEuclidean;

/// Closest valid reference point to `p` within `sqrt(max_dist2)`, by the angular walk
/// starting at ray `guess`.
pub(crate) fn nearest_by_angle(
    reference: &PreparedScan,
    p: [f64; 2],
    guess: usize,
    max_dist2: f64,
) -> Option<usize> {
    let rays = &reference.rays[..];
    let n = rays.len();
    // cross > 0: p is counter-clockwise of the ray; dot > 0: p is in front of it.
    let cross = |d: [f64; 2]| d[0] * p[1] - d[1] * p[0];
    let dot = |d: [f64; 2]| d[0] * p[0] + d[1] * p[1];
    let r2 = p[0] * p[0] + p[1] * p[1];

    let mut j = guess.min(n - 1);
    if dot(rays[j].dir) <= 0.0 {
        // The guess points away from p: restart from p's bearing.
        j = reference.ray_near_bearing(p[1].atan2(p[0]));
    }
    // Walk to the pair of rays (lo, lo + 1) that brackets p's bearing.
    let lo: isize = if cross(rays[j].dir) > 0.0 {
        while j + 1 < n && cross(rays[j + 1].dir) > 0.0 && dot(rays[j + 1].dir) > 0.0 {
            j += 1;
        }
        j as isize
    } else {
        while j > 0 && cross(rays[j - 1].dir) <= 0.0 && dot(rays[j - 1].dir) > 0.0 {
            j -= 1;
        }
        j as isize - 1
    };
    // Lower bound of the squared distance from p to any point on ray k: the squared
    // distance to the ray's half-line. It grows as the rays turn away from p.
    let lower_bound = |d: [f64; 2]| {
        let c = cross(d);
        if dot(d) > 0.0 {
            c * c
        } else {
            r2
        }
    };
    let mut best = max_dist2;
    let mut best_k = usize::MAX;
    let first_ccw = (lo + 1) as usize;
    // Fast path: the two rays on each side of p's bearing, without branches on the
    // data; when the next rays out on both sides are already ruled out by their
    // bound, the answer is final. Otherwise (or near the ends), the general walk.
    if first_ccw >= 2 && first_ccw + 2 < n {
        // The four rays as one slice (one bounds check; `skip` and `take` cost 8 % of
        // this function's instructions).
        let base = first_ccw - 2;
        for (k, ray) in rays[base..base + 4].iter().enumerate() {
            let d2 = dist2(ray.point, p);
            if d2 < best {
                best = d2;
                best_k = base + k;
            }
        }
        let settled = first_ccw < 3 || lower_bound(rays[first_ccw - 3].dir) >= best;
        if settled && lower_bound(rays[first_ccw + 2].dir) >= best {
            return (best_k != usize::MAX).then_some(best_k);
        }
        best = max_dist2;
        best_k = usize::MAX;
    }
    // Clockwise from lo, then counter-clockwise from lo + 1. Invalid points are NaN,
    // whose distance never compares smaller.
    let mut visit = |k: usize| {
        let ray = rays[k];
        if lower_bound(ray.dir) >= best {
            return false;
        }
        let d2 = dist2(ray.point, p);
        if d2 < best {
            best = d2;
            best_k = k;
        }
        true
    };
    for k in (0..first_ccw).rev() {
        if !visit(k) {
            break;
        }
    }
    for k in first_ccw..n {
        if !visit(k) {
            break;
        }
    }
    (best_k != usize::MAX).then_some(best_k)
}

/// Closest valid reference point to `p` within `sqrt(max_dist2)`, by the k-d tree.
pub(crate) fn nearest_by_tree(
    reference: &PreparedScan,
    p: [f64; 2],
    max_dist2: f64,
) -> Option<usize> {
    let tree = reference.tree.as_ref()?;
    let found = tree.nearest_one::<SquaredEuclidean>(&p);
    (found.distance < max_dist2).then_some(found.item as usize)
}

/// The reference segment `p` lies on, given its closest reference point `j`.
///
/// Returns the segment index `i` (segment from point `i` to `i + 1`).
#[inline]
pub(crate) fn segment_for(reference: &PreparedScan, p: [f64; 2], j: usize) -> Option<usize> {
    let point = reference.rays[j].point;
    let sides = &reference.sides[j];
    let e = [(p[0] - point[0]) as f32, (p[1] - point[1]) as f32];
    // Distance of p's projection from point j along each usable segment (NaN when
    // that segment is not usable: NaN never compares true).
    let forward = e[0] * sides.to_next[0] + e[1] * sides.to_next[1];
    let backward = e[0] * sides.to_previous[0] + e[1] * sides.to_previous[1];
    if forward >= 0.0 && (backward.is_nan() || backward <= forward) {
        Some(j)
    } else if backward >= 0.0 {
        Some(j - 1)
    } else if forward.is_nan() && backward < 0.0 && reference.no_return_after(j) {
        within_extension(reference, j, j - 1, -backward).then(|| j - 1)
    } else if backward.is_nan() && forward < 0.0 && reference.no_return_before(j) {
        within_extension(reference, j, j + 1, -forward).then_some(j)
    } else {
        None
    }
}

/// Beyond the end `j` of a run whose last segment goes to `inner`, a point projecting
/// `beyond` (m) past `j` still belongs to the end segment's line when that is at most
/// [`END_EXTENSION_SEGMENTS`] segment lengths.
fn within_extension(reference: &PreparedScan, j: usize, inner: usize, beyond: f32) -> bool {
    let d2 = dist2(reference.rays[j].point, reference.rays[inner].point);
    let limit = END_EXTENSION_SEGMENTS * d2.sqrt();
    f64::from(beyond) <= limit
}

/// How far (in lengths of the end segment) a run's local line is followed past the
/// run's end when the next ray got no return.
const END_EXTENSION_SEGMENTS: f64 = 3.0;

fn dist2(a: [f64; 2], b: [f64; 2]) -> f64 {
    let dx = a[0] - b[0];
    let dy = a[1] - b[1];
    dx * dx + dy * dy
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::IcpParams;

    /// A wall at y = 2 m seen by 181 rays over 90°, with the readings `gap` missing
    /// (0: no return), or replaced by `jump` (m: a far surface); the first 40 and the
    /// last 50 rays got no return either (a sparse scan: missing returns are common).
    fn wall_with_gap(gap: std::ops::Range<usize>, jump: Option<f32>) -> PreparedScan {
        let angles: Vec<f64> = (0..181)
            .map(|i| (45.0 + i as f64 * 0.5).to_radians())
            .collect();
        let ranges: Vec<f32> = angles
            .iter()
            .enumerate()
            .map(|(i, a)| match (gap.contains(&i), jump) {
                _ if !(40..=130).contains(&i) => 0.0,
                (false, _) => (2.0 / a.sin()) as f32,
                (true, None) => 0.0,
                (true, Some(far)) => far,
            })
            .collect();
        PreparedScan::new(&ranges, &angles, 0.02, 5.6, &IcpParams::default()).expect("scan")
    }

    /// The point on the wall at x, and the closest reference point to it (its index
    /// among the scan's valid points).
    fn on_wall(scan: &PreparedScan, x: f64) -> ([f64; 2], usize) {
        let p = [x, 2.0];
        let j = (0..scan.points.len())
            .min_by(|&a, &b| dist2(scan.points[a], p).total_cmp(&dist2(scan.points[b], p)))
            .expect("a valid point");
        (p, j)
    }

    /// The scan's reading (ray) of valid point or segment `k`.
    fn ray(scan: &PreparedScan, k: Option<usize>) -> Option<u32> {
        k.map(|k| scan.original[k])
    }

    #[test]
    fn a_run_ending_at_readings_without_return_is_followed_a_little_further() {
        // Rays 90..100 (x from 0 to −0.17 m) got no return; the run before them ends
        // at ray 89 (x ≈ 0.017 m), with segments ≈ 17 mm long.
        let scan = wall_with_gap(90..100, None);
        let (end, end_point) = on_wall(&scan, 0.0175);
        assert_eq!(scan.original[end_point], 89, "{end:?}");
        // One and a half segment lengths past the end: measured against the end
        // segment's line (before: no correspondence).
        let (p, j) = on_wall(&scan, -0.008);
        assert_eq!(scan.original[j], 89);
        assert_eq!(ray(&scan, segment_for(&scan, p, j)), Some(88));
        // Likewise past the start of the run after the gap (ray 100).
        let (p, j) = on_wall(&scan, -0.16);
        assert_eq!(scan.original[j], 100);
        assert_eq!(ray(&scan, segment_for(&scan, p, j)), Some(100));
        // Far past the end (5 segment lengths): unseen, no correspondence.
        let (p, j) = on_wall(&scan, -0.07);
        assert_eq!(segment_for(&scan, p, j), None, "ray {j}");
    }

    #[test]
    fn a_rare_dropout_is_bridged_and_a_run_ending_at_one_is_not_followed() {
        // One missing reading (ray 90) in a scan that has no other: a dropout.
        let angles: Vec<f64> = (0..181)
            .map(|i| (45.0 + i as f64 * 0.5).to_radians())
            .collect();
        let ranges: Vec<f32> = angles
            .iter()
            .enumerate()
            .map(|(i, a)| if i == 90 { 0.0 } else { (2.0 / a.sin()) as f32 })
            .collect();
        // Bridged: the point where ray 90 would have hit is on the segment 89 → 91.
        let scan =
            PreparedScan::new(&ranges, &angles, 0.02, 5.6, &IcpParams::default()).expect("scan");
        let (p, j) = on_wall(&scan, 0.008);
        assert_eq!(scan.original[j], 89);
        assert_eq!(ray(&scan, segment_for(&scan, p, j)), Some(89));
        assert_eq!(scan.original[segment_for(&scan, p, j).unwrap() + 1], 91);
        // Not bridged: the run ends at ray 89 and is not followed past it.
        let params = IcpParams {
            bridged_missing_rays: 0,
            ..IcpParams::default()
        };
        let scan = PreparedScan::new(&ranges, &angles, 0.02, 5.6, &params).expect("scan");
        let (p, j) = on_wall(&scan, 0.008);
        assert_eq!(scan.original[j], 89);
        assert_eq!(segment_for(&scan, p, j), None);
    }

    #[test]
    fn a_run_ending_at_a_range_jump_is_not_followed() {
        // The same wall, rays 90..100 seeing a far surface instead: an occlusion edge,
        // whether the far readings are valid (3.5 m) or beyond the scan's maximum
        // range (6 m, above its 5.6 m).
        for far in [3.5, 6.0] {
            let scan = wall_with_gap(90..100, Some(far));
            let (p, j) = on_wall(&scan, -0.008);
            assert_eq!(scan.original[j], 89, "{far}");
            assert_eq!(segment_for(&scan, p, j), None, "{far}");
        }
    }
}
