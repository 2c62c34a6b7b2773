//! Correlative first guesses for sparse scans: a grid search over `(x, y, θ)` around
//! the caller's guess, scoring every pose by how many current points land near a
//! reference point (each contributes `1 − d²/g²` within the gate `g`, 0 beyond), first
//! on a coarse grid with a wide gate, then on a fine grid around each of the best
//! coarse poses. Translation-and-rotation exhaustive within the window, so it finds the
//! right basin where ICP from the guess would slide into a wrong one (on a 1° LDS the
//! point-to-line iterations from the *true* pose end 20–55 mm off on half the pairs).

use crate::nearest_grid::NearestGrid;
use odocal_geom::{wrap_angle, Pose2};

/// One level of the search: steps and gate (m, rad, m).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Level {
    /// Translation step (m).
    pub step_xy: f64,
    /// Rotation step (rad).
    pub step_theta: f64,
    /// Gate of the score (m).
    pub gate: f64,
}

/// A scored pose.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Candidate {
    /// The pose of the current scan in the reference frame.
    pub pose: Pose2,
    /// Its score (≈ the number of current points explained).
    pub score: f64,
}

/// Most translation steps the search takes each way from its centre (±6 m at the
/// sparse matcher's coarse 6 cm).
const MAX_STEPS: f64 = 100.0;

/// The best poses of the grid `level` within `±half_xy` (m) and `±half_theta` (rad)
/// of `centre`, at most `keep` of them, each a local maximum farther than
/// `distinct_xy` / `distinct_theta` from every better one; best first.
#[allow(clippy::too_many_arguments)]
pub(crate) fn search(
    grid: &NearestGrid,
    reference: &[[f64; 2]],
    current: &[[f64; 2]],
    centre: &Pose2,
    half_xy: f64,
    half_theta: f64,
    level: Level,
    keep: usize,
    distinct: (f64, f64),
) -> Vec<Candidate> {
    // Bounded whatever the window (a library caller's correction limits may be
    // huge or infinite): at most MAX_STEPS steps each way, and a full turn.
    let nxy = (half_xy / level.step_xy).round().min(MAX_STEPS) as i64;
    let nth = (half_theta.min(std::f64::consts::PI) / level.step_theta).round() as i64;
    let offsets: Vec<f64> = (-nxy..=nxy).map(|i| i as f64 * level.step_xy).collect();
    let side = offsets.len();
    let inv_g2 = 1.0 / (level.gate * level.gate);
    let mut all: Vec<Candidate> = Vec::new();
    // Per rotation, the scores of every translation `(i, j)`: each point adds its
    // share to all of them before the next point does (its lookups stay in one
    // neighbourhood of the grid), so every pose's sum still runs over the points in
    // order, as a pose-by-pose loop would add them.
    let mut scores = vec![0.0; side * side];
    let (mut xs, mut ys) = (vec![0.0; side], vec![0.0; side]);
    let (mut columns, mut rows) = (vec![None; side], vec![None; side]);
    for k in -nth..=nth {
        let theta = centre.theta + k as f64 * level.step_theta;
        let (s, c) = theta.sin_cos();
        scores.fill(0.0);
        for q in current {
            let r = [c * q[0] - s * q[1], s * q[0] + c * q[1]];
            // A moved point's abscissa depends on the step along x only, its
            // ordinate on the step along y: their cells are found once each.
            for (i, d) in offsets.iter().enumerate() {
                xs[i] = r[0] + (centre.x + d);
                columns[i] = grid.column(xs[i]);
                ys[i] = r[1] + (centre.y + d);
                rows[i] = grid.row(ys[i]);
            }
            // Row by row, so that the lookups of one row walk along the grid's memory.
            for (j, row) in rows.iter().enumerate() {
                let Some(row) = *row else { continue };
                for (i, column) in columns.iter().enumerate() {
                    let Some(column) = *column else { continue };
                    if let Some(n) = grid.at(column, row) {
                        let p = reference[n];
                        let d2 = (xs[i] - p[0]).powi(2) + (ys[j] - p[1]).powi(2);
                        scores[j * side + i] += (1.0 - d2 * inv_g2).max(0.0);
                    }
                }
            }
        }
        for (i, di) in offsets.iter().enumerate() {
            for (j, dj) in offsets.iter().enumerate() {
                let score = scores[j * side + i];
                if score > 0.0 {
                    all.push(Candidate {
                        pose: Pose2::new(centre.x + di, centre.y + dj, theta),
                        score,
                    });
                }
            }
        }
    }
    best_distinct(all, keep, distinct)
}

