//! The report of a calibration: what `--json` prints and `results.json` holds, and
//! the human summary.

use crate::provenance::Provenance;
use odocal_geom::FlatParams;
use odocal_log::Log;
use odocal_pipeline::consistency::Consistency;
use odocal_pipeline::self_check::MatchSelfCheck;
use odocal_pipeline::sync::DiscardCounts;
use odocal_pipeline::{Estimate, Finding, FindingKind, Options, Outcome, RejectionCounts, Timing};
use odocal_solver::{
    Constraint, LateralSlip, NoiseShaping, NoiseSource, Observability, SharedScanNoise,
    PARAMETER_NAMES,
};
use serde::Serialize;
use std::fmt;
use std::path::Path;

/// Everything a user needs from one calibration.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Report {
    /// The log calibrated.
    pub log: String,
    /// What the reader found in it.
    pub log_contents: LogContents,
    /// The data-health findings: each fault found, what was done, what the user can do.
    pub health: Vec<Finding>,
    /// The estimate: fields `r_l`, `r_r`, `b`, `l_x`, `l_y`, `l_theta` (m, rad).
    #[serde(flatten)]
    pub params: FlatParams,
    /// Standard deviations from the data alone, order r_L, r_R, b, ℓx, ℓy, ℓθ (the
    /// laser's range scale is in `range_scale`, with data and scale together).
    pub sigma: [f64; 6],
    /// Covariance 6×6 from the data alone, order r_L, r_R, b, ℓx, ℓy, ℓθ.
    pub covariance: [[f64; 6]; 6],
    /// The laser's range scale: its σ and where it came from (stated, the data sheet
    /// of the range finder recognised, unknown), the σ it adds, and the σ and
    /// covariance of data and scale together.
    pub range_scale: crate::range_scale::RangeScaleReport,
    /// `J = [[r_L/2, r_R/2], [−r_L/b, r_R/b]]`.
    pub j: [[f64; 2]; 2],
    /// The closed-form estimate (before refinement): r_L, r_R, b, ℓx, ℓy, ℓθ.
    pub closed_form: [f64; 6],
    /// Samples used by the final estimate (after trimming).
    pub samples_used: usize,
    /// Samples handed to the solver (before trimming).
    pub samples_synchronized: usize,
    /// Samples removed by outlier trimming.
    pub samples_trimmed: usize,
    /// Scan pairs considered.
    pub scan_pairs: usize,
    /// Scan pairs discarded before the solver, by reason.
    pub discarded: DiscardCounts,
    /// The pairs discarded as `match_failed`, by the matcher's reason (overlap,
    /// residuals, correction, correspondences, conditioning, ambiguity, …).
    pub match_rejections: RejectionCounts,
    /// Pairs refused when matched directly and matched through the scans between
    /// their two instead (a chain of 2 to 4 shorter matches; see
    /// `odocal_pipeline::chained`), among the samples synchronized.
    pub chained_matches: usize,
    /// Pairs of sparse scans refused when matched alone and matched with each scan
    /// densified by the scan beyond it (or two), placed by odometry (see
    /// `odocal_pipeline::local_map`), among the samples synchronized.
    pub neighbour_matches: usize,
    /// Pairs of sparse scans matched along a corridor, among the samples
    /// synchronized: the match fixes two directions of the displacement (across the
    /// walls, the rotation) and not the third, where ŝ keeps odometry's first guess
    /// and the calibration gives it no weight (see `odocal_icp::IcpResult::free_direction`).
    pub free_direction_matches: usize,
    /// The scan matcher's own error per pair, measured on this log by the closure of
    /// scan triples; absent when too few triples close.
    pub match_self_check: Option<MatchSelfCheck>,
    /// Scans between the two of a pair.
    pub stride: usize,
    /// Median interval between the two scans of a sample (s).
    pub interval_s: f64,
    /// Encoder ticks per wheel revolution used.
    pub ticks_per_revolution: f64,
    /// Estimated scan-matching noise σ (x m, y m, θ rad).
    pub sm_sigma: [f64; 3],
    /// How the samples were weighted: `shaped` (the typical match's σ,
    /// `noise_shaping.weight_level`, shaped per sample by the matcher's covariance of
    /// it relative to the typical match's), `estimated` (`sm_sigma` for every sample)
    /// or `sample_covariance` (`--icp-covariance`).
    pub noise_weights: NoiseSource,
    /// With `noise_weights` `shaped`: the typical match's σ the samples were weighted
    /// by, the share of the residuals' noise that follows the matcher's covariances
    /// (per component), and the level the σ of the estimate take with that blend.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub noise_shaping: Option<NoiseShaping>,
    /// Weighted cost at the closed form and at the estimate.
    pub cost_before: f64,
    /// Weighted cost at the returned estimate.
    pub cost_after: f64,
    /// Observability verdicts.
    pub observability: Observability,
    /// The two halves of the samples calibrated separately and compared.
    pub consistency: Consistency,
    /// The noise shared by consecutive samples (through their common scan) that the
    /// covariance accounts for; absent when the samples were treated as independent.
    pub shared_scan_noise: Option<SharedScanNoise>,
    /// The sideways slide of a skid-steer robot in turns, `v_y = −k·v·ω`, when it was
    /// checked for: `k` (s) with its σ, and `applied` when the estimate includes it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lateral_slip: Option<LateralSlip>,
    /// Estimated clock offset (s, laser clock minus encoder clock), when asked.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub time_offset_s: Option<f64>,
    /// Standard deviation (s) of the estimated clock offset, from the curvature of the
    /// offset search's cost, when it is convex there.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub time_offset_sigma_s: Option<f64>,
    /// How far the parameters (r_L, r_R, b, ℓx, ℓy, ℓθ) move when the clock offset
    /// moves by its σ (half the difference of the estimates solved at the offset ± σ);
    /// the covariance includes it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub time_offset_parameter_shift: Option<[f64; 6]>,
    /// The nominal parameters given (`--nominal`), order r_L, r_R, b, ℓx, ℓy, ℓθ.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub nominal: Option<[f64; 6]>,
    /// Odometry-only mode: the wheel rotations were recovered from odometry poses with
    /// the nominal parameters (whose absolute scale the radii then inherit).
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub odometry_only: bool,
    /// The laser pose the input's own description gives (a bag's `/tf_static`), in
    /// the base frame named there.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub nominal_laser: Option<NominalLaserPose>,
    /// With nominal values: `estimate / nominal` of r_L, r_R and b, what to multiply
    /// the robot's configured values by.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub correction_factors: Option<[f64; 3]>,
    /// Consistency checks of the result (e.g. the two halves of the log agree).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub checks: Vec<Finding>,
    /// Command line, version, input checksum and wall time, when the caller gives them.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub provenance: Option<Provenance>,
    /// Duration of one laser sweep (s), when the rays were taken one after another and
    /// the sweep was compensated before matching.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sweep_compensated_s: Option<f64>,
    /// Trimming rule, refinement, profile use.
    pub settings: Settings,
    /// Wall time per stage (s).
    pub timing_s: Timing,
    /// With several logs calibrated together: one row per log.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub logs: Vec<crate::joint::LogRow>,
    /// With `--all-pairs` and several logs given: one row per log given, its phases
    /// solved together (the rows of `logs` are its phases).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub logs_given: Vec<crate::joint::LogRow>,
    /// With `--all-pairs`: per log given, how much its phases share their errors
    /// (the joint σ are scaled by the largest `sigma_factor`).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub phase_correlation: Vec<crate::joint::PhaseCorrelationRow>,
    /// With several lasers on the robot: one row per laser (the six-parameter fields
    /// above are the first laser's).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub lasers: Vec<crate::joint::LaserRow>,
}

