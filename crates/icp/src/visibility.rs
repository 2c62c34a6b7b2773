//! Which points of the current scan the reference scan could have seen, at a result:
//! the denominator of the matched share.
//!
//! A point of the current scan can be explained by the reference only if the
//! reference looked that way and saw something there: inside its field of view, and
//! its ray in that bearing (or a neighbour) returned — no return is open space beyond
//! the range, or a dark or glass surface. Points that fail either say nothing about
//! the alignment; on the real URG-04LX scans of the MinesRover (55 % of the readings
//! without a return) counting them made right matches look like "too small an
//! overlap". Points hidden behind a reference surface still count against the match:
//! excluding them too let a wrong alignment through on the simulated arena (from a
//! guess 0.18 m and 45° off).

use crate::PreparedScan;
use odocal_geom::Pose2;

/// Valid current points on a usable local line that the reference could see at
/// `estimate` (the current sensor pose in the reference frame).
pub(crate) fn visible_count(
    reference: &PreparedScan,
    current: &PreparedScan,
    estimate: &Pose2,
) -> usize {
    let n = reference.angles.len();
    if n == 0 {
        return 0;
    }
    let (first, last) = (reference.angles[0], reference.angles[n - 1]);
    let (lo, hi) = (first.min(last), first.max(last));
    let mut count = 0;
    for &i in &current.valid_indices {
        let i = i as usize;
        if current.incidence_cos[i].is_nan() {
            continue;
        }
        let p = estimate.transform_point(current.points[i]);
        let bearing = p[1].atan2(p[0]);
        if !(lo..=hi).contains(&bearing) {
            continue;
        }
        let k = reference.ray_near_bearing(bearing);
        let seen = (k.saturating_sub(1)..=(k + 1).min(n - 1)).any(|j| reference.valid[j]);
        count += usize::from(seen);
    }
    count
}
