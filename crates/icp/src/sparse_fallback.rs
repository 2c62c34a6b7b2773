//! The matcher of very sparse scans (a 1° LDS with 40–140 returns of 361): a
//! correlative grid search for the basin, then point-to-line iterations against lines
//! fitted over metric neighbourhoods of the reference points.
//!
//! The primary path's local lines come from windows of consecutive rays; on such scans
//! most windows straddle missing readings, and a ray 1° from its neighbour at 3 m is
//! 5 cm away, so the few lines left are poor and the iterations — even started at the
//! true pose — end 20–55 mm off on half the pairs with a σ of 3 mm. Here:
//! 1. `neighbourhood_lines`: a line per reference point through the reference points
//!    within a few ray spacings of it, kept where it is a line at the scan's own noise.
//! 2. `correlative`: every pose within the correction window is scored on a coarse
//!    grid; the best few distinct ones are sharpened on a fine grid.
//! 3. From each, the exact point-to-line step of `solve_step` is iterated with the
//!    current points matched to their nearest reference point's line (within the
//!    extent of its neighbourhood) and a gate shrinking to a few σ of the noise.
//! 4. Two distinct results that explain the scans about equally well are refused as
//!    ambiguous; a result is refused when its residuals are far above the noise or it
//!    explains too little of the current scan (`consistency`), and flagged
//!    ill-conditioned as on the primary path. The covariance is the primary path's
//!    sandwich with the noise by range and the residual autocorrelation
//!    (`covariance`, `range_noise`).

use crate::consistency::{check_consistency, robust_spread};
use crate::correlative::{search, Candidate, Level};
use crate::covariance::{InformationSum, RayResiduals};
use crate::free_direction::free_if_corridor;
use crate::matcher::check_correction;
use crate::nearest_grid::NearestGrid;
use crate::neighbourhood_lines::{
    NeighbourhoodLine, NeighbourhoodLines, MATCHING_RADIUS, MAX_POINTS,
};
use crate::range_noise::RangeBins;
use crate::solve_step::NormalEquations;
use crate::{IcpError, IcpParams, IcpResult, PreparedScan};
use odocal_geom::{wrap_angle, Pose2};

/// The coarse search: 6 cm and 3° steps, 15 cm gate.
const COARSE: Level = Level {
    step_xy: 0.06,
    step_theta: 0.052,
    gate: 0.15,
};
/// The fine search around each coarse candidate: 1.5 cm and 0.5° steps, 5 cm gate.
const FINE: Level = Level {
    step_xy: 0.015,
    step_theta: 0.0087,
    gate: 0.05,
};
/// Coarse candidates sharpened, and fine ones iterated from.
const CANDIDATES: usize = 3;
/// Two candidates closer than this (m, rad) are one.
const DISTINCT: (f64, f64) = (0.08, 0.06);
/// Grid cell of the nearest-point lookup (m).
const CELL: f64 = 0.02;
/// Iterations with the fine search's gate; after them the gate is this many σ of the
/// noise.
const WIDE_ITERATIONS: u32 = 3;
const GATE_SIGMAS: f64 = 4.0;
/// From `settle_after` iterations on, steps moving the points by less than this
/// share of the noise end the iterations.
const SETTLE_NOISE_SHARE: f64 = 0.1;
/// Matches that come back with steps below this (m, rad): converged (a cycle).
const CYCLE_XY: f64 = 1e-4;
const CYCLE_THETA: f64 = 1e-4;

/// A current point may match a line this far beyond its neighbourhood's extent (m).
const LINE_OVERHANG: f64 = 0.03;
/// Two consistent results farther apart than this (m, rad) are different alignments …
const AMBIGUOUS_APART: (f64, f64) = (0.02, 0.0175);
/// … and the pair is ambiguous unless the best one's cost is lower by at least this
/// (a log-likelihood ratio of 8: the evidence of two clean points' worth).
const AMBIGUITY_MARGIN: f64 = 16.0;
/// The cost of a result: `Σ min((e/σ)², COST_CAP²)` over the current points, an
/// unmatched point costing `COST_CAP²` (σ: the scans' noise).
const COST_CAP: f64 = 3.0;
/// Share of the current scan's points a right match explains at least: the pairs
/// the matcher is for overlap by half a scan or more (the primary path asks 70 %,
/// which the sparse scans' clutter and missing returns rarely reach).
const MIN_MATCHED_SHARE: f64 = 0.5;
/// The same for a cloud ([`PreparedScan::from_points`]), over its own scan's points:
/// the other cloud's lines, through neighbourhoods of two scans' points placed by
/// odometry, cover less of what its scans saw than one scan's lines cover of a pair
/// matched alone. The simulated Neato's cloud matches within 20 mm of the truth
/// explained 21–83 % of their own points. At 40 % (stop 38), lower shares took in
/// a match 12.6° wrong; since the clouds' matches keep within the window of what
/// odometry with the estimate allows (`odocal_pipeline::local_map`), that one is
/// refused, and at 25 % the simulated Neato matches 93 % of its overlapping pairs
/// (86 % at 40 %) while the MinesRover logs thinned to a Neato-like scan gain 22–35 %
/// more samples and agree better with their full logs (docs/benchmarks.md, stop 49).
const CLOUD_MIN_MATCHED_SHARE: f64 = 0.25;

