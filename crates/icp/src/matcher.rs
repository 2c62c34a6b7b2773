//! The ICP loop: correspondences, trimming, exact step, until the estimate settles.

use crate::consistency::{check_consistency, robust_spread, scans_noise};
use crate::correspondence::{nearest_by_angle, nearest_by_tree, segment_for};
use crate::covariance::{conditioning, InformationSum, RayResiduals};
use crate::range_noise::RangeBins;
use crate::rotation_search::candidate_rotations;
use crate::small_objects::UsedTerm;
use crate::solve_step::NormalEquations;
use crate::trimming::threshold;
use crate::{IcpError, IcpParams, NeighbourSearch, PreparedScan};
use odocal_geom::{wrap_angle, Pose2};

/// `next` moved back so that the step from `estimate` has no component along the
/// unit direction `weak` of `(x, y, ρθ)`.
fn without_component(estimate: &Pose2, next: &Pose2, weak: [f64; 3], rho: f64) -> Pose2 {
    let rho = if rho.is_finite() && rho > 1e-6 {
        rho
    } else {
        1.0
    };
    let d = [
        next.x - estimate.x,
        next.y - estimate.y,
        rho * wrap_angle(next.theta - estimate.theta),
    ];
    let along = d[0] * weak[0] + d[1] * weak[1] + d[2] * weak[2];
    Pose2::new(
        estimate.x + d[0] - along * weak[0],
        estimate.y + d[1] - along * weak[1],
        estimate.theta + (d[2] - along * weak[2]) / rho,
    )
}

/// Outcome of a successful match.
#[derive(Debug, Clone, PartialEq)]
pub struct IcpResult {
    /// ŝ: the pose of the current sensor frame in the reference sensor frame.
    pub pose: Pose2,
    /// Covariance of `pose` as `[x, y, θ]` (m², m·rad, rad²); Hessian-based, see the crate documentation.
    pub covariance: [[f64; 3]; 3],
    /// Iterations done (each: correspondences + one exact step).
    pub iterations: u32,
    /// Correspondences used in the final step (after trimming).
    pub correspondences: usize,
    /// Mean absolute point-to-line residual of the used correspondences (m).
    pub mean_residual: f64,
    /// Weighted residual standard deviation σ̂ (m, for a head-on ray).
    pub residual_sigma: f64,
    /// Variance inflation factor applied to the covariance for the correlation of
    /// neighbouring residuals (≈ 1 for independent noise).
    pub residual_correlation_inflation: f64,
    /// Condition number of the scale-normalised information matrix.
    pub condition_number: f64,
    /// True when `condition_number > max_condition_number`: some direction (see
    /// `weakest_direction`) is poorly constrained — e.g. along a corridor.
    pub ill_conditioned: bool,
    /// Unit vector `(x, y, ρ·θ)` of the least constrained direction (ρ: RMS range of
    /// the used points).
    pub weakest_direction: [f64; 3],
    /// Robust spread (1.4826 × median absolute weighted residual, m for a head-on ray)
    /// over every correspondence within the gate at the result, trimmed or not.
    pub residual_spread: f64,
    /// Range noise the two scans show themselves (the larger of the two; m), with a
    /// floor for exact data; see [`IcpParams::max_residual_to_noise`].
    pub noise_sigma: f64,
    /// Correspondences used in the final step per valid point of the current scan on
    /// a usable local line (at most 1). When that falls short of
    /// [`IcpParams::min_matched_share`], per such point the reference could have
    /// matched: its nearest reference point within the correspondence gate has a
    /// local line, or it has none within the gate (free space counts against a match).
    /// For a point cloud, over its own scan's points only
    /// ([`crate::PreparedScan::from_points`]).
    pub matched_share: f64,
    /// Starting points tried: 1 when the first guess led to the result.
    pub starts: u32,
    /// A match that fixes two directions of the displacement and not the third (a
    /// corridor; module `free_direction`): the free direction as a motion
    /// `(x, y, θ)` (m, m, rad per unit). The pose keeps the first guess along it and
    /// the covariance is [`crate::FREE_VARIANCE`] wide along it. `None` for a match
    /// that fixes all three. Only the sparse scans' matcher gives such matches; the
    /// primary path flags them `ill_conditioned`.
    pub free_direction: Option<[f64; 3]>,
}

