//! The small-object test of a result: matched again without the small objects standing
//! in front of the walls, it must stay where it is, or its covariance says how far it
//! may be off.
//!
//! A person walking past the robot moves 0.1–0.4 m between the two scans of a pair.
//! Where the walls leave one direction weak (a hall, a corridor), the person's legs can
//! drag the iterations along; the walls' correspondences, found again at the dragged
//! pose, then give that direction an information that does not resist the drag, and the
//! covariance says nothing is wrong (the simulated rover's hall: 182 mm off with a σ of
//! 2.9 mm). Which objects moved, two scans cannot tell. That the result rests on them,
//! they can: when the small objects in front of the rest (see
//! [`foreground_small_objects`]) together give at least [`MIN_SHARE`] of the
//! information along some direction, and the information of the other points is not
//! comfortably well conditioned (condition number at least ⅕ of the limit, as for the
//! basin test: otherwise the walls hold every direction whatever the objects do), the
//! pair is matched again from the same start without their points. When the two results
//! are farther apart than their covariances allow, the result is kept and its
//! covariance widened by their difference `d dᵀ`, as the basin test does: the
//! calibration then weighs it by what it may really be worth.
//! Refusing such pairs instead was measured and not kept: on the real MinesRover logs it
//! cost matches and the two logs' agreement (docs/benchmarks.md).

use crate::basin_check::{difference, mahalanobis_sq, rms_range, widen, TESTED_CONDITION_SHARE};
use crate::covariance::conditioning;
use crate::{IcpParams, IcpResult, Matcher, PreparedScan};
use odocal_geom::Pose2;

/// Consecutive valid points farther apart than this (m) are different objects.
const CLUSTER_GAP: f64 = 0.15;
/// An object less than this across (m, the bounding-box diagonal of its points) is
/// small: a person's legs, a chair, a bin, a pillar.
const SMALL_OBJECT: f64 = 0.6;
/// How much farther from the sensor (m) the points beside a small object must be for
/// it to stand in front of them.
const FOREGROUND_STEP: f64 = 0.3;
/// The small objects' least share of the information along some direction for the
/// result to be tested.
const MIN_SHARE: f64 = 0.3;
/// χ²(3)'s 99.9 % level.
const CHI2_3_999: f64 = 16.27;

/// One correspondence used at a result: its current point and its information
/// `w·J·Jᵀ`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct UsedTerm {
    /// Index of the current point (among the scan's valid points).
    pub index: u32,
    /// `∂e/∂(x, y, θ)` of its residual at the result.
    pub j: [f64; 3],
    /// Its weight.
    pub w: f64,
}

/// Adds `t`'s information to `info`.
fn add(info: &mut [[f64; 3]; 3], t: &UsedTerm) {
    for (r, row) in info.iter_mut().enumerate() {
        for (c, v) in row.iter_mut().enumerate() {
            *v += t.w * t.j[r] * t.j[c];
        }
    }
}

/// The largest share of the information `full` that `part` gives along one direction:
/// the largest eigenvalue of `L⁻¹ part L⁻ᵀ` with `full = L Lᵀ` (scale-free; 1 when
/// `full` is not positive definite).
fn largest_share(full: &[[f64; 3]; 3], part: &[[f64; 3]; 3]) -> f64 {
    let f = nalgebra::Matrix3::from_fn(|r, c| full[r][c]);
    let p = nalgebra::Matrix3::from_fn(|r, c| part[r][c]);
    let Some(l_inv) = f.cholesky().and_then(|ch| ch.l().try_inverse()) else {
        return 1.0;
    };
    let m = l_inv * p * l_inv.transpose();
    let share = nalgebra::SymmetricEigen::new((m + m.transpose()) * 0.5)
        .eigenvalues
        .max();
    if share.is_finite() {
        share
    } else {
        1.0
    }
}

