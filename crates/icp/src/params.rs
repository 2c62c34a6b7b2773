//! Tuning parameters of the matcher, with defaults for a Hokuyo URG-04LX.

/// How the closest reference point of each current point is found.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum NeighbourSearch {
    /// Walk the reference scan's rays outward from the ray closest in bearing, stopping
    /// when the bearing difference alone rules out anything closer (CSM's idea for
    /// ordered range scans). Needs strictly increasing ray angles.
    #[default]
    Angular,
    /// A k-d tree (kiddo) over the reference scan's valid points.
    KdTree,
}

/// A correction window that grows with the first guess (see
/// [`IcpParams::guess_window`]): a match may end at most `xy + share · |t|` (m) and
/// `theta + share · |θ|` (rad) from a guess `(t, θ)`. For guesses whose error is
/// known (the pipeline's second pass: odometry with an estimate solved from the log).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GuessWindow {
    /// The fixed part of the displacement's bound (m).
    pub xy: f64,
    /// The fixed part of the rotation's bound (rad).
    pub theta: f64,
    /// The share of the guessed displacement and rotation added.
    pub share: f64,
}

/// Tuning of [`crate::Matcher`] and [`crate::PreparedScan`].
///
/// Distances are in metres, angles in radians.
#[derive(Debug, Clone, PartialEq)]
pub struct IcpParams {
    /// Iterations before giving up with [`crate::IcpError::FailedToConverge`].
    pub max_iterations: u32,
    /// Converged when an iteration moves the estimate by less than this (m) …
    pub epsilon_xy: f64,
    /// … and turns it by less than this (rad).
    pub epsilon_theta: f64,
    /// From this iteration on, a step below `settle_xy` and `settle_theta` also ends the
    /// iterations: on noisy scans a few matches may keep flipping between nearly
    /// equivalent segments, moving the estimate back and forth by micrometres.
    pub settle_after: u32,
    /// See [`IcpParams::settle_after`] (m).
    pub settle_xy: f64,
    /// See [`IcpParams::settle_after`] (rad).
    pub settle_theta: f64,
    /// A current point farther than this from every reference point gets no match (m).
    pub max_correspondence_dist: f64,
    /// At most this fraction of the matches (the ones with the smallest residuals) is
    /// used; 1 (the default) disables the fractional trimming and leaves outlier
    /// removal to the adaptive threshold alone: on simulated URG-04LX pairs, always
    /// dropping the worst 5 % cost 5–10 % of accuracy.
    pub trim_fraction: f64,
    /// Adaptive threshold: residuals above `outlier_sigma_mult · σ̂` are dropped, σ̂ being
    /// the robust (median-based) spread of the residuals of the iteration.
    pub outlier_sigma_mult: f64,
    /// While far from convergence the threshold is at least `step_threshold_mult` times
    /// the largest point motion of the previous iteration, so that a good part of the
    /// matches is never thrown away only because the estimate is still moving.
    pub step_threshold_mult: f64,
    /// Readings at or below this range are invalid (m).
    pub min_reading: f64,
    /// Readings at or above this range are invalid (m), as those at or above the
    /// scan's own maximum range (the `max_range` given to [`crate::PreparedScan::new`])
    /// are. ∞ by default: the scan's maximum alone (the pipeline gives each laser's
    /// range up to its rated accuracy).
    pub max_reading: f64,
    /// Fail if the result is farther than this from the first guess (m).
    pub max_linear_correction: f64,
    /// Fail if the result turns more than this from the first guess (rad).
    pub max_angular_correction: f64,
    /// Number of consecutive points over which the local line of a segment is fitted.
    pub line_fit_window: usize,
    /// A segment whose best local line fit has a larger RMS residual is not used (m).
    pub max_line_fit_rms: f64,
    /// Two consecutive valid points are on the same surface when they are closer than
    /// `max(discontinuity_min_gap, discontinuity_gap_factor · range · Δangle)` (m) …
    pub discontinuity_min_gap: f64,
    /// … see [`IcpParams::discontinuity_min_gap`].
    pub discontinuity_gap_factor: f64,
    /// The last reading of a run at a depth edge that lies off the run's
    /// continuation, towards the surface across the edge, by more than this many
    /// standard deviations (of the range noise — the log's typical one, or the
    /// run's own scatter where larger — with the continuation's own uncertainty) is
    /// a mixed pixel, left out of the scan as a reading without a return; only in
    /// scans of rays at most 0.6° apart (see the crate documentation, step 1). 3 by
    /// default; infinity keeps every reading.
    pub mixed_pixel_sigmas: f64,
    /// Two valid points with up to this many readings without a return between them
    /// (zero, NaN or at most the minimum range: dropouts, dark or glancing spots) are
    /// consecutive points of one run, on one surface when the gap test above holds
    /// over their angle; 0: only neighbouring rays are. Readings at or beyond the
    /// maximum range (+∞ included) are never bridged: the surface ended there. 2 by
    /// default (docs/benchmarks.md, "Runs across missing readings").
    pub bridged_missing_rays: usize,
    /// A scan with fewer valid readings is rejected.
    pub min_valid_points: usize,
    /// A match with fewer used correspondences is rejected.
    pub min_correspondences: usize,
    /// Above this condition number of the (scale-normalised) information matrix the
    /// result is flagged `ill_conditioned`, and the iterations take no step along the
    /// least constrained direction (the result keeps the first guess there).
    pub max_condition_number: f64,
    /// Closest-point search method.
    pub search: NeighbourSearch,
    /// Weight correspondences by the inverse variance of their residual under range
    /// noise: `1 / (cos²α_cur + reference_noise_share · cos²α_ref + min_incidence_cos²)`,
    /// α being the incidence angles of the current ray and of the reference rays on the
    /// line (range noise moves a point along its ray, so only `cos α` of it shows in a
    /// point-to-line distance).
    pub incidence_weighting: bool,
    /// Share of the reference points' noise left in a local line (≈ 1 / effective
    /// number of independent points in the fitting window).
    pub reference_noise_share: f64,
    /// Floor of `cos α` in the weights, bounding the weight of grazing rays.
    pub min_incidence_cos: f64,
    /// Consistency test: a match whose residual spread (robust, over every
    /// correspondence within the gate at the result) exceeds this many times the
    /// range noise the two scans show themselves is refused — it sits in a wrong local
    /// minimum. On simulated URG-04LX pairs right matches are at 1.8× (at most 2.2×;
    /// the noise there is correlated over 4 rays, which the windows partly absorb),
    /// wrong ones at 32× and more. Infinity disables the test.
    pub max_residual_to_noise: f64,
    /// Range noise (σ, m) assumed by the consistency test for a pair of scans neither
    /// of which has enough straight stretches to show its own noise (cluttered or
    /// sparse scans: a fifth of the real URG-04LX scans of the MinesRover logs).
    /// 0 (the default) takes such scans as noise-free, which refuses every match of
    /// them whose residuals are not; the pipeline sets it to the median noise of the
    /// log's scans.
    pub typical_noise_sigma: f64,
    /// Consistency test: a match using fewer than this share of the current scan's
    /// valid points on a usable local line is refused. On simulated URG-04LX pairs 0.4 s apart right matches
    /// use 86–100 %, translations slid along a wall to a wrong but equally tight
    /// alignment 29–60 %. Points landing where the reference has no local line
    /// (clutter, mixed pixels) are left out of the share, as the current scan's own
    /// are ([`crate::IcpResult::matched_share`]): on the realistic TurtleBot 4 preset
    /// (seed 2, every pair matched from its true displacement) 415 of 920 pairs fell
    /// at 51–69 % of all its points, most of them right.
    pub min_matched_share: f64,
    /// When the match from the first guess fails or is refused, it is tried again from
    /// up to this many other starting rotations: the best agreements of the two scans'
    /// histograms of line directions within `max_angular_correction` of the guess
    /// (0: no second try).
    pub rotation_hypotheses: usize,
    /// Basin test (m): a result whose condition number is above a tenth of
    /// `max_condition_number` is matched again from this far on either side along its
    /// least constrained direction (`(x, y, ρθ)`); when the iterations do not come
    /// back (the two results differ beyond the covariance's 99.7 % level) the result
    /// is flagged `ill_conditioned` and its covariance widened. On the simulated
    /// TurtleBot 4 (noise growing with range, clutter) such results were 10–100 mm
    /// off with a reported σ of 1–3 mm. 0 disables the test.
    pub basin_check_step: f64,
    /// A pair where either scan has fewer valid readings per full turn of its field of
    /// view (a 240° scan's count times 1.5) than this is matched by the
    /// sparse matcher (a correlative search, then point-to-line iterations against
    /// lines through metric neighbourhoods; see the crate documentation) instead of
    /// the primary path, whose local lines need runs of consecutive returns. 0: never.
    pub sparse_below_returns: usize,
    /// A bound on the correction that grows with the first guess, within
    /// `max_linear_correction` and `max_angular_correction`: for guesses whose error is
    /// known to be a share of the motion (odometry with a solved estimate). `None`
    /// (the default): the fixed bounds alone, for guesses of unknown quality (the
    /// identity, a nominal typed by hand).
    pub guess_window: Option<GuessWindow>,
}

