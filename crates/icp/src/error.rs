//! Why a scan could not be prepared or a pair could not be matched.

/// Errors of [`crate::PreparedScan::new`] and [`crate::Matcher::match_scans`].
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum IcpError {
    /// A parameter is out of its meaningful range.
    #[error("invalid ICP parameters: {0}")]
    InvalidParams(String),
    /// The scan's arrays disagree or its angles are unusable.
    #[error("invalid scan: {0}")]
    InvalidScan(String),
    /// Not enough readings survive the validity checks (0, NaN, out of range).
    #[error("scan has {valid} valid readings out of {total}, at least {needed} are needed")]
    TooFewValidPoints {
        /// Valid readings found.
        valid: usize,
        /// Readings in the scan.
        total: usize,
        /// Minimum required ([`crate::IcpParams::min_valid_points`]).
        needed: usize,
    },
    /// Not enough current points found a reference segment.
    #[error("only {found} correspondences at iteration {iteration}, at least {needed} are needed")]
    TooFewCorrespondences {
        /// Correspondences kept.
        found: usize,
        /// Minimum required ([`crate::IcpParams::min_correspondences`]).
        needed: usize,
        /// Iteration (1-based) where it happened.
        iteration: u32,
    },
    /// The first guess is not finite.
    #[error("first guess is not finite: {0}")]
    NonFiniteGuess(odocal_geom::Pose2),
    /// The estimate became NaN or the step equations were singular.
    #[error("numerical failure at iteration {iteration}: {what}")]
    Numerical {
        /// Iteration (1-based) where it happened.
        iteration: u32,
        /// What went wrong.
        what: &'static str,
    },
    /// The iterations did not settle.
    #[error("no convergence after {iterations} iterations (last step {last_step_xy:.3e} m, {last_step_theta:.3e} rad)")]
    FailedToConverge {
        /// Iterations done.
        iterations: u32,
        /// Translation of the last step (m).
        last_step_xy: f64,
        /// Rotation of the last step (rad).
        last_step_theta: f64,
    },
    /// The result is too far from the first guess to be trusted.
    #[error("correction from the first guess too large: {linear:.4} m (max {max_linear}), {angular:.4} rad (max {max_angular})")]
    CorrectionTooLarge {
        /// Distance between result and first guess (m).
        linear: f64,
        /// Angle between result and first guess (rad).
        angular: f64,
        /// [`crate::IcpParams::max_linear_correction`].
        max_linear: f64,
        /// [`crate::IcpParams::max_angular_correction`].
        max_angular: f64,
    },
    /// The iterations settled where the residuals are far above the noise the scans
    /// show themselves: a wrong local minimum, not a match.
    #[error("residuals inconsistent with the scans' noise: spread {spread_mm:.2} mm is {ratio:.1}x the scans' own noise {noise_mm:.2} mm (at most {max_ratio}x allowed): a wrong alignment")]
    ResidualAboveNoise {
        /// Robust residual spread at the result (mm).
        spread_mm: f64,
        /// Range noise the scans show about their own local lines (mm).
        noise_mm: f64,
        /// `spread_mm / noise_mm`.
        ratio: f64,
        /// [`crate::IcpParams::max_residual_to_noise`].
        max_ratio: f64,
    },
    /// The result explains too small a part of the current scan.
    #[error("only {share_percent:.0} % of the current scan's points match the reference at the result (at least {min_percent:.0} % needed): too little overlap or a wrong alignment")]
    SmallOverlap {
        /// Share of the valid points used (%).
        share_percent: f64,
        /// [`crate::IcpParams::min_matched_share`] (%).
        min_percent: f64,
    },
    /// Starting points far apart reached different, equally consistent results.
    #[error("ambiguous: two consistent alignments {apart_m:.3} m and {apart_deg:.1}° apart (repeated structure); no result chosen")]
    Ambiguous {
        /// Translation between the two results (m).
        apart_m: f64,
        /// Rotation between the two results (°).
        apart_deg: f64,
    },
}