/// One used-or-not correspondence of the current iteration.
#[derive(Debug, Clone, Copy)]
struct Correspondence {
    /// Current point in the current sensor frame.
    q: [f64; 2],
    /// Reference line.
    normal: [f64; 2],
    offset: f64,
    /// Weight (inverse residual variance up to a common factor).
    weight: f64,
    /// Tilt variance of the line per unit range-noise variance, and the position of
    /// its window's centroid along the line (errors-in-variables correction).
    tilt_variance: f64,
    centroid_along: f64,
    /// `residual² · weight`: what the trimming compares (squared).
    normalized_sq: f64,
    /// Index of the current point and of the reference segment (for cycle detection).
    key: u64,
}

/// Lines whose tilt variance exceeds this (rad², i.e. a tilt σ of ≈ 1.8°) get no
/// errors-in-variables correction (the first-order correction would not hold).
const MAX_CORRECTED_TILT_VARIANCE: f64 = 0.02;

/// Early convergence: the last two steps must contract at least this fast …
const MAX_PREDICTION_RATIO: f64 = 0.5;
/// … and the predicted largest point motion of the next step be below this fraction
/// of the robust residual spread σ̂ (on URG-04LX pairs σ̂ ≈ 3 mm, and the estimate's
/// own standard deviation moves a point at 4 m by ≈ 1.5 mm, i.e. 0.5 σ̂: stopping
/// there adds < 0.5 % to the RMS error; measured: no change beyond ±0.3 %).
const PREDICTED_MOTION_SHARE: f64 = 0.03;

/// A candidate rotation this close to the first guess's (rad) is not tried again.
const SAME_START_THETA: f64 = 0.035;
/// Two consistent results farther apart than this (m) …
const DISTINCT_XY: f64 = 0.02;
/// … or this (rad) are different alignments: the pair is ambiguous.
const DISTINCT_THETA: f64 = 0.0175;

/// The current point `q` placed in the reference frame by `estimate`, whose rotation's
/// sine and cosine are `sc` (computed once per scan).
#[inline]
fn placed(estimate: &Pose2, (s, c): (f64, f64), q: [f64; 2]) -> [f64; 2] {
    [
        estimate.x + c * q[0] - s * q[1],
        estimate.y + s * q[0] + c * q[1],
    ]
}

/// Number of past correspondence sets remembered to detect a cycle.
const CYCLE_MEMORY: usize = 8;

/// Point-to-line ICP with its scratch buffers (reused: no allocation per iteration
/// once warmed up). Use one per thread.
#[derive(Debug, Clone)]
pub struct Matcher {
    params: IcpParams,
    correspondences: Vec<Correspondence>,
    squared_residuals: Vec<f64>,
    /// Per valid current point: the reference ray where the last search ended.
    search_start: Vec<u32>,
    /// Per valid current point: the last segment matched and its weight.
    weight_cache: Vec<(u32, f64)>,
    /// Scratch of the covariance's residual autocorrelation.
    ray_residuals: RayResiduals,
    /// Scratch of the covariance's residual noise by range.
    range_bins: RangeBins,
    /// The cost envelope's fixed correspondences (current point, line normal, offset,
    /// weight; module `cost_envelope`).
    fixed_lines: Vec<([f64; 2], [f64; 2], f64, f64)>,
    /// The correspondences the last refinement used at its result (module
    /// `small_objects`).
    pub(crate) used_terms: Vec<UsedTerm>,
    /// Those of the result being checked, while the checks run again.
    pub(crate) kept_terms: Vec<UsedTerm>,
    /// Per valid current point: left out of the correspondences (empty: none).
    pub(crate) skipped: Vec<bool>,
}