/// A nominal laser pose read from the input (a bag's static transforms).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct NominalLaserPose {
    /// Where it was read (`/tf_static`).
    pub source: String,
    /// The frame it is relative to (`base_link`, `base_footprint`, …).
    pub base_frame: String,
    /// The scan's frame.
    pub laser_frame: String,
    /// Forward offset (m).
    pub l_x: f64,
    /// Leftward offset (m).
    pub l_y: f64,
    /// Yaw (rad).
    pub l_theta: f64,
}

/// Counts from the log reader.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LogContents {
    /// Scans read.
    pub scans: usize,
    /// ENCODER records read.
    pub encoder_records: usize,
    /// What the wheel records are called in the summary: `encoder records` for a text
    /// log, `TOPIC messages` for a bag.
    #[serde(skip)]
    pub wheel_records: String,
    /// Malformed lines skipped (lenient mode).
    pub skipped_lines: u64,
    /// The first skipped lines: (1-based line, error).
    pub first_skipped: Vec<(u64, String)>,
    /// Messages of unknown names, skipped.
    pub unknown_messages: u64,
}

/// Settings worth recording with the results.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Settings {
    /// The trimming rule.
    pub trim: odocal_solver::Trim,
    /// ML refinement on.
    pub refine: bool,
    /// Encoder profile (non-constant speeds) used.
    pub use_profile: bool,
    /// ŝ weighted by the scan matcher's covariance.
    pub use_icp_covariance: bool,
    /// First guesses: "nominal" (given parameters), "bootstrap" (rough estimate from
    /// a subset) or "identity".
    pub first_guess: &'static str,
    /// Second matching pass.
    pub second_pass: bool,
    /// Scan matching used the readings below this range (m): the range the laser is
    /// rated for when recognised, else the maximum its scans declare (see
    /// `odocal_pipeline::LaserSignature::matching_range`).
    pub matching_range_m: f64,
    /// In words, when scan matching left out readings the scans declare valid ("readings
    /// up to 4 m of the 5.6 m the scans declare (the Hokuyo URG-04LX's rated range; …)");
    /// `None` when it used their whole range.
    pub matching_range_statement: Option<String>,
    /// Clock offset applied when not estimated (s).
    pub time_offset_s: f64,
    /// Per parameter (r_L, r_R, b, l_x, l_y, l_theta): "free", {"held": value}
    /// (`--fix`) or {"prior": {"mean", "sigma"}} (`--prior`).
    pub constraints: odocal_solver::Constraints,
    /// Numbers returned even for weakly determined parameters (`--accept-weak`).
    pub accept_weak: bool,
}