/// Candidates ranked before the others are looked at first (see [`best_distinct`]).
const FIRST_LOOK: usize = 128;

/// The first `keep` candidates of `all`, best score first (equal scores in the order
/// given), each farther than `distinct` (m, rad) from every one taken before it.
/// Only the best [`FIRST_LOOK`] are sorted, unless they hold fewer distinct ones:
/// the same as sorting them all, for a fraction of the time.
fn best_distinct(all: Vec<Candidate>, keep: usize, distinct: (f64, f64)) -> Vec<Candidate> {
    // Score, then the order given: a total order, so any sort gives a stable sort's.
    let by_rank = |a: &(usize, Candidate), b: &(usize, Candidate)| {
        b.1.score.total_cmp(&a.1.score).then(a.0.cmp(&b.0))
    };
    let mut ranked: Vec<(usize, Candidate)> = all.into_iter().enumerate().collect();
    let first = ranked.len().min(FIRST_LOOK);
    if ranked.len() > first {
        ranked.select_nth_unstable_by(first - 1, by_rank);
    }
    let (head, tail) = ranked.split_at_mut(first);
    head.sort_unstable_by(by_rank);
    let mut best: Vec<Candidate> = Vec::with_capacity(keep);
    let take = |best: &mut Vec<Candidate>, c: &Candidate| {
        let apart = |b: &Candidate| {
            let d = b.pose.between(&c.pose);
            d.translation_norm() > distinct.0 || wrap_angle(d.theta).abs() > distinct.1
        };
        if best.iter().all(apart) {
            best.push(*c);
        }
    };
    for (_, c) in head.iter() {
        if best.len() >= keep {
            return best;
        }
        take(&mut best, c);
    }
    tail.sort_unstable_by(by_rank);
    for (_, c) in tail.iter() {
        if best.len() >= keep {
            break;
        }
        take(&mut best, c);
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An L of points 2 cm apart, and the same seen from `pose`.
    fn corner(pose: &Pose2) -> (Vec<[f64; 2]>, Vec<[f64; 2]>) {
        let world: Vec<[f64; 2]> = (0..100)
            .map(|i| [1.0, -1.0 + 0.02 * i as f64])
            .chain((0..80).map(|i| [1.0 - 0.02 * i as f64, 1.0]))
            .collect();
        let inv = pose.inverse();
        let seen = world.iter().map(|p| inv.transform_point(*p)).collect();
        (world, seen)
    }

    /// What [`best_distinct`] stands for: every candidate sorted (stably, best
    /// first), then taken greedily.
    fn best_distinct_by_full_sort(
        mut all: Vec<Candidate>,
        keep: usize,
        distinct: (f64, f64),
    ) -> Vec<Candidate> {
        all.sort_by(|a, b| b.score.total_cmp(&a.score));
        let mut best: Vec<Candidate> = Vec::new();
        for c in all {
            if best.len() >= keep {
                break;
            }
            if best.iter().all(|b| {
                let d = b.pose.between(&c.pose);
                d.translation_norm() > distinct.0 || wrap_angle(d.theta).abs() > distinct.1
            }) {
                best.push(c);
            }
        }
        best
    }

    /// What [`search`] stands for: every pose of the grid scored on its own, point
    /// after point, then the best distinct ones taken from a full sort.
    /// `window`: half widths (m, rad), level, how many to keep, how far apart.
    fn search_pose_by_pose(
        (grid, reference, current): (&NearestGrid, &[[f64; 2]], &[[f64; 2]]),
        centre: &Pose2,
        window: (f64, f64, Level, usize, (f64, f64)),
    ) -> Vec<Candidate> {
        let (half_xy, half_theta, level, keep, distinct) = window;
        let steps = |half: f64, step: f64| (half / step).round() as i64;
        let (nxy, nth) = (
            steps(half_xy, level.step_xy),
            steps(half_theta, level.step_theta),
        );
        let mut all = Vec::new();
        for k in -nth..=nth {
            let theta = centre.theta + k as f64 * level.step_theta;
            let (s, c) = theta.sin_cos();
            for i in -nxy..=nxy {
                for j in -nxy..=nxy {
                    let t = [
                        centre.x + i as f64 * level.step_xy,
                        centre.y + j as f64 * level.step_xy,
                    ];
                    let mut score = 0.0;
                    for q in current {
                        let p = [c * q[0] - s * q[1] + t[0], s * q[0] + c * q[1] + t[1]];
                        if let Some(n) = grid.nearest(p) {
                            let r = reference[n];
                            let d2 = (p[0] - r[0]).powi(2) + (p[1] - r[1]).powi(2);
                            score += (1.0 - d2 * (1.0 / (level.gate * level.gate))).max(0.0);
                        }
                    }
                    if score > 0.0 {
                        all.push(Candidate {
                            pose: Pose2::new(t[0], t[1], theta),
                            score,
                        });
                    }
                }
            }
        }
        best_distinct_by_full_sort(all, keep, distinct)
    }

    #[test]
    fn search_scores_as_pose_by_pose() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand::rngs::StdRng::seed_from_u64(11);
        let level = Level {
            step_xy: 0.06,
            step_theta: 0.052,
            gate: 0.15,
        };
        for _ in 0..5 {
            let truth = Pose2::new(
                rng.random_range(-0.2..0.2),
                rng.random_range(-0.2..0.2),
                rng.random_range(-0.5..0.5),
            );
            let (reference, mut current) = corner(&truth);
            // Sparse and noisy, as an LDS's scans.
            current.retain(|_| rng.random_bool(0.4));
            for q in &mut current {
                q[0] += rng.random_range(-0.01..0.01);
            }
            let grid = NearestGrid::new(&reference, 0.02, level.gate);
            let guess = Pose2::new(0.03, -0.02, 0.1);
            let args = (0.3, 0.87, level, 3, (0.08, 0.06));
            let fast = search(
                &grid, &reference, &current, &guess, args.0, args.1, args.2, args.3, args.4,
            );
            let slow = search_pose_by_pose((&grid, &reference, &current), &guess, args);
            // The same floating-point sums: equal to the bit.
            assert_eq!(fast, slow);
        }
    }

    #[test]
    fn an_unbounded_window_is_searched_within_bounds() {
        let (reference, current) = corner(&Pose2::new(0.05, 0.0, 0.1));
        let grid = NearestGrid::new(&reference, 0.02, 0.15);
        let level = Level {
            step_xy: 0.06,
            step_theta: 0.052,
            gate: 0.15,
        };
        for half in [1e9, f64::INFINITY] {
            let best = search(
                &grid,
                &reference,
                &current[..20],
                &Pose2::IDENTITY,
                half,
                half,
                level,
                3,
                (0.08, 0.06),
            );
            assert!(!best.is_empty() && best.len() <= 3);
        }
    }

    #[test]
    fn best_distinct_takes_what_a_full_sort_would() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand::rngs::StdRng::seed_from_u64(7);
        for round in 0..200 {
            let n = rng.random_range(0..600);
            // Few score levels: many ties, whose order must be kept; clustered poses,
            // so that the first look often holds too few distinct ones.
            let spread = if round % 2 == 0 { 0.05 } else { 1.0 };
            let all: Vec<Candidate> = (0..n)
                .map(|_| Candidate {
                    pose: Pose2::new(
                        rng.random_range(-spread..spread),
                        rng.random_range(-spread..spread),
                        rng.random_range(-0.1..0.1),
                    ),
                    score: rng.random_range(0..12) as f64,
                })
                .collect();
            for keep in [1, 3, 8] {
                let fast = best_distinct(all.clone(), keep, (0.08, 0.06));
                let full = best_distinct_by_full_sort(all.clone(), keep, (0.08, 0.06));
                assert_eq!(fast, full, "round {round}, keep {keep}");
            }
        }
    }

    #[test]
    fn finds_the_true_pose_from_far_off() {
        let truth = Pose2::new(0.12, -0.07, 0.3);
        let (reference, current) = corner(&truth);
        let grid = NearestGrid::new(&reference, 0.01, 0.2);
        let level = Level {
            step_xy: 0.01,
            step_theta: 0.01,
            gate: 0.05,
        };
        let best = search(
            &grid,
            &reference,
            &current,
            &Pose2::IDENTITY,
            0.2,
            0.4,
            level,
            3,
            (0.05, 0.05),
        );
        let d = truth.between(&best[0].pose);
        assert!(d.translation_norm() < 0.011 && d.theta.abs() < 0.011, "{d}");
        assert!(best.len() <= 3);
        assert!(best.windows(2).all(|w| w[0].score >= w[1].score));
    }
}