impl Matcher {
    /// A matcher with these parameters (checked by [`Matcher::match_scans`]).
    pub fn new(params: IcpParams) -> Self {
        Matcher {
            params,
            correspondences: Vec::new(),
            squared_residuals: Vec::new(),
            search_start: Vec::new(),
            weight_cache: Vec::new(),
            ray_residuals: RayResiduals::default(),
            range_bins: RangeBins::default(),
            fixed_lines: Vec::new(),
            used_terms: Vec::new(),
            kept_terms: Vec::new(),
            skipped: Vec::new(),
        }
    }

    /// The parameters.
    pub fn params(&self) -> &IcpParams {
        &self.params
    }

    /// Estimates ŝ, the pose of `current`'s sensor in `reference`'s sensor frame,
    /// starting from `first_guess` (e.g. from odometry).
    ///
    /// When the iterations from the first guess fail or end in a result the
    /// consistency test refuses (residuals far above the scans' own noise, or too few
    /// points matched), they are run again from up to
    /// [`IcpParams::rotation_hypotheses`] other rotations (where the scans' line
    /// directions agree best); the consistent result is returned, an
    /// [`IcpError::Ambiguous`] when two distinct consistent results are found, and the
    /// first attempt's error when none is.
    pub fn match_scans(
        &mut self,
        reference: &PreparedScan,
        current: &PreparedScan,
        first_guess: Pose2,
    ) -> Result<IcpResult, IcpError> {
        self.params.validate()?;
        if !first_guess.is_finite() {
            return Err(IcpError::NonFiniteGuess(first_guess));
        }
        let params = self.params.around(&first_guess);
        if crate::sparse_fallback::applies(reference, current, &params) {
            return crate::sparse_fallback::match_sparse(reference, current, first_guess, &params);
        }
        let use_tree = params.search == NeighbourSearch::KdTree || !reference.angles_increasing;
        if use_tree && reference.tree.is_none() {
            return Err(IcpError::InvalidParams(
                "k-d tree search asked for, but the reference scan was prepared without it \
                 (prepare it with search = KdTree)"
                    .to_string(),
            ));
        }
        let first_error = match self.refine(
            reference,
            current,
            first_guess,
            first_guess,
            &params,
            use_tree,
        ) {
            Ok(result) => {
                // The small-object test needs the correspondences of this result, which
                // the basin test's runs replace.
                std::mem::swap(&mut self.used_terms, &mut self.kept_terms);
                let result =
                    self.basin_checked(reference, current, result, first_guess, &params, use_tree);
                let result = self.envelope_widened(reference, current, result, &params, use_tree);
                return Ok(self.small_objects_widened(
                    reference,
                    current,
                    result,
                    first_guess,
                    first_guess,
                    &params,
                    use_tree,
                ));
            }
            Err(e) => e,
        };
        let candidates = candidate_rotations(
            reference,
            current,
            first_guess.theta,
            params.max_angular_correction,
            params.rotation_hypotheses + 1,
        );
        // The consistent result found, its start, and its correspondences (for the
        // small-object test).
        let mut found: Option<(IcpResult, Pose2, Vec<UsedTerm>)> = None;
        let mut starts = 1;
        for theta in candidates
            .into_iter()
            .filter(|t| (t - first_guess.theta).abs() > SAME_START_THETA)
            .take(params.rotation_hypotheses)
        {
            starts += 1;
            let start = Pose2::new(first_guess.x, first_guess.y, theta);
            let Ok(result) = self.refine(reference, current, start, first_guess, &params, use_tree)
            else {
                continue;
            };
            let terms = std::mem::take(&mut self.used_terms);
            found = match found {
                None => Some((result, start, terms)),
                Some(best) => {
                    let apart = best.0.pose.between(&result.pose);
                    let apart_theta = wrap_angle(apart.theta).abs();
                    if apart.translation_norm() > DISTINCT_XY || apart_theta > DISTINCT_THETA {
                        return Err(IcpError::Ambiguous {
                            apart_m: apart.translation_norm(),
                            apart_deg: apart_theta.to_degrees(),
                        });
                    }
                    Some(if result.matched_share > best.0.matched_share {
                        (result, start, terms)
                    } else {
                        best
                    })
                }
            };
        }
        match found {
            Some((result, start, terms)) => {
                self.kept_terms = terms;
                let result =
                    self.basin_checked(reference, current, result, first_guess, &params, use_tree);
                let result = self.envelope_widened(reference, current, result, &params, use_tree);
                let result = self.small_objects_widened(
                    reference,
                    current,
                    result,
                    start,
                    first_guess,
                    &params,
                    use_tree,
                );
                Ok(IcpResult { starts, ..result })
            }
            None => Err(first_error),
        }
    }