/// The two-halves check as a finding: a note when the halves agree or could not
/// be checked, a warning when they disagree beyond 3σ.
fn two_halves(c: &Consistency) -> Finding {
    match c {
        Consistency::Checked(h) if h.agree => {
            Finding::note(FindingKind::TwoHalves, h.sentence.clone())
        }
        Consistency::Checked(h) => Finding::warning(FindingKind::TwoHalves, h.sentence.clone()),
        Consistency::NotAvailable { reason } => Finding::note(
            FindingKind::TwoHalves,
            format!("the two halves of the log were not compared: {reason}"),
        ),
    }
}

/// Builds the report of a finished calibration.
pub fn build_report(path: &Path, log: &Log, opts: &Options, outcome: &Outcome) -> Report {
    let c = &outcome.calibration;
    let e = Estimate::of(outcome);
    let v = e.params;
    Report {
        log: path.display().to_string(),
        log_contents: LogContents {
            scans: log.scans.len(),
            encoder_records: log.encoders.len(),
            wheel_records: match &log.stats.origin {
                odocal_log::Origin::Text => "encoder records".into(),
                origin => origin.records(odocal_log::Stream::Wheels),
            },
            skipped_lines: log.stats.skipped_lines,
            first_skipped: log.stats.first_skipped.clone(),
            unknown_messages: log.stats.unknown.values().sum(),
        },
        health: outcome.health.clone(),
        params: FlatParams::from_array(v),
        sigma: e.sigma,
        covariance: e.covariance,
        range_scale: crate::range_scale::RangeScaleReport::new(&outcome.range_scale, &e),
        j: e.j,
        closed_form: c.closed_form.to_vector(),
        samples_used: e.samples_used,
        samples_synchronized: e.samples_synchronized,
        samples_trimmed: outcome.synced.samples.len().saturating_sub(c.samples_used),
        scan_pairs: outcome.synced.pairs,
        discarded: outcome.synced.discarded.clone(),
        match_rejections: outcome.synced.match_rejections.clone(),
        chained_matches: outcome
            .synced
            .samples
            .iter()
            .filter(|s| s.icp.links > 1)
            .count(),
        neighbour_matches: outcome
            .synced
            .samples
            .iter()
            .filter(|s| s.icp.neighbours > 0)
            .count(),
        free_direction_matches: outcome
            .synced
            .samples
            .iter()
            .filter(|s| !s.icp.fixes_every_direction())
            .count(),
        match_self_check: outcome.synced.match_self_check,
        stride: e.stride,
        interval_s: e.interval_s,
        ticks_per_revolution: outcome.synced.ticks_per_revolution,
        sm_sigma: c.sm_sigma,
        noise_weights: c.noise_source,
        noise_shaping: c.noise_shaping,
        cost_before: c.cost_before,
        cost_after: c.cost_after,
        observability: c.observability.clone(),
        consistency: outcome.consistency.clone(),
        shared_scan_noise: c.shared_scan_noise,
        lateral_slip: c.lateral_slip,
        time_offset_s: outcome.offset.as_ref().map(|o| o.offset),
        time_offset_sigma_s: outcome.offset.as_ref().and_then(|o| o.sigma),
        time_offset_parameter_shift: outcome.offset.as_ref().and_then(|o| o.parameter_shift),
        nominal: opts.initial_params.map(|p| p.to_vector()),
        nominal_laser: None,
        odometry_only: false,
        correction_factors: opts
            .initial_params
            .map(|n| [v[0] / n.r_l, v[1] / n.r_r, v[2] / n.b]),
        checks: vec![two_halves(&outcome.consistency)],
        provenance: None,
        sweep_compensated_s: outcome.synced.sweep_compensated.then(|| {
            log.scans
                .geometries
                .iter()
                .map(|g| g.sweep_duration().abs())
                .fold(0.0, f64::max)
        }),
        settings: Settings {
            trim: opts.solve.trim,
            refine: opts.solve.refine,
            use_profile: opts.use_profile,
            use_icp_covariance: opts.use_icp_covariance,
            first_guess: if opts.initial_params.is_some() {
                "nominal"
            } else if opts.bootstrap_guesses {
                "bootstrap"
            } else {
                "identity"
            },
            second_pass: opts.second_pass,
            matching_range_m: opts.icp_for(log).max_reading,
            matching_range_statement: opts.matching_range_statement(log),
            time_offset_s: opts.time_offset,
            constraints: opts.solve.constraints,
            accept_weak: opts.solve_options().accept_weak,
        },
        timing_s: e.timing_s,
        logs: Vec::new(),
        logs_given: Vec::new(),
        phase_correlation: Vec::new(),
        lasers: Vec::new(),
    }
}

