//! Correspondences: which reference segment a current point lies on.
//!
//! A current point `p` (already moved into the reference frame by the current
//! estimate) is matched to the segment between its two closest consecutive points of
//! the reference scan: first its closest valid reference point `j`, then the usable
//! segment `(j, j+1)` or `(j−1, j)` on whose side `p` projects. There is no match when
//! the closest point is farther than the gate, or when `p` projects beyond the end of
//! a run (past a range discontinuity, i.e. towards an occluded or unseen part), or
//! when neither segment has a usable local line.
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
    let n = reference.dirs.len();
    let dirs = &reference.dirs;
    let cross = |k: usize| dirs[k][0] * p[1] - dirs[k][1] * p[0];
    let dot = |k: usize| dirs[k][0] * p[0] + dirs[k][1] * p[1];
    let r2 = p[0] * p[0] + p[1] * p[1];

    let mut j = guess.min(n - 1);
    if dot(j) <= 0.0 {
        // The guess points away from p: restart from p's bearing.
        j = reference.ray_near_bearing(p[1].atan2(p[0]));
    }
    // Walk to the pair of rays (lo, lo+1) that brackets p's bearing.
    let mut lo;
    if cross(j) > 0.0 {
        // p is counter-clockwise of ray j.
        while j + 1 < n && cross(j + 1) > 0.0 && dot(j + 1) > 0.0 {
            j += 1;
        }
        lo = j as isize;
    } else {
        while j > 0 && cross(j - 1) <= 0.0 && dot(j - 1) > 0.0 {
            j -= 1;
        }
        lo = j as isize - 1;
    }
    let mut best = max_dist2;
    let mut best_j = None;
    let points = &reference.points;
    let valid = &reference.valid;
    let lower_bound = |k: usize| {
        if dot(k) > 0.0 {
            let s = cross(k);
            s * s
        } else {
            r2
        }
    };
    let lo_start = lo;
    // Clockwise from lo.
    while lo >= 0 {
        let k = lo as usize;
        if lower_bound(k) >= best {
            break;
        }
        if valid[k] {
            let d2 = dist2(points[k], p);
            if d2 < best {
                best = d2;
                best_j = Some(k);
            }
        }
        lo -= 1;
    }
    // Counter-clockwise from lo + 1.
    let mut k = (lo_start + 1) as usize;
    while k < n {
        if lower_bound(k) >= best {
            break;
        }
        if valid[k] {
            let d2 = dist2(points[k], p);
            if d2 < best {
                best = d2;
                best_j = Some(k);
            }
        }
        k += 1;
    }
    best_j
}

/// Closest valid reference point to `p` within `sqrt(max_dist2)`, by the k-d tree.
pub(crate) fn nearest_by_tree(reference: &PreparedScan, p: [f64; 2], max_dist2: f64) -> Option<usize> {
    let tree = reference.tree.as_ref()?;
    let found = tree.nearest_one::<SquaredEuclidean>(&p);
    (found.distance < max_dist2).then(|| reference.valid_indices[found.item as usize] as usize)
}

/// The reference segment `p` lies on, given its closest reference point `j`.
///
/// Returns the segment index `i` (segment from point `i` to `i + 1`).
pub(crate) fn segment_for(reference: &PreparedScan, p: [f64; 2], j: usize) -> Option<usize> {
    let pts = &reference.points;
    let pj = pts[j];
    let e = [p[0] - pj[0], p[1] - pj[1]];
    // Projection parameter of p along the segment from j towards `other` (0 at j).
    let along = |other: usize| {
        let v = [pts[other][0] - pj[0], pts[other][1] - pj[1]];
        (e[0] * v[0] + e[1] * v[1]) / (v[0] * v[0] + v[1] * v[1])
    };
    let forward = reference.segments[j].map(|_| along(j + 1));
    let backward = if j > 0 {
        reference.segments[j - 1].map(|_| along(j - 1))
    } else {
        None
    };
    match (forward, backward) {
        (Some(f), Some(b)) if f >= b && f >= 0.0 => Some(j),
        (Some(_), Some(b)) if b >= 0.0 => Some(j - 1),
        (Some(f), None) if f >= 0.0 => Some(j),
        (None, Some(b)) if b >= 0.0 => Some(j - 1),
        _ => None,
    }
}

fn dist2(a: [f64; 2], b: [f64; 2]) -> f64 {
    let dx = a[0] - b[0];
    let dy = a[1] - b[1];
    dx * dx + dy * dy
}