    /// Keeps the correspondences found at `pose` (current point, line normal, offset,
    /// weight) as the fixed ones of [`Matcher::truncated_costs`]; returns the
    /// truncated cost at `pose`.
    pub(crate) fn fix_correspondences(
        &mut self,
        reference: &PreparedScan,
        current: &PreparedScan,
        pose: &Pose2,
        gate2: f64,
        tau_sq: f64,
        use_tree: bool,
    ) -> f64 {
        self.find_correspondences(reference, current, pose, gate2, use_tree);
        self.fixed_lines.clear();
        self.fixed_lines.extend(
            self.correspondences
                .iter()
                .map(|c| (c.q, c.normal, c.offset, c.weight)),
        );
        let unmatched = current.points.len() - self.correspondences.len();
        self.correspondences
            .iter()
            .map(|k| k.normalized_sq.min(tau_sq))
            .sum::<f64>()
            + unmatched as f64 * tau_sq
    }

    /// The truncated cost `Σ min(w e², τ²)` over the valid current points (unmatched
    /// ones at `τ²`) at `pose`: with the correspondences kept by
    /// [`Matcher::fix_correspondences`], and with those found at `pose` (module
    /// `cost_envelope`).
    pub(crate) fn truncated_costs(
        &mut self,
        reference: &PreparedScan,
        current: &PreparedScan,
        pose: &Pose2,
        gate2: f64,
        tau_sq: f64,
        use_tree: bool,
    ) -> (f64, f64) {
        let n = current.points.len() as f64;
        let (s, c) = pose.theta.sin_cos();
        let fixed: f64 = self
            .fixed_lines
            .iter()
            .map(|&(q, normal, offset, w)| {
                let p = [pose.x + c * q[0] - s * q[1], pose.y + s * q[0] + c * q[1]];
                let e = normal[0] * p[0] + normal[1] * p[1] - offset;
                (w * e * e).min(tau_sq)
            })
            .sum::<f64>()
            + (n - self.fixed_lines.len() as f64) * tau_sq;
        self.find_correspondences(reference, current, pose, gate2, use_tree);
        let again: f64 = self
            .correspondences
            .iter()
            .map(|k| k.normalized_sq.min(tau_sq))
            .sum::<f64>()
            + (n - self.correspondences.len() as f64) * tau_sq;
        (fixed, again)
    }