// No bound on a sparse match's σ: a match along a wall, uncertain along it, is kept
// with its covariance (the condition number, the basin and the consistency tests still
// apply). A bound of 3 mm / 0.3° (`neato-lds`, 30 seeds × 120 s) left 13 of 30 logs
// with enough samples to calibrate; without it 29 do, every parameter's RMS error/σ
// within 0.74–1.27 (docs/benchmarks.md, "The sparse matcher's σ bound").

/// The Cauchy weight of a residual `e` with scale `sigma`.
fn cauchy(e: f64, sigma: f64) -> f64 {
    1.0 / (1.0 + (e / (2.0 * sigma)).powi(2))
}

/// Is any term of the covariance `cov` not finite?
fn not_finite(cov: &[[f64; 3]; 3]) -> bool {
    !cov.iter().flatten().all(|v| v.is_finite())
}

/// Rays at least this far apart (rad) make a coarse scan: the primary path's windows
/// of consecutive rays span more than 4° there.
const COARSE_RAY_STEP: f64 = 0.7 * std::f64::consts::PI / 180.0;

/// Should the pair be matched by [`match_sparse`]: the rays are coarse (at least
/// [`COARSE_RAY_STEP`] apart), one of the scans has fewer valid readings per full
/// turn than [`IcpParams::sparse_below_returns`], and neither has more valid points
/// than the neighbourhood search takes ([`MAX_POINTS`]: a scan declaring thousands of
/// coarse rays over many turns goes to the primary path, whose cost is linear).
/// A point cloud ([`PreparedScan::from_points`]) is always matched here.
pub(crate) fn applies(
    reference: &PreparedScan,
    current: &PreparedScan,
    params: &IcpParams,
) -> bool {
    let sparse = |s: &PreparedScan| s.cloud || sparse_scan(s, params);
    let searchable = |s: &PreparedScan| s.valid_count() <= MAX_POINTS;
    (sparse(reference) || sparse(current)) && searchable(reference) && searchable(current)
}

/// Are rays at `angles` (rad, in scan order) far enough apart (0.7° on average) for a
/// scan of them to be sparse ([`PreparedScan::is_sparse`])? A scan with closer rays
/// never is, whatever its returns: the cheap test before preparing it.
pub fn coarse_rays(angles: &[f64]) -> bool {
    crate::preprocess::mean_step(angles) >= COARSE_RAY_STEP
}

/// The scan's rays are coarse and it has few returns per turn (see [`applies`]).
pub(crate) fn sparse_scan(scan: &PreparedScan, params: &IcpParams) -> bool {
    scan.ray_step >= COARSE_RAY_STEP
        && returns_per_turn(scan) < params.sparse_below_returns as f64
        && scan.valid_count() <= MAX_POINTS
}

/// The valid readings of `scan` per full turn of its field of view: a 240° laser with
/// 136 returns has 204 per turn, a 360° one with 80 returns 80.
fn returns_per_turn(scan: &PreparedScan) -> f64 {
    let span = (scan.ray_step * scan.ray_count as f64).clamp(1e-3, std::f64::consts::TAU);
    scan.valid_count() as f64 * std::f64::consts::TAU / span
}

/// The valid points of a scan and their ray indices.
fn valid_points(scan: &PreparedScan) -> (Vec<[f64; 2]>, Vec<usize>) {
    let rays = scan.original.iter().map(|&i| i as usize).collect();
    (scan.points.clone(), rays)
}

/// One correspondence of the iterations.
#[derive(Debug, Clone, Copy)]
struct Match {
    /// Index of the current point among the valid ones.
    point: usize,
    line: NeighbourhoodLine,
    /// Residual at the pose it was found at (m).
    residual: f64,
}

/// The sparse pair's data shared by every start.
struct Pair<'a> {
    reference: Vec<[f64; 2]>,
    lines: Vec<Option<NeighbourhoodLine>>,
    current: Vec<[f64; 2]>,
    current_rays: Vec<usize>,
    current_scan: &'a PreparedScan,
    /// The current scan's own points (all but a cloud's placed ones): what the
    /// matched share is taken over.
    own_points: usize,
    noise: f64,
    /// RMS range of the current points (m).
    rms_range: f64,
    grid: NearestGrid,
}