/// Per point of `points` (a scan's valid points in ray order, sensor frame): on a
/// small object standing in front of what is around it. The points are cut into
/// clusters where consecutive ones are more than [`CLUSTER_GAP`] apart; a cluster less
/// than [`SMALL_OBJECT`] across whose neighbouring points on both sides (on one side
/// at the ends of the scan) are at least [`FOREGROUND_STEP`] farther from the sensor
/// is such an object. A stretch of wall between missing readings is not: its
/// neighbours are the same wall.
pub(crate) fn foreground_small_objects(points: &[[f64; 2]]) -> Vec<bool> {
    let mut flags = vec![false; points.len()];
    // Distances as √(x² + y²) and compared squared: `hypot`'s care for overflow is not
    // needed at a laser's ranges, and it costs.
    let range = |p: [f64; 2]| (p[0] * p[0] + p[1] * p[1]).sqrt();
    let squared = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2);
    let mut start = 0;
    while start < points.len() {
        let mut end = start + 1;
        while end < points.len() {
            let (a, b) = (points[end - 1], points[end]);
            if squared(a, b) > CLUSTER_GAP * CLUSTER_GAP {
                break;
            }
            end += 1;
        }
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for p in &points[start..end] {
            for a in 0..2 {
                lo[a] = lo[a].min(p[a]);
                hi[a] = hi[a].max(p[a]);
            }
        }
        let small = squared(hi, lo) < SMALL_OBJECT * SMALL_OBJECT;
        let before = (start > 0).then(|| range(points[start - 1]) - range(points[start]));
        let after = (end < points.len()).then(|| range(points[end]) - range(points[end - 1]));
        let in_front = (before.is_some() || after.is_some())
            && [before, after]
                .into_iter()
                .flatten()
                .all(|step| step >= FOREGROUND_STEP);
        if small && in_front {
            flags[start..end].iter_mut().for_each(|f| *f = true);
        }
        start = end;
    }
    flags
}

/// The current points of `terms` flagged in `on_small`, when together they give at
/// least [`MIN_SHARE`] of the information of `terms` along some direction, with the
/// information of the other terms; `None` otherwise.
pub(crate) fn small_object_points(
    terms: &[UsedTerm],
    on_small: &[bool],
) -> Option<(Vec<u32>, [[f64; 3]; 3])> {
    let mut full = [[0.0; 3]; 3];
    let mut small = [[0.0; 3]; 3];
    let mut rest = [[0.0; 3]; 3];
    let mut points = Vec::new();
    for t in terms {
        add(&mut full, t);
        if on_small.get(t.index as usize).copied().unwrap_or(false) {
            add(&mut small, t);
            points.push(t.index);
        } else {
            add(&mut rest, t);
        }
    }
    (!points.is_empty() && largest_share(&full, &small) >= MIN_SHARE).then_some((points, rest))
}