    /// The ICP iterations from `start`, the corrections measured from `anchor` (the
    /// caller's first guess), and the consistency test of the result.
    pub(crate) fn refine(
        &mut self,
        reference: &PreparedScan,
        current: &PreparedScan,
        start: Pose2,
        anchor: Pose2,
        params: &IcpParams,
        use_tree: bool,
    ) -> Result<IcpResult, IcpError> {
        let gate2 = params.max_correspondence_dist * params.max_correspondence_dist;
        let rho_max = current.max_valid_range;

        // First guess of the reference ray for each current point: its bearing turned
        // by the guessed rotation (the walk then corrects for the translation).
        self.weight_cache.clear();
        self.weight_cache
            .resize(current.points.len(), (u32::MAX, 0.0));
        self.search_start.clear();
        match (reference.uniform, current.uniform) {
            // Same ray geometry: the guess is a shift of the ray index.
            (Some(r), Some(c)) if r == c => {
                let shift = (start.theta / r.1).round();
                let last = reference.points.len() as f64 - 1.0;
                self.search_start.extend(
                    (0..current.points.len()).map(|i| (i as f64 + shift).clamp(0.0, last) as u32),
                );
            }
            _ => {
                for angle in &current.angles {
                    let bearing = angle + start.theta;
                    self.search_start
                        .push(reference.ray_near_bearing(bearing) as u32);
                }
            }
        }

        let mut estimate = start;
        let mut previous_motion: Option<f64> = None;
        let mut tau = f64::INFINITY;
        let mut iterations = 0;
        let mut converged = false;
        let mut last_step = (f64::INFINITY, f64::INFINITY);
        // Fingerprints of the sets of used correspondences of the last iterations.
        let mut history = [0u64; CYCLE_MEMORY];
        let mut well_conditioned = false;
        // Set after a first cycle: the threshold then follows the residual spread only.
        let mut motion_term_dropped = false;
        while iterations < params.max_iterations {
            iterations += 1;
            self.find_correspondences(reference, current, &estimate, gate2, use_tree);
            let found = self.correspondences.len();
            if found < params.min_correspondences {
                return Err(IcpError::TooFewCorrespondences {
                    found,
                    needed: params.min_correspondences,
                    iteration: iterations,
                });
            }
            self.squared_residuals.clear();
            self.squared_residuals
                .extend(self.correspondences.iter().map(|c| c.normalized_sq));
            let motion = if motion_term_dropped {
                Some(0.0)
            } else {
                previous_motion
            };
            let (motion_limited, noise_tau);
            (tau, motion_limited, noise_tau) =
                threshold(&mut self.squared_residuals, params, motion, tau);
            let noise_tau_sq = noise_tau * noise_tau;
            // Tilt-noise scale of the reference lines, for the errors-in-variables
            // correction (0 on noise-free scans).
            let noise_variance = reference.tilt_noise_scale;
            let tau_sq = tau * tau;

            let mut equations = NormalEquations::new();
            let mut used = 0;
            // Used matches that the threshold without the motion term would drop.
            let mut beyond_noise = 0;
            let mut fingerprint = 0xcbf2_9ce4_8422_2325u64;
            for c in self
                .correspondences
                .iter()
                .filter(|c| c.normalized_sq <= tau_sq)
            {
                // Errors-in-variables correction, first order: only for lines whose
                // tilt is small.
                let tilt = noise_variance * c.tilt_variance;
                if tilt > 0.0 && tilt <= MAX_CORRECTED_TILT_VARIANCE {
                    equations.add_corrected(
                        c.q,
                        c.normal,
                        c.offset,
                        c.weight,
                        c.centroid_along,
                        c.weight * tilt,
                    );
                } else {
                    equations.add(c.q, c.normal, c.offset, c.weight);
                }
                used += 1;
                beyond_noise += usize::from(c.normalized_sq > noise_tau_sq);
                fingerprint = (fingerprint ^ c.key).wrapping_mul(0x0000_0100_0000_01b3);
            }
            if used < params.min_correspondences {
                return Err(IcpError::TooFewCorrespondences {
                    found: used,
                    needed: params.min_correspondences,
                    iteration: iterations,
                });
            }
            // Tilt corrections that outweigh the information (many poor lines while
            // far off): the step without them.
            let mut next = match equations.solve(&estimate) {
                Some(next) => Some(next),
                None => self.plain_equations(tau_sq).solve(&estimate),
            }
            .ok_or(IcpError::Numerical {
                iteration: iterations,
                what: "singular or non-finite point-to-line step",
            })?;
            // Degeneracy: along a direction the scans hardly constrain (a corridor),
            // the step would only follow noise. Keep the estimate there as it is —
            // i.e. at the first guess — and move only along the others.
            // The geometry changes little between iterations: once the problem is found
            // comfortably well conditioned (10× margin), it is not checked again.
            if !well_conditioned {
                let (info, rho) = equations.information(estimate.theta);
                if let Some(cond) = conditioning(&info, rho) {
                    if cond.condition_number.is_nan()
                        || cond.condition_number > params.max_condition_number
                    {
                        next = without_component(&estimate, &next, cond.weakest_direction, rho);
                    } else if cond.condition_number * 10.0 < params.max_condition_number {
                        well_conditioned = true;
                    }
                }
            }
            let step = estimate.between(&next);
            let step_xy = step.translation_norm();
            let step_theta = step.theta.abs();
            let previous_step = last_step;
            last_step = (step_xy, step_theta);
            estimate = next;
            previous_motion = Some(step_xy + rho_max * step_theta);
            // The matches the next iteration would use are these, up to the closest
            // points moving: the motion term of the threshold drops nothing more.
            let trimming_settled = !motion_limited || beyond_noise == 0;
            if step_xy <= params.epsilon_xy
                && step_theta <= params.epsilon_theta
                && trimming_settled
            {
                converged = true;
                break;
            }
            // The steps shrink geometrically near the solution: when the next one is
            // predicted (from the contraction of the last two) to be below the
            // epsilons and to move the points by a negligible fraction of the residual
            // noise (so never on noise-free scans), it is not taken — that saves the
            // iteration that would only confirm convergence.
            if trimming_settled && iterations >= 2 {
                let ratio = (step_xy / previous_step.0.max(f64::MIN_POSITIVE))
                    .max(step_theta / previous_step.1.max(f64::MIN_POSITIVE));
                let noise_sigma = noise_tau / params.outlier_sigma_mult;
                if ratio <= MAX_PREDICTION_RATIO
                    && ratio * step_xy <= params.epsilon_xy
                    && ratio * step_theta <= params.epsilon_theta
                    && ratio * (step_xy + rho_max * step_theta)
                        <= PREDICTED_MOTION_SHARE * noise_sigma
                {
                    converged = true;
                    break;
                }
            }
            // The same correspondences as a few iterations ago: the iterations cycle
            // (the weights depend on the correspondences only, so the same set gives
            // the same solution). A first cycle is broken by letting the threshold
            // drop to the residual spread — on exact data that removes the last
            // imperfect matches near corners; a cycle after that is noise flipping
            // matches between nearly equivalent segments, and another turn would only
            // repeat it.
            let slot = iterations as usize % CYCLE_MEMORY;
            if history.contains(&fingerprint) {
                if motion_term_dropped {
                    converged = true;
                    break;
                }
                motion_term_dropped = true;
                history = [0; CYCLE_MEMORY];
            }
            history[slot] = fingerprint;
            // Longer or irregular flipping: accept once the steps are negligible.
            if iterations >= params.settle_after
                && step_xy <= params.settle_xy
                && step_theta <= params.settle_theta
            {
                converged = true;
                break;
            }
            // Hopelessly far: stop early (the final check reports it).
            let off = anchor.between(&estimate);
            if off.translation_norm() > 3.0 * params.max_linear_correction
                || off.theta.abs() > 3.0 * params.max_angular_correction
            {
                break;
            }
        }
        check_ending(&anchor, &estimate, converged, iterations, last_step, params)?;

        // Uncertainty at the final estimate, over the correspondences used last; the
        // residual spread over all of them (used or not) for the consistency test.
        let tau_sq = tau * tau;
        let mut info = InformationSum::new(&estimate, current.len(), &mut self.ray_residuals);
        let (s, c) = estimate.theta.sin_cos();
        let mut sum_abs = 0.0;
        self.squared_residuals.clear();
        self.range_bins.clear();
        let residual = |k: &Correspondence| {
            let p = placed(&estimate, (s, c), k.q);
            k.normal[0] * p[0] + k.normal[1] * p[1] - k.offset
        };
        for k in &self.correspondences {
            let e = residual(k);
            self.squared_residuals.push(e * e * k.weight);
            // The range as √(x² + y²): `hypot`'s care for overflow is not needed at a
            // laser's ranges, and it was 2 % of `calibrate`'s CPU.
            let range = (k.q[0] * k.q[0] + k.q[1] * k.q[1]).sqrt();
            self.range_bins.push(range, e * e * k.weight);
        }
        let noise_variances = self.range_bins.variances();
        self.used_terms.clear();
        for (k, &v) in self.correspondences.iter().zip(noise_variances) {
            if k.normalized_sq > tau_sq {
                continue;
            }
            let e = residual(k);
            sum_abs += e.abs();
            let j = info.add(
                current.original[(k.key >> 32) as usize] as usize,
                k.q,
                k.normal,
                e,
                k.weight,
                v,
            );
            self.used_terms.push(UsedTerm {
                index: (k.key >> 32) as u32,
                j,
                w: k.weight,
            });
        }
        let used = info.count();
        let unc = info.finish().ok_or(IcpError::Numerical {
            iteration: iterations,
            what: "non-finite information matrix",
        })?;
        let result = IcpResult {
            pose: estimate,
            covariance: unc.covariance,
            iterations,
            correspondences: used,
            mean_residual: sum_abs / used.max(1) as f64,
            residual_sigma: unc.residual_sigma,
            residual_correlation_inflation: unc.inflation,
            condition_number: unc.condition_number,
            ill_conditioned: unc.condition_number.is_nan()
                || unc.condition_number > params.max_condition_number,
            weakest_direction: unc.weakest_direction,
            residual_spread: robust_spread(&mut self.squared_residuals),
            noise_sigma: scans_noise(reference, current, params),
            matched_share: (used as f64 / self.lined_not_skipped(current).max(1) as f64).min(1.0),
            starts: 1,
            free_direction: None,
        };
        let result = if result.matched_share < params.min_matched_share {
            // Short of the share: leave out of it the current points that land where
            // the reference scan itself has no line (a reading it lost, an edge): the
            // current scan's own such points are not counted either.
            let matchable = self.matchable_lined(reference, current, &estimate, gate2, use_tree);
            IcpResult {
                matched_share: (used as f64 / matchable.max(1) as f64).min(1.0),
                ..result
            }
        } else {
            result
        };
        check_consistency(&result, params)?;
        Ok(result)
    }