impl Default for IcpParams {
    fn default() -> Self {
        IcpParams {
            max_iterations: 40,
            epsilon_xy: 5e-5,
            epsilon_theta: 5e-5,
            settle_after: 12,
            settle_xy: 5e-5,
            settle_theta: 5e-5,
            max_correspondence_dist: 0.3,
            trim_fraction: 1.0,
            outlier_sigma_mult: 4.0,
            step_threshold_mult: 3.0,
            min_reading: 0.02,
            max_reading: f64::INFINITY,
            max_linear_correction: 0.3,
            max_angular_correction: 50f64.to_radians(),
            line_fit_window: 7,
            max_line_fit_rms: 0.01,
            discontinuity_min_gap: 0.05,
            discontinuity_gap_factor: 10.0,
            mixed_pixel_sigmas: 3.0,
            bridged_missing_rays: 2,
            min_valid_points: 20,
            min_correspondences: 20,
            max_condition_number: 50.0,
            search: NeighbourSearch::Angular,
            incidence_weighting: true,
            reference_noise_share: 0.5,
            min_incidence_cos: 0.2,
            max_residual_to_noise: 6.0,
            typical_noise_sigma: 0.0,
            min_matched_share: 0.7,
            rotation_hypotheses: 3,
            basin_check_step: 0.02,
            sparse_below_returns: 160,
            guess_window: None,
        }
    }
}