impl Matcher {
    /// `result` after the small-object test (module documentation), with the
    /// correspondences it used in `self.kept_terms`: `start` is where its iterations
    /// began, `anchor` the caller's first guess.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn small_objects_widened(
        &mut self,
        reference: &PreparedScan,
        current: &PreparedScan,
        mut result: IcpResult,
        start: Pose2,
        anchor: Pose2,
        params: &IcpParams,
        use_tree: bool,
    ) -> IcpResult {
        let on_small = foreground_small_objects(&current.points);
        let Some((points, rest)) = small_object_points(&self.kept_terms, &on_small) else {
            return result;
        };
        // The rest comfortably well conditioned: the walls hold every direction
        // whatever the objects do.
        let rest_held = conditioning(&rest, rms_range(current).max(1e-3)).is_some_and(|c| {
            c.condition_number < TESTED_CONDITION_SHARE * params.max_condition_number
        });
        if rest_held {
            return result;
        }
        self.skipped.clear();
        self.skipped.resize(current.points.len(), false);
        for i in points {
            self.skipped[i as usize] = true;
        }
        let again = self.refine(reference, current, start, anchor, params, use_tree);
        self.skipped.clear();
        // Without them the pair does not match, or not in every direction: nothing to
        // compare with.
        let Ok(again) = again else { return result };
        if again.ill_conditioned {
            return result;
        }
        let d = difference(&result.pose, &again.pose);
        let judged: [[f64; 3]; 3] = std::array::from_fn(|r| {
            std::array::from_fn(|c| again.covariance[r][c] + result.covariance[r][c])
        });
        if mahalanobis_sq(d, &judged) > CHI2_3_999 {
            widen(&mut result.covariance, d);
        }
        result
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Points along the ray angles `angles` (rad) at the ranges `ranges` (m).
    fn polar(angles: &[f64], ranges: &[f64]) -> Vec<[f64; 2]> {
        angles
            .iter()
            .zip(ranges)
            .map(|(a, r)| [r * a.cos(), r * a.sin()])
            .collect()
    }

    /// A wall 3 m ahead seen over ±30° at 0.5° steps.
    fn wall() -> (Vec<f64>, Vec<f64>) {
        let angles: Vec<f64> = (-60..=60)
            .map(|i| f64::from(i) * 0.5f64.to_radians())
            .collect();
        let ranges = angles.iter().map(|a| 3.0 / a.cos()).collect();
        (angles, ranges)
    }

    #[test]
    fn a_leg_in_front_of_a_wall_is_a_small_object_and_the_wall_is_not() {
        let (angles, mut ranges) = wall();
        // A leg 1 m ahead covers rays 58..=62 (±1°: 3.5 cm at 1 m).
        for r in &mut ranges[58..=62] {
            *r = 1.0;
        }
        let flags = foreground_small_objects(&polar(&angles, &ranges));
        let flagged: Vec<usize> = (0..flags.len()).filter(|&i| flags[i]).collect();
        assert_eq!(flagged, vec![58, 59, 60, 61, 62]);
    }

    #[test]
    fn a_stretch_of_wall_between_missing_readings_is_not_a_small_object() {
        let (angles, ranges) = wall();
        // Only every seventh reading returned (dark wall): stretches of one point,
        // 18 cm apart, with the same wall on both sides.
        let kept: Vec<usize> = (0..angles.len()).step_by(7).collect();
        let a: Vec<f64> = kept.iter().map(|&i| angles[i]).collect();
        let r: Vec<f64> = kept.iter().map(|&i| ranges[i]).collect();
        assert!(foreground_small_objects(&polar(&a, &r)).iter().all(|f| !f));
    }

    #[test]
    fn an_object_with_something_nearer_beside_it_is_not_in_front() {
        let (angles, mut ranges) = wall();
        // A box 2 m ahead (rays 40..=50), and right beside it a nearer one at 1.2 m
        // (rays 51..=55): the far box does not stand in front of its neighbours.
        for r in &mut ranges[40..=50] {
            *r = 2.0;
        }
        for r in &mut ranges[51..=55] {
            *r = 1.2;
        }
        let flags = foreground_small_objects(&polar(&angles, &ranges));
        assert!(flags[40..=50].iter().all(|f| !f));
        assert!(flags[51..=55].iter().all(|f| *f));
    }

    #[test]
    fn the_share_is_the_largest_fraction_of_the_information_along_a_direction() {
        // Two terms along x (weights 1 and 3) and one along y: the second term gives
        // 3/4 of the information along x and none along y or θ.
        let term = |index, j, w| UsedTerm { index, j, w };
        let terms = [
            term(0, [1.0, 0.0, 0.0], 1.0),
            term(1, [1.0, 0.0, 0.0], 3.0),
            term(2, [0.0, 1.0, 0.0], 1.0),
            term(3, [0.0, 0.0, 1.0], 1.0),
        ];
        let mut full = [[0.0; 3]; 3];
        let mut part = [[0.0; 3]; 3];
        for t in &terms {
            add(&mut full, t);
        }
        add(&mut part, &terms[1]);
        assert!((largest_share(&full, &part) - 0.75).abs() < 1e-12);
        let mut on_small = vec![false; 4];
        on_small[1] = true;
        assert_eq!(
            small_object_points(&terms, &on_small).map(|(points, _)| points),
            Some(vec![1])
        );
        // A term giving a fifth of the information along x is below the least share.
        let weak = [
            term(0, [1.0, 0.0, 0.0], 4.0),
            term(1, [1.0, 0.0, 0.0], 1.0),
            terms[2],
            terms[3],
        ];
        assert_eq!(small_object_points(&weak, &on_small), None);
        assert_eq!(small_object_points(&weak, &[false; 4]), None);
    }
}