impl Report {
    /// The estimate as `[r_L, r_R, b, ℓx, ℓy, ℓθ]`.
    pub fn values(&self) -> [f64; 6] {
        self.params.to_array()
    }
}

/// The summary's line on the sideways slide in turns.
fn slide_line(slip: &LateralSlip) -> String {
    let k = format!(
        "k = {:.3} ± {:.3} s ({:.1}σ; {:.1}° slip angle at 1 rad/s)",
        slip.k,
        slip.sigma,
        slip.significance(),
        slip.slip_angle_deg(1.0)
    );
    if slip.applied && slip.weight < 1.0 {
        format!(
            "sideways slide in turns v_y = −k·v·ω weighed in at {:.0} %: {k}; without it ℓx would be {:+.1} mm off, with it in full {:+.1} mm; the σ above include both and their difference",
            100.0 * slip.weight,
            -1e3 * slip.weight * slip.l_x_shift,
            1e3 * (1.0 - slip.weight) * slip.l_x_shift
        )
    } else if slip.applied {
        format!(
            "sideways slide in turns v_y = −k·v·ω estimated: {k}; without it ℓx would be {:+.1} mm off; the σ above include it",
            -1e3 * slip.l_x_shift
        )
    } else {
        format!("sideways slide in turns checked, not estimated: {k}")
    }
}