impl IcpParams {
    /// The largest gap (m) between two consecutive points of one run: `range` the
    /// larger of their ranges (m), `step` the angle between their rays (rad); see
    /// [`IcpParams::discontinuity_min_gap`].
    pub(crate) fn run_gap(&self, range: f64, step: f64) -> f64 {
        self.discontinuity_min_gap
            .max(self.discontinuity_gap_factor * range * step.abs())
    }

    /// The readings a scan keeps are those strictly between these (m): its own
    /// `min_range` and `max_range`, narrowed by `min_reading` and `max_reading`.
    pub(crate) fn reading_bounds(&self, min_range: f64, max_range: f64) -> (f64, f64) {
        (
            min_range.max(self.min_reading),
            max_range.min(self.max_reading),
        )
    }

    /// Checks that every parameter is in its meaningful range.
    pub fn validate(&self) -> Result<(), crate::IcpError> {
        let bad = |what: &str| Err(crate::IcpError::InvalidParams(what.to_string()));
        let positive = |v: f64| v.is_finite() && v > 0.0;
        if self.max_iterations == 0 {
            return bad("max_iterations must be at least 1");
        }
        let non_negative = |v: f64| v.is_finite() && v >= 0.0;
        if !non_negative(self.epsilon_xy) || !non_negative(self.epsilon_theta) {
            return bad("epsilon_xy and epsilon_theta must be finite and non-negative");
        }
        if !non_negative(self.settle_xy) || !non_negative(self.settle_theta) {
            return bad("settle_xy and settle_theta must be finite and non-negative");
        }
        if !positive(self.max_correspondence_dist) {
            return bad("max_correspondence_dist must be positive");
        }
        if !(self.trim_fraction > 0.0 && self.trim_fraction <= 1.0) {
            return bad("trim_fraction must be in (0, 1]");
        }
        if !positive(self.outlier_sigma_mult) || !positive(self.step_threshold_mult) {
            return bad("outlier_sigma_mult and step_threshold_mult must be positive");
        }
        if !(self.min_reading.is_finite() && self.min_reading >= 0.0)
            || self.max_reading.is_nan()
            || self.max_reading <= self.min_reading
        {
            return bad("need 0 <= min_reading < max_reading");
        }
        if !positive(self.max_linear_correction) || !positive(self.max_angular_correction) {
            return bad("max_linear_correction and max_angular_correction must be positive");
        }
        if self.line_fit_window < 2 {
            return bad("line_fit_window must be at least 2");
        }
        if !positive(self.max_line_fit_rms) {
            return bad("max_line_fit_rms must be positive");
        }
        if !positive(self.discontinuity_min_gap) || !positive(self.discontinuity_gap_factor) {
            return bad("discontinuity_min_gap and discontinuity_gap_factor must be positive");
        }
        if self.mixed_pixel_sigmas.is_nan() || self.mixed_pixel_sigmas <= 0.0 {
            return bad("mixed_pixel_sigmas must be positive (infinity keeps every reading)");
        }
        if self.min_valid_points < 3 || self.min_correspondences < 3 {
            return bad("min_valid_points and min_correspondences must be at least 3");
        }
        if !positive(self.max_condition_number) {
            return bad("max_condition_number must be positive");
        }
        if !(self.reference_noise_share.is_finite() && self.reference_noise_share >= 0.0) {
            return bad("reference_noise_share must be finite and non-negative");
        }
        if !(self.min_incidence_cos > 0.0 && self.min_incidence_cos <= 1.0) {
            return bad("min_incidence_cos must be in (0, 1]");
        }
        if self.max_residual_to_noise.is_nan() || self.max_residual_to_noise <= 0.0 {
            return bad("max_residual_to_noise must be positive (infinity: no test)");
        }
        if !(self.typical_noise_sigma.is_finite() && self.typical_noise_sigma >= 0.0) {
            return bad("typical_noise_sigma must be finite and non-negative");
        }
        if !(self.basin_check_step.is_finite() && self.basin_check_step >= 0.0) {
            return bad("basin_check_step must be finite and non-negative (0: no test)");
        }
        if !(0.0..=1.0).contains(&self.min_matched_share) {
            return bad("min_matched_share must be in [0, 1]");
        }
        if let Some(w) = &self.guess_window {
            if !positive(w.xy) || !positive(w.theta) || !non_negative(w.share) {
                return bad("guess_window needs positive xy and theta and a non-negative share");
            }
        }
        Ok(())
    }

    /// These parameters with the correction bounds for a match from `guess`: the
    /// fixed ones narrowed by [`IcpParams::guess_window`], when there is one.
    pub fn around(&self, guess: &odocal_geom::Pose2) -> IcpParams {
        let Some(w) = self.guess_window else {
            return self.clone();
        };
        IcpParams {
            max_linear_correction: self
                .max_linear_correction
                .min(w.xy + w.share * guess.translation_norm()),
            max_angular_correction: self
                .max_angular_correction
                .min(w.theta + w.share * odocal_geom::wrap_angle(guess.theta).abs()),
            ..self.clone()
        }
    }
}