impl Pair<'_> {
    /// The correspondences at `pose` within `gate` (m).
    fn matches(&self, pose: &Pose2, gate: f64, out: &mut Vec<Match>) {
        out.clear();
        for (k, q) in self.current.iter().enumerate() {
            let p = pose.transform_point(*q);
            let Some(j) = self.grid.nearest(p) else {
                continue;
            };
            let Some(line) = self.lines[j] else { continue };
            let along = (p[0] - line.centroid[0]) * -line.normal[1]
                + (p[1] - line.centroid[1]) * line.normal[0];
            if along.abs() > line.half_length + LINE_OVERHANG {
                continue;
            }
            let residual = line.normal[0] * p[0] + line.normal[1] * p[1] - line.offset;
            if residual.abs() <= gate {
                out.push(Match {
                    point: k,
                    line,
                    residual,
                });
            }
        }
    }

    /// The point-to-line iterations from `start`; `anchor` is the caller's guess.
    /// The first iterations use the fine search's gate, the others a fixed gate of a
    /// few σ of the noise, so that the set of matches settles; residuals are weighted
    /// by a Cauchy kernel of scale σ (smooth, unlike a hard threshold).
    fn refine(
        &self,
        start: Pose2,
        anchor: &Pose2,
        params: &IcpParams,
    ) -> Result<Refined, IcpError> {
        let mut pose = start;
        let mut matches = Vec::new();
        let mut history = [0u64; 8];
        let mut converged = false;
        let mut iterations = 0;
        let mut last_step = (f64::NAN, f64::NAN);
        let mut last_motion = Pose2::IDENTITY;
        let settle = (SETTLE_NOISE_SHARE * self.noise).max(params.settle_xy);
        let gate = |iteration: u32| {
            if iteration <= WIDE_ITERATIONS {
                FINE.gate
            } else {
                (GATE_SIGMAS * self.noise).min(FINE.gate)
            }
        };
        while iterations < params.max_iterations {
            iterations += 1;
            self.matches(&pose, gate(iterations), &mut matches);
            if matches.len() < params.min_correspondences {
                return Err(IcpError::TooFewCorrespondences {
                    found: matches.len(),
                    needed: params.min_correspondences,
                    iteration: iterations,
                });
            }
            let mut equations = NormalEquations::new();
            let mut fingerprint = 0xcbf2_9ce4_8422_2325u64;
            for m in &matches {
                let w = cauchy(m.residual, self.noise);
                equations.add(self.current[m.point], m.line.normal, m.line.offset, w);
                fingerprint = (fingerprint ^ (m.point as u64 | (m.line.offset.to_bits() << 16)))
                    .wrapping_mul(0x0000_0100_0000_01b3);
            }
            let next = equations.solve(&pose).ok_or(IcpError::Numerical {
                iteration: iterations,
                what: "singular or non-finite point-to-line step (sparse scans)",
            })?;
            let step = pose.between(&next);
            last_step = (step.translation_norm(), step.theta.abs());
            last_motion = step;
            pose = next;
            let small = last_step.0 <= params.epsilon_xy && last_step.1 <= params.epsilon_theta;
            // Matches flipping between neighbouring lines (whose offsets differ by
            // their noise) move the estimate back and forth: settled once the steps
            // move the points by a small fraction of the noise.
            let settled = iterations >= params.settle_after
                && last_step.0 <= settle
                && last_step.1 * self.rms_range <= settle;
            // The same matches as a few iterations ago: the weights change little,
            // the iterations cycle about the minimum.
            let cycling = iterations > WIDE_ITERATIONS
                && history.contains(&fingerprint)
                && last_step.0 <= CYCLE_XY
                && last_step.1 <= CYCLE_THETA;
            if iterations > WIDE_ITERATIONS && (small || settled || cycling) {
                converged = true;
                break;
            }
            history[iterations as usize % history.len()] = fingerprint;
        }
        if !converged {
            // Along a corridor the iterations may slide along the walls without end:
            // only the directions the scans fix need to have settled.
            return match self.result(pose, anchor, gate(iterations), iterations, params) {
                Ok(r)
                    if settled_across(
                        &last_motion,
                        r.result.free_direction,
                        self.rms_range,
                        settle,
                    ) =>
                {
                    Ok(r)
                }
                _ => Err(IcpError::FailedToConverge {
                    iterations,
                    last_step_xy: last_step.0,
                    last_step_theta: last_step.1,
                }),
            };
        }
        self.result(pose, anchor, gate(iterations), iterations, params)
    }

    /// The result at `pose`: covariance, consistency.
    fn result(
        &self,
        pose: Pose2,
        anchor: &Pose2,
        gate: f64,
        iterations: u32,
        params: &IcpParams,
    ) -> Result<Refined, IcpError> {
        let mut matches = Vec::new();
        // Every correspondence within the fine gate, for the spread (trimmed or not).
        self.matches(&pose, FINE.gate, &mut matches);
        let mut squared: Vec<f64> = matches.iter().map(|m| m.residual * m.residual).collect();
        let residual_spread = robust_spread(&mut squared);
        let mut bins = RangeBins::default();
        for m in &matches {
            let q = self.current[m.point];
            bins.push(q[0].hypot(q[1]), m.residual * m.residual);
        }
        let variances = bins.variances().to_vec();
        let mut rays = RayResiduals::default();
        let mut info = InformationSum::new(&pose, self.current_scan.len(), &mut rays);
        let mut sum_abs = 0.0;
        // The share is of the current scan's own points (a cloud's placed ones help
        // the fit only; see `PreparedScan::from_points`).
        let mut used_own = 0usize;
        // Truncated χ²: every current point costs at most COST_CAP², matched or not.
        let mut cost = (self.current.len() - matches.len()) as f64 * COST_CAP * COST_CAP;
        for (m, v) in matches.iter().zip(variances) {
            cost += (m.residual / self.noise).powi(2).min(COST_CAP * COST_CAP);
            if m.residual.abs() > gate {
                continue;
            }
            sum_abs += m.residual.abs();
            used_own += usize::from(!self.current_scan.is_placed(m.point));
            info.add(
                self.current_rays[m.point],
                self.current[m.point],
                m.line.normal,
                m.residual,
                1.0,
                v,
            );
        }
        let used = info.count();
        if used < params.min_correspondences {
            return Err(IcpError::TooFewCorrespondences {
                found: used,
                needed: params.min_correspondences,
                iteration: iterations,
            });
        }
        let unc = info.finish().ok_or(IcpError::Numerical {
            iteration: iterations,
            what: "non-finite information matrix (sparse scans)",
        })?;
        let result = IcpResult {
            pose,
            covariance: unc.covariance,
            iterations,
            correspondences: used,
            mean_residual: sum_abs / used.max(1) as f64,
            residual_sigma: unc.residual_sigma,
            residual_correlation_inflation: unc.inflation,
            condition_number: unc.condition_number,
            ill_conditioned: unc.condition_number.is_nan()
                || unc.condition_number > params.max_condition_number
                || not_finite(&unc.covariance),
            weakest_direction: unc.weakest_direction,
            residual_spread,
            noise_sigma: self.noise,
            matched_share: used_own as f64 / self.own_points.max(1) as f64,
            starts: 1,
            free_direction: None,
        };
        let sparse = IcpParams {
            min_matched_share: params.min_matched_share.min(if self.current_scan.cloud {
                CLOUD_MIN_MATCHED_SHARE
            } else {
                MIN_MATCHED_SHARE
            }),
            ..params.clone()
        };
        check_consistency(&result, &sparse)?;
        // Along a corridor: the two directions the scans fix, the third left free.
        let result = free_if_corridor(result, anchor, self.rms_range, params.max_condition_number);
        // The correction is judged where the result ends: along a corridor, at the
        // guess (a washboard's minimum far along it says nothing).
        check_correction(anchor, &result.pose, params)?;
        Ok(Refined { result, cost })
    }
}