impl fmt::Display for Report {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "odocal calibration of {}", self.log)?;
        let c = &self.log_contents;
        writeln!(
            f,
            "  {} scans, {} {}",
            c.scans, c.encoder_records, c.wheel_records
        )?;
        if c.skipped_lines > 0 {
            let lines: Vec<String> = c.first_skipped.iter().map(|(l, _)| l.to_string()).collect();
            writeln!(
                f,
                "  warning: {} malformed line(s) skipped (first: {})",
                c.skipped_lines,
                lines.join(", ")
            )?;
        }
        for finding in &self.health {
            writeln!(f, "  {finding}")?;
        }
        writeln!(f)?;
        let v = self.values();
        for i in 0..6 {
            let verdict = self
                .observability
                .parameters
                .get(i)
                .map(|p| match p.constraint {
                    Constraint::Free => p.verdict.as_str().to_string(),
                    Constraint::Held(_) => "held (--fix)".to_string(),
                    Constraint::Prior { mean, sigma } => {
                        format!("{} (prior {mean} ± {sigma})", p.verdict.as_str())
                    }
                })
                .unwrap_or_default();
            if i == 5 && self.range_scale.sigma_from_scale[5] > 0.0 {
                // Parameters held or with priors: the range scale moves ℓθ a little.
                writeln!(
                    f,
                    "  {:<8} = {:>+12.6} rad {}  ({:+.3}° ± {:.3}°)  {}",
                    PARAMETER_NAMES[i],
                    v[i],
                    self.range_scale.sigma_words(i, self.sigma[i], 1e3, "mrad"),
                    v[i].to_degrees(),
                    self.range_scale.sigma_total[i].to_degrees(),
                    verdict
                )?;
            } else if i == 5 {
                writeln!(
                    f,
                    "  {:<8} = {:>+12.6} rad ± {:.6} rad  ({:+.3}° ± {:.3}°)  {}",
                    PARAMETER_NAMES[i],
                    v[i],
                    self.sigma[i],
                    v[i].to_degrees(),
                    self.sigma[i].to_degrees(),
                    verdict
                )?;
            } else {
                writeln!(
                    f,
                    "  {:<8} = {:>+12.4} mm  {}  {}",
                    PARAMETER_NAMES[i],
                    v[i] * 1e3,
                    self.range_scale.sigma_words(i, self.sigma[i], 1e3, "mm"),
                    verdict
                )?;
            }
        }
        writeln!(f)?;
        writeln!(
            f,
            "  J = [[{:+.6e}, {:+.6e}], [{:+.6e}, {:+.6e}]]",
            self.j[0][0], self.j[0][1], self.j[1][0], self.j[1][1]
        )?;
        writeln!(f)?;
        writeln!(
            f,
            "  samples: {} used of {} synchronized ({} trimmed as outliers); {} scan pairs, stride {} (≈{:.2} s)",
            self.samples_used,
            self.samples_synchronized,
            self.samples_trimmed,
            self.scan_pairs,
            self.stride,
            self.interval_s
        )?;
        let d: Vec<String> = self
            .discarded
            .0
            .iter()
            .map(|(k, n)| format!("{} {n}", k.replace('_', " ")))
            .collect();
        writeln!(f, "  discarded pairs: {}", d.join(", "))?;
        if let Some((reason, n)) = self.match_rejections.most_common() {
            let r: Vec<String> = self
                .match_rejections
                .0
                .iter()
                .filter(|(_, n)| **n > 0)
                .map(|(k, n)| format!("{k} {n}"))
                .collect();
            writeln!(f, "  scan matches refused: {}", r.join(", "))?;
            writeln!(
                f,
                "    most often {} ({n}): {}",
                reason.key(),
                reason.advice()
            )?;
        }
        if self.chained_matches > 0 {
            writeln!(
                f,
                "  matched through the scans between: {} pairs refused when matched directly (ŝ composed of 2 to 4 shorter matches)",
                self.chained_matches
            )?;
        }
        if self.neighbour_matches > 0 {
            writeln!(
                f,
                "  matched with their neighbouring scans: {} pairs of sparse scans refused when matched alone (each scan densified by the scan beyond it, or the {} beyond it when it has few returns, placed by odometry)",
                self.neighbour_matches,
                odocal_pipeline::local_map::MAX_NEIGHBOURS
            )?;
        }
        if self.free_direction_matches > 0 {
            writeln!(
                f,
                "  matched along a corridor: {} pairs of sparse scans fix the rotation and the displacement across the walls only (along them ŝ keeps odometry's guess, which gets no weight)",
                self.free_direction_matches
            )?;
        }
        if let Some(c) = &self.match_self_check {
            let ratio = if c.range_noise_m > 0.0 {
                format!(", {:.1}× the laser's range noise", c.xy_m / c.range_noise_m)
            } else {
                String::new()
            };
            writeln!(
                f,
                "  scan matching on this log: {:.2} mm / {:.3}° per pair{ratio} (closure of {} scan triples{}: a lower bound, errors shared between matches of one scan do not show)",
                c.xy_m * 1e3,
                c.theta_rad.to_degrees(),
                c.triples,
                match c.left_out {
                    0 => String::new(),
                    n => format!(", {n} more left out as outliers, as the solver leaves out samples"),
                }
            )?;
        }
        writeln!(
            f,
            "  scan-matching noise σ: x {:.3} mm, y {:.3} mm, θ {:.4}°{}",
            self.sm_sigma[0] * 1e3,
            self.sm_sigma[1] * 1e3,
            self.sm_sigma[2].to_degrees(),
            match self.noise_weights {
                NoiseSource::Shaped | NoiseSource::Estimated => "",
                NoiseSource::SampleCovariance => " (each sample weighted by its own covariance)",
            }
        )?;
        if let Some(n) = &self.noise_shaping {
            writeln!(
                f,
                "  each sample weighted by the typical match's σ (x {:.3} mm, y {:.3} mm, θ \
                 {:.4}°) shaped as the matcher's covariance of it compares with the typical \
                 match's; the residuals follow the spread in the matches' sizes by {:.0} %, \
                 and the σ take each match's noise at that blend of its size with the \
                 typical one, its shape kept",
                n.weight_level[0] * 1e3,
                n.weight_level[1] * 1e3,
                n.weight_level[2].to_degrees(),
                100.0 * n.share
            )?;
        }
        if let Some(n) = &self.shared_scan_noise {
            writeln!(
                f,
                "  shared by consecutive samples through their common scan: {:.0} %, {:.0} %, {:.0} % \
                 of it (x, y, θ; {} shared scans), accounted for in the σ above",
                100.0 * n.shared_fraction[0],
                100.0 * n.shared_fraction[1],
                100.0 * n.shared_fraction[2],
                n.shared_scans
            )?;
        }
        if let Some(slip) = &self.lateral_slip {
            writeln!(f, "  {}", slide_line(slip))?;
        }
        writeln!(
            f,
            "  cost: {:.4e} (closed form) → {:.4e}",
            self.cost_before, self.cost_after
        )?;
        let o = &self.observability;
        writeln!(
            f,
            "  observability: step-1 condition {:.1}, A condition {:.3e}; {}",
            o.step1_condition, o.a_condition, o.sentence
        )?;
        if let Some(w) = &o.wheel_signs {
            writeln!(f, "  warning: {w}")?;
        }
        writeln!(f, "  laser range scale: {}", self.range_scale.statement)?;
        if let Some(m) = &self.settings.matching_range_statement {
            writeln!(f, "  scan matching used {m}")?;
        }
        if let Some(t) = self.sweep_compensated_s {
            writeln!(
                f,
                "  sweep: {:.1} ms per scan, compensated (rays moved to mid-sweep with the wheel motion)",
                t * 1e3
            )?;
        }
        if let Some(t) = self.time_offset_s {
            let sigma = self
                .time_offset_sigma_s
                .map_or(String::new(), |s| format!(" ± {s:.4} s"));
            let shift = self
                .time_offset_parameter_shift
                .map_or(String::new(), |d| format!("; {}", offset_shift_words(&d)));
            writeln!(
                f,
                "  clock offset (laser clock − encoder clock): {t:+.4} s{sigma}{shift}"
            )?;
        }
        if let Some(c) = self.correction_factors {
            writeln!(
                f,
                "  correction factors (calibrated / nominal): r_L ×{:.6}, r_R ×{:.6}, b ×{:.6}",
                c[0], c[1], c[2]
            )?;
        }
        if !self.logs.is_empty() {
            crate::joint::write_log_table(
                f,
                "per log (own estimate; share of the information on b and ℓθ):",
                &self.logs,
            )?;
        }
        if !self.logs_given.is_empty() {
            crate::joint::write_log_table(
                f,
                "per log given, its phases together (share of the information on b and ℓθ):",
                &self.logs_given,
            )?;
        }
        if !self.lasers.is_empty() {
            crate::joint::write_laser_table(f, &self.lasers)?;
        }
        for finding in &self.checks {
            writeln!(f, "  {finding}")?;
        }
        let t = &self.timing_s;
        writeln!(
            f,
            "  timing: parse {:.2} s, sync {:.3} s, match {:.2} s, clock offset {:.2} s, solve {:.3} s",
            t.parse, t.sync, t.r#match, t.time_offset, t.solve
        )
    }
}

/// The parameters' move per σ of the clock offset in words, as the σ above include it.
fn offset_shift_words(shift: &[f64; 6]) -> String {
    let moves = PARAMETER_NAMES
        .iter()
        .zip(shift)
        .map(|(name, d)| {
            if *name == "l_theta" {
                format!("{name} {:.3}°", d.abs().to_degrees())
            } else {
                format!("{name} {:.2} mm", 1e3 * d.abs())
            }
        })
        .collect::<Vec<_>>()
        .join(", ");
    format!("an offset one σ away moves the estimate by {moves} (included in the σ above)")
}