    /// True when current point `k` is left out of the correspondences.
    #[inline]
    fn is_skipped(&self, k: usize) -> bool {
        self.skipped.get(k).copied().unwrap_or(false)
    }

    /// The current scan's points with a local line, less those left out.
    fn lined_not_skipped(&self, current: &PreparedScan) -> usize {
        if self.skipped.is_empty() {
            return current.lined_count;
        }
        current
            .incidence_cos
            .iter()
            .zip(&self.skipped)
            .filter(|(c, &skip)| !c.is_nan() && !skip)
            .count()
    }

    /// The normal equations of the used correspondences without the
    /// errors-in-variables correction.
    fn plain_equations(&self, tau_sq: f64) -> NormalEquations {
        let mut equations = NormalEquations::new();
        for c in self
            .correspondences
            .iter()
            .filter(|c| c.normalized_sq <= tau_sq)
        {
            equations.add(c.q, c.normal, c.offset, c.weight);
        }
        equations
    }

    /// The current scan's points with a local line of their own, less those whose
    /// nearest reference point at `estimate` (within the correspondence gate) has
    /// none: the points the reference could have matched. Points with no reference
    /// point within the gate stay counted (a wrong alignment puts points there).
    fn matchable_lined(
        &mut self,
        reference: &PreparedScan,
        current: &PreparedScan,
        estimate: &Pose2,
        gate2: f64,
        use_tree: bool,
    ) -> usize {
        let (s, c) = estimate.theta.sin_cos();
        let mut count = 0;
        for (k, &q) in current.points.iter().enumerate() {
            if current.incidence_cos[k].is_nan() || self.is_skipped(k) {
                continue;
            }
            let p = placed(estimate, (s, c), q);
            let nearest = self.nearest_reference(reference, p, k, gate2, use_tree);
            if nearest.is_none_or(|j| !reference.incidence_cos[j].is_nan()) {
                count += 1;
            }
        }
        count
    }