/// Did the last `step` of the iterations move the points by at most `settle` (m)
/// across a result's `free` direction (a corridor's; see [`free_if_corridor`]),
/// with rotations scaled by `rho`, the current scan's RMS range? Never for a result
/// that fixes every direction (`None`).
fn settled_across(step: &Pose2, free: Option<[f64; 3]>, rho: f64, settle: f64) -> bool {
    let Some(d) = free else {
        return false;
    };
    let s = [step.x, step.y, rho * step.theta];
    let a = [d[0], d[1], rho * d[2]];
    let norm = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
    if norm.is_nan() || norm <= 0.0 {
        return false;
    }
    let along = (s[0] * a[0] + s[1] * a[1] + s[2] * a[2]) / norm;
    let across2 = (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]) - along * along;
    across2.max(0.0).sqrt() <= settle
}

/// A consistent result and how well it explains the scans.
struct Refined {
    result: IcpResult,
    /// Truncated χ² of the current points' residuals (see [`COST_CAP`]).
    cost: f64,
}

/// ŝ for a pair of sparse scans from `first_guess` (see the module documentation).
pub(crate) fn match_sparse(
    reference: &PreparedScan,
    current: &PreparedScan,
    first_guess: Pose2,
    params: &IcpParams,
) -> Result<IcpResult, IcpError> {
    let (reference_points, _) = valid_points(reference);
    let (current_points, current_rays) = valid_points(current);
    let floor = 1e-5 * reference.max_valid_range.max(current.max_valid_range);
    let lines = NeighbourhoodLines::new(&reference_points, MATCHING_RADIUS, floor);
    let current_noise =
        NeighbourhoodLines::new(&current_points, MATCHING_RADIUS, floor).noise_sigma;
    let noise = match (lines.noise_sigma, current_noise) {
        (Some(a), Some(b)) => a.max(b),
        (Some(a), None) | (None, Some(a)) => a,
        (None, None) => params.typical_noise_sigma,
    }
    .max(floor);
    let rms_range = (current_points
        .iter()
        .map(|q| q[0] * q[0] + q[1] * q[1])
        .sum::<f64>()
        / current_points.len().max(1) as f64)
        .sqrt();
    let own_points = (0..current_points.len())
        .filter(|&k| !current.is_placed(k))
        .count();
    let pair = Pair {
        rms_range,
        grid: NearestGrid::new(&reference_points, CELL, COARSE.gate),
        reference: reference_points,
        lines: lines.lines,
        current: current_points,
        current_rays,
        own_points,
        current_scan: current,
        noise,
    };
    let coarse = search(
        &pair.grid,
        &pair.reference,
        &pair.current,
        &first_guess,
        params.max_linear_correction,
        params.max_angular_correction,
        COARSE,
        CANDIDATES,
        DISTINCT,
    );
    let mut starts: Vec<Candidate> = coarse
        .iter()
        .flat_map(|c| {
            search(
                &pair.grid,
                &pair.reference,
                &pair.current,
                &c.pose,
                COARSE.step_xy,
                COARSE.step_theta,
                FINE,
                1,
                DISTINCT,
            )
        })
        .collect();
    starts.sort_by(|a, b| b.score.total_cmp(&a.score));
    let mut first_error = None;
    let mut found: Vec<Refined> = Vec::new();
    for start in &starts {
        match pair.refine(start.pose, &first_guess, params) {
            Ok(r) => found.push(r),
            Err(e) => {
                first_error.get_or_insert(e);
            }
        }
    }
    found.sort_by(|a, b| a.cost.total_cmp(&b.cost));
    let Some(best) = found.first() else {
        return Err(first_error.unwrap_or(IcpError::TooFewCorrespondences {
            found: 0,
            needed: params.min_correspondences,
            iteration: 0,
        }));
    };
    for other in &found[1..] {
        let apart = best.result.pose.between(&other.result.pose);
        let apart_theta = wrap_angle(apart.theta).abs();
        if (apart.translation_norm() > AMBIGUOUS_APART.0 || apart_theta > AMBIGUOUS_APART.1)
            && other.cost < best.cost + AMBIGUITY_MARGIN
        {
            return Err(IcpError::Ambiguous {
                apart_m: apart.translation_norm(),
                apart_deg: apart_theta.to_degrees(),
            });
        }
    }
    Ok(IcpResult {
        starts: starts.len() as u32,
        ..best.result.clone()
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A segment of the test worlds.
    type Wall = ([f64; 2], [f64; 2]);

    /// Range along the ray from `origin` at `angle` to the nearest wall (0: none
    /// within 5 m).
    fn cast(walls: &[Wall], origin: [f64; 2], angle: f64) -> f32 {
        let d = [angle.cos(), angle.sin()];
        let mut best = f64::INFINITY;
        for (a, b) in walls {
            let e = [b[0] - a[0], b[1] - a[1]];
            let denom = d[0] * e[1] - d[1] * e[0];
            if denom.abs() < 1e-12 {
                continue;
            }
            let w = [a[0] - origin[0], a[1] - origin[1]];
            let t = (w[0] * e[1] - w[1] * e[0]) / denom;
            let u = (w[0] * d[1] - w[1] * d[0]) / denom;
            if t > 0.0 && (0.0..=1.0).contains(&u) {
                best = best.min(t);
            }
        }
        if best < 5.0 {
            best as f32
        } else {
            0.0
        }
    }

    /// A 1° scan of `walls` from `pose`, keeping one run of 5 rays in `keep_every`
    /// (sparse: returns come in runs on an LDS).
    fn scan(walls: &[Wall], pose: &Pose2, keep_every: usize, phase: usize) -> Vec<f32> {
        (0..360)
            .map(|i| {
                if ((i / 5) * 7 + phase) % keep_every != 0 {
                    return 0.0;
                }
                cast(
                    walls,
                    [pose.x, pose.y],
                    pose.theta + (i as f64).to_radians(),
                )
            })
            .collect()
    }

    fn angles() -> Vec<f64> {
        (0..360).map(|i| (i as f64).to_radians()).collect()
    }

    /// A 5 m × 4 m room with a box and a pillar.
    fn room() -> Vec<Wall> {
        let mut walls = vec![
            ([-2.5, -2.0], [2.5, -2.0]),
            ([2.5, -2.0], [2.5, 2.0]),
            ([2.5, 2.0], [-2.5, 2.0]),
            ([-2.5, 2.0], [-2.5, -2.0]),
        ];
        let square = |c: [f64; 2], h: f64| {
            [
                ([c[0] - h, c[1] - h], [c[0] + h, c[1] - h]),
                ([c[0] + h, c[1] - h], [c[0] + h, c[1] + h]),
                ([c[0] + h, c[1] + h], [c[0] - h, c[1] + h]),
                ([c[0] - h, c[1] + h], [c[0] - h, c[1] - h]),
            ]
        };
        walls.extend(square([1.2, 0.8], 0.3));
        walls.extend(square([-1.0, -1.1], 0.15));
        walls
    }

    fn prepare(ranges: &[f32], params: &IcpParams) -> PreparedScan {
        PreparedScan::new(ranges, &angles(), 0.06, 5.0, params).unwrap()
    }

    #[test]
    fn recovers_the_displacement_of_noise_free_sparse_scans_exactly() {
        let params = IcpParams::default();
        let walls = room();
        let (a, b) = (Pose2::new(0.1, -0.2, 0.3), Pose2::new(0.22, -0.15, 0.38));
        // A third of the rays return, not the same ones in the two scans.
        let reference = prepare(&scan(&walls, &a, 3, 0), &params);
        let current = prepare(&scan(&walls, &b, 3, 1), &params);
        assert!(reference.valid_count() <= 125 && applies(&reference, &current, &params));
        let truth = a.between(&b);
        let guess = Pose2::new(truth.x - 0.04, truth.y + 0.03, truth.theta - 0.05);
        let r = match_sparse(&reference, &current, guess, &params).unwrap();
        let e = truth.between(&r.pose);
        assert!(e.translation_norm() < 1e-5 && e.theta.abs() < 1e-5, "{e}");
        assert!(!r.ill_conditioned, "{r:?}");
        // Through the matcher: the same path.
        let via = crate::Matcher::new(params)
            .match_scans(&reference, &current, guess)
            .unwrap();
        assert_eq!(via.pose, r.pose);
    }

    /// Scans densified by neighbours placed exactly in their frames
    /// ([`PreparedScan::from_points`]): the clouds' match is exact, and a cloud takes
    /// this path even when it is dense.
    #[test]
    fn clouds_of_placed_neighbours_recover_the_displacement_exactly() {
        let params = IcpParams::default();
        let walls = room();
        let poses = [
            Pose2::new(0.0, -0.25, 0.2),
            Pose2::new(0.1, -0.2, 0.3),
            Pose2::new(0.22, -0.15, 0.38),
            Pose2::new(0.3, -0.1, 0.45),
        ];
        let cloud = |anchor: usize, other: usize, phases: (usize, usize)| {
            let own = prepare(&scan(&walls, &poses[anchor], 3, phases.0), &params);
            let near = prepare(&scan(&walls, &poses[other], 3, phases.1), &params);
            let place = poses[anchor].between(&poses[other]);
            let placed: Vec<_> = near
                .points()
                .iter()
                .map(|p| place.transform_point(*p))
                .collect();
            PreparedScan::from_points(own.points(), &placed, &params).unwrap()
        };
        let reference = cloud(1, 0, (0, 1));
        let current = cloud(2, 3, (2, 0));
        let truth = poses[1].between(&poses[2]);
        let guess = Pose2::new(truth.x - 0.03, truth.y + 0.02, truth.theta - 0.03);
        let r = crate::Matcher::new(params.clone())
            .match_scans(&reference, &current, guess)
            .unwrap();
        let e = truth.between(&r.pose);
        assert!(e.translation_norm() < 1e-5 && e.theta.abs() < 1e-5, "{e}");
        assert!(!r.ill_conditioned, "{r:?}");
        let whole = prepare(&scan(&walls, &poses[1], 1, 0), &params);
        let dense = PreparedScan::from_points(whole.points(), &[], &params).unwrap();
        assert!(!dense.is_sparse(&params) && applies(&dense, &dense, &params));
        assert!(PreparedScan::from_points(&[[1.0, 0.0]; 3], &[], &params).is_err());
    }

    /// The share a cloud's match must explain is of its own scan's points: points
    /// placed from a neighbour where the other cloud saw nothing do not count against
    /// it; the scan's own points there do.
    #[test]
    fn a_cloud_is_judged_by_the_share_of_its_own_points_explained() {
        let params = IcpParams::default();
        let walls = room();
        let (a, b) = (Pose2::new(0.1, -0.2, 0.3), Pose2::new(0.22, -0.15, 0.38));
        let reference = prepare(&scan(&walls, &a, 3, 0), &params);
        let reference = PreparedScan::from_points(reference.points(), &[], &params).unwrap();
        let own = prepare(&scan(&walls, &b, 3, 1), &params).points().to_vec();
        // A wall 3 m long, 4.5 m beyond the room, twice as many points as the scan's.
        let unseen: Vec<[f64; 2]> = (0..2 * own.len())
            .map(|i| [7.0, -1.5 + 3.0 * i as f64 / (2 * own.len()) as f64])
            .collect();
        let truth = a.between(&b);
        let guess = Pose2::new(truth.x - 0.04, truth.y + 0.03, truth.theta - 0.05);
        let alone = PreparedScan::from_points(&own, &[], &params).unwrap();
        let alone = match_sparse(&reference, &alone, guess, &params).unwrap();
        let current = PreparedScan::from_points(&own, &unseen, &params).unwrap();
        let r = match_sparse(&reference, &current, guess, &params).unwrap();
        let e = truth.between(&r.pose);
        assert!(e.translation_norm() < 1e-5 && e.theta.abs() < 1e-5, "{e}");
        assert!(alone.matched_share > 0.6, "{alone:?}");
        assert_eq!(r.matched_share, alone.matched_share);
        // The same points as the scan's own: a third of its share, refused.
        let mixed: Vec<[f64; 2]> = own.iter().chain(&unseen).copied().collect();
        let current = PreparedScan::from_points(&mixed, &[], &params).unwrap();
        let refused = match_sparse(&reference, &current, guess, &params);
        assert!(
            matches!(refused, Err(IcpError::SmallOverlap { .. })),
            "{refused:?}"
        );
    }

    /// `r` fixes `truth`'s rotation and its displacement across walls along x, and
    /// leaves x free at the guess's `guess_x`.
    fn free_along_x(r: &IcpResult, truth: &Pose2, guess_x: f64) {
        let d = r.free_direction.expect("a direction left free");
        assert!(!r.ill_conditioned, "{r:?}");
        assert!(d[0].abs() > 0.999, "{d:?}");
        assert!((r.pose.x - guess_x).abs() < 1e-6, "{r:?}");
        assert!((r.pose.y - truth.y).abs() < 1e-5, "{r:?}");
        assert!((r.pose.theta - truth.theta).abs() < 1e-5, "{r:?}");
        assert!(r.covariance[0][0] >= 0.99 * crate::FREE_VARIANCE, "{r:?}");
        assert!(
            r.covariance[1][1] < 1e-9 && r.covariance[2][2] < 1e-9,
            "{r:?}"
        );
    }

    /// Along a corridor without ends the scans fix the rotation and the
    /// displacement across it, not along it: the match keeps the guess there and
    /// leaves that direction free (its covariance a metre wide along it).
    #[test]
    fn a_corridor_without_ends_leaves_the_direction_along_it_free() {
        let params = IcpParams::default();
        let walls = vec![([-60.0, -1.0], [60.0, -1.0]), ([-60.0, 1.2], [60.0, 1.2])];
        let (a, b) = (Pose2::new(0.0, 0.0, 0.0), Pose2::new(0.1, 0.02, 0.03));
        let reference = prepare(&scan(&walls, &a, 3, 0), &params);
        let current = prepare(&scan(&walls, &b, 3, 1), &params);
        let truth = a.between(&b);
        let guess = Pose2::new(0.05, 0.0, 0.0);
        let r = match_sparse(&reference, &current, guess, &params).unwrap();
        free_along_x(&r, &truth, guess.x);
        // Scans of a room: every direction fixed.
        let walls = room();
        let (a, b) = (Pose2::new(0.1, -0.2, 0.3), Pose2::new(0.22, -0.15, 0.38));
        let reference = prepare(&scan(&walls, &a, 3, 0), &params);
        let current = prepare(&scan(&walls, &b, 3, 1), &params);
        let truth = a.between(&b);
        let guess = Pose2::new(truth.x - 0.04, truth.y + 0.03, truth.theta - 0.05);
        let r = match_sparse(&reference, &current, guess, &params).unwrap();
        assert!(r.free_direction.is_none() && !r.ill_conditioned, "{r:?}");
    }

    /// Posts every 0.4 m along a wall, no ends in sight: shifted by one period the
    /// scans agree as well as at the truth. Refused, or matched with the direction
    /// along the wall left free at the guess: never a displacement along it.
    #[test]
    fn repeated_structure_fixes_no_displacement_along_it() {
        let mut walls = vec![([-60.0, -1.0], [60.0, -1.0])];
        for k in -30..=30 {
            let x = 0.4 * k as f64;
            walls.push(([x - 0.05, 0.8], [x + 0.05, 0.8]));
            walls.push(([x + 0.05, 0.8], [x + 0.05, 0.9]));
            walls.push(([x - 0.05, 0.8], [x - 0.05, 0.9]));
        }
        let params = IcpParams::default();
        let (a, b) = (Pose2::new(0.0, 0.0, 0.0), Pose2::new(0.2, 0.0, 0.0));
        let reference = prepare(&scan(&walls, &a, 2, 0), &params);
        let current = prepare(&scan(&walls, &b, 2, 1), &params);
        // The guess halfway between the truth and the truth shifted by one period.
        match match_sparse(&reference, &current, Pose2::IDENTITY, &params) {
            Ok(r) if !r.ill_conditioned => free_along_x(&r, &a.between(&b), 0.0),
            _ => {}
        }
    }

    /// With a guess window ([`crate::IcpParams::guess_window`]) the search stays
    /// within it: a match 12 cm from a guess allowed 5 cm is refused, not found; a
    /// window that grows with the guess to cover it finds it exactly. Along a
    /// corridor the free direction is not judged against the window: the result
    /// is at the guess there, whatever the washboard's minimum.
    #[test]
    fn a_guess_window_keeps_the_search_near_the_guess() {
        let window = |xy: f64, share: f64| IcpParams {
            guess_window: Some(crate::GuessWindow {
                xy,
                theta: 0.05,
                share,
            }),
            ..IcpParams::default()
        };
        let walls = room();
        let (a, b) = (Pose2::new(0.1, -0.2, 0.3), Pose2::new(0.3, -0.05, 0.32));
        let reference = prepare(&scan(&walls, &a, 2, 0), &IcpParams::default());
        let current = prepare(&scan(&walls, &b, 2, 1), &IcpParams::default());
        let truth = a.between(&b);
        // About 13 cm guessed, 12 cm short.
        let guess = Pose2::new(truth.x - 0.12, truth.y, truth.theta);
        let run = |params: IcpParams| {
            crate::Matcher::new(params).match_scans(&reference, &current, guess)
        };
        let wide = run(IcpParams::default()).unwrap();
        let e = truth.between(&wide.pose);
        assert!(e.translation_norm() < 1e-5 && e.theta.abs() < 1e-5, "{e}");
        let narrow = run(window(0.05, 0.0));
        assert!(
            matches!(narrow, Err(IcpError::CorrectionTooLarge { .. })),
            "{narrow:?}"
        );
        // 5 cm and all of the guessed displacement: wide enough.
        let grown = run(window(0.05, 1.0)).unwrap();
        let e = truth.between(&grown.pose);
        assert!(e.translation_norm() < 1e-5 && e.theta.abs() < 1e-5, "{e}");
        // A corridor: guessed 25 cm along it from the truth, 2 cm across.
        let walls = vec![([-60.0, -1.0], [60.0, -1.0]), ([-60.0, 1.2], [60.0, 1.2])];
        let (a, b) = (Pose2::new(0.0, 0.0, 0.0), Pose2::new(0.1, 0.02, 0.03));
        let reference = prepare(&scan(&walls, &a, 3, 0), &IcpParams::default());
        let current = prepare(&scan(&walls, &b, 3, 1), &IcpParams::default());
        let guess = Pose2::new(0.35, 0.0, 0.0);
        let r = crate::Matcher::new(window(0.05, 0.0))
            .match_scans(&reference, &current, guess)
            .unwrap();
        free_along_x(&r, &a.between(&b), guess.x);
    }

    /// The iterations along a corridor count as settled when their last step moved
    /// the points along the free direction only.
    #[test]
    fn steps_along_the_free_direction_only_are_settled() {
        let free = Some([1.0, 0.0, 0.0]);
        let along = Pose2::new(0.3, 0.0, 0.0);
        let across = Pose2::new(0.3, 0.002, 0.0);
        let turned = Pose2::new(0.0, 0.0, 0.001);
        assert!(settled_across(&along, free, 2.0, 1e-3));
        assert!(!settled_across(&across, free, 2.0, 1e-3));
        // 1 mrad at 2 m moves the points 2 mm.
        assert!(!settled_across(&turned, free, 2.0, 1e-3));
        assert!(settled_across(&turned, free, 2.0, 3e-3));
        assert!(!settled_across(&along, None, 2.0, 1e-3));
    }

    #[test]
    fn dense_scans_take_the_primary_path() {
        let params = IcpParams::default();
        let walls = room();
        let reference = prepare(&scan(&walls, &Pose2::IDENTITY, 1, 0), &params);
        assert!(!applies(&reference, &reference, &params));
        let off = IcpParams {
            sparse_below_returns: 0,
            ..params.clone()
        };
        let guess = Pose2::new(0.01, 0.0, 0.01);
        let with = crate::Matcher::new(params).match_scans(&reference, &reference, guess);
        let without = crate::Matcher::new(off).match_scans(&reference, &reference, guess);
        assert_eq!(with, without);
    }

    /// A scan declaring more coarse rays than a turn holds (a hostile file: 1° apart
    /// over six turns, every one a return) beside a sparse one: not for the sparse
    /// matcher, whose neighbourhood search compares every pair of points.
    #[test]
    fn a_scan_of_more_points_than_the_search_takes_goes_to_the_primary_path() {
        let params = IcpParams::default();
        let walls = room();
        let sparse = prepare(&scan(&walls, &Pose2::IDENTITY, 3, 0), &params);
        let n = MAX_POINTS + 100;
        let many_angles: Vec<f64> = (0..n).map(|i| (i as f64).to_radians()).collect();
        let many_ranges: Vec<f32> = many_angles
            .iter()
            .map(|&a| cast(&walls, [0.0, 0.0], a))
            .collect();
        let many = PreparedScan::new(&many_ranges, &many_angles, 0.06, 5.0, &params).unwrap();
        assert!(many.valid_count() > MAX_POINTS, "{}", many.valid_count());
        assert!(applies(&sparse, &sparse, &params));
        assert!(!applies(&many, &sparse, &params));
        assert!(!applies(&sparse, &many, &params));
    }
}