    /// The reference point nearest to `p` (current point `k` placed by the estimate)
    /// within the gate: by the k-d tree, or by angle from the point's last match.
    fn nearest_reference(
        &self,
        reference: &PreparedScan,
        p: [f64; 2],
        k: usize,
        gate2: f64,
        use_tree: bool,
    ) -> Option<usize> {
        if use_tree {
            nearest_by_tree(reference, p, gate2)
        } else {
            nearest_by_angle(reference, p, self.search_start[k] as usize, gate2)
        }
    }

    /// Fills `self.correspondences` for the estimate.
    fn find_correspondences(
        &mut self,
        reference: &PreparedScan,
        current: &PreparedScan,
        estimate: &Pose2,
        gate2: f64,
        use_tree: bool,
    ) {
        self.correspondences.clear();
        let (s, c) = estimate.theta.sin_cos();
        for (k, &q) in current.points.iter().enumerate() {
            if self.is_skipped(k) {
                continue;
            }
            let p = placed(estimate, (s, c), q);
            let nearest = self.nearest_reference(reference, p, k, gate2, use_tree);
            let Some(j) = nearest else { continue };
            self.search_start[k] = j as u32;
            let Some(seg) = segment_for(reference, p, j) else {
                continue;
            };
            let Some(line) = reference.segments[seg] else {
                continue;
            };
            let residual = line.normal[0] * p[0] + line.normal[1] * p[1] - line.offset;
            let weight = if !self.params.incidence_weighting {
                1.0
            } else if self.weight_cache[k].0 == seg as u32 {
                self.weight_cache[k].1
            } else {
                // Incidence of the current ray on its own surface (a property of the
                // current scan alone, so that a correspondence's weight never depends
                // on the estimate), or of the reference rays when unknown.
                let own = current.incidence_cos[k];
                let cos_cur = if own.is_nan() {
                    line.incidence_cos
                } else {
                    own
                };
                let floor = self.params.min_incidence_cos;
                let w = 1.0
                    / (cos_cur * cos_cur
                        + self.params.reference_noise_share
                            * line.incidence_cos
                            * line.incidence_cos
                        + floor * floor);
                self.weight_cache[k] = (seg as u32, w);
                w
            };
            self.correspondences.push(Correspondence {
                q,
                normal: line.normal,
                offset: line.offset,
                weight,
                tilt_variance: line.tilt_variance,
                centroid_along: line.centroid_along,
                normalized_sq: residual * residual * weight,
                key: ((k as u64) << 32) | seg as u64,
            });
        }
    }
}

/// The verdict on how an iteration ended: the correction from `anchor` (the first
/// guess) beyond the limits ([`check_correction`]), or no convergence, is an error
/// (the order in which they are reported).
pub(crate) fn check_ending(
    anchor: &Pose2,
    estimate: &Pose2,
    converged: bool,
    iterations: u32,
    last_step: (f64, f64),
    params: &IcpParams,
) -> Result<(), IcpError> {
    check_correction(anchor, estimate, params)?;
    check_convergence(converged, iterations, last_step)
}

/// A correction of `estimate` from `anchor` (the first guess) beyond
/// `params.max_linear_correction` or `params.max_angular_correction` is an error.
/// Shared by the point-to-line matcher and the sparse fallback.
pub(crate) fn check_correction(
    anchor: &Pose2,
    estimate: &Pose2,
    params: &IcpParams,
) -> Result<(), IcpError> {
    let correction = anchor.between(estimate);
    let (linear, angular) = (
        correction.translation_norm(),
        wrap_angle(correction.theta).abs(),
    );
    if linear > params.max_linear_correction || angular > params.max_angular_correction {
        return Err(IcpError::CorrectionTooLarge {
            linear,
            angular,
            max_linear: params.max_linear_correction,
            max_angular: params.max_angular_correction,
        });
    }
    Ok(())
}

/// Iterations that did not converge are an error. Shared by the point-to-line
/// matcher and the sparse fallback.
pub(crate) fn check_convergence(
    converged: bool,
    iterations: u32,
    last_step: (f64, f64),
) -> Result<(), IcpError> {
    if !converged {
        return Err(IcpError::FailedToConverge {
            iterations,
            last_step_xy: last_step.0,
            last_step_theta: last_step.1,
        });
    }
    Ok(())
}
