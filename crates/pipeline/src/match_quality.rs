//! The scan matcher's self-measured error ([`crate::self_check`]) put to use: in σ,
//! and in the verdicts.
//!
//! **σ.** The solver weighs the samples with the scatter of their residuals
//! `ŝ_pred − ŝ` (`sm_sigma`, the scan-matching noise of its model), which holds the
//! scan matcher's error and the odometry's: one match's error, measured by the closure
//! of scan triples, can be at most that. On clean simulated logs it is 0.2–0.5× of it
//! (Khepera, TurtleBot, Pioneer, seeds 1–5), on the real MinesRover logs 0.25–0.55×.
//! When it is larger on some axis, beyond the self-check's own sampling error (its
//! standard error `1/√triples` on the ratio), the residuals do not show all of the
//! matcher's error (part of it is absorbed by the parameters), and the σ, which scale
//! with the noise level, are multiplied by the largest ratio over the axes
//! (translation per axis against the mean of x and y; rotation against θ), weighed by
//! the evidence that it exceeds 1 ([`sigma_inflation`]). The closure is a lower bound
//! (matches of one scan share errors), so the check can only say that the model is
//! too small, never that it is too large. (Against the model's part not shared
//! through scans, `SharedScanNoise::per_sample`, which the closure measures more
//! directly, the ratio is 0.4–1.0 on the clean presets but up to 3.6 on a 30-second
//! log whose split between shared and own noise is poorly estimated: too noisy a
//! reference.)
//!
//! **Verdicts.** A parameter is determined from the motion in the pairs; when one
//! match's error is a sizeable share of that motion — the rotation error against the
//! rotation per pair (b, and the radii through it), the translation error against the
//! translation per pair (the radii's scale, ℓ through its lever arm and heading) — no
//! σ makes the estimate trustworthy (errors of that size are rarely independent and
//! unbiased), so those parameters are not "well determined", and the summary, the
//! verdict and the refusal say so with the figures and the way out: pairs further
//! apart (a larger stride) hold more motion for the same matching error.

use crate::samples::PairSample;
use crate::self_check::MatchSelfCheck;

/// One match's error above this share of the motion per pair (RMS) leaves the
/// parameters determined from that motion "weak". Measured shares (translation,
/// rotation): 0.4 %, 0.1 % on a 10-minute Khepera log; 3.2 %, 2.2 % and 1.5 %, 1.8 %
/// on the two real MinesRover logs (7 mm / 0.24° per pair at 0.6 m/s). 5-minute
/// Khepera logs with 2 and 3 cm of range noise: 13 % and 18 %, where the radii came
/// out 4.4σ and b 3.1–3.6σ off the truth, all "well determined" (at stride 8 and 16
/// the 2 cm log's shares are 6.5 % and 3.4 %, the radii 2.5σ and 2σ off: the bias
/// shrinks with the share but is not gone). A 30-second Khepera log with 2 cm of
/// noise, 10 %, has its radii within 4σ (σ are larger on short logs): the threshold
/// lies between, a compromise, not a law.
pub const COMPARABLE_SHARE: f64 = 0.12;

/// The factor by which the σ are multiplied: the largest ratio `q` of one match's
/// error (the self-check) to the solver's scan-matching noise `sm_sigma` (x, y, θ)
/// over the axes, weighed by the evidence that it exceeds 1 — `1 + w·(q − 1)`, `w` 0
/// while `q` is within one standard error of the self-check (`1/√triples`) of 1, 1
/// from three, linear between — so that the σ do not jump where `q` crosses a
/// threshold (a switch at two standard errors multiplied them by 1 or by 1.26 on
/// either side of it with 60 triples; the sideways slide is weighed the same way).
pub fn sigma_inflation(check: &MatchSelfCheck, sm_sigma: [f64; 3]) -> f64 {
    let model_xy = (0.5 * (sm_sigma[0].powi(2) + sm_sigma[1].powi(2))).sqrt();
    let ratio = |measured: f64, model: f64| {
        if model > 0.0 && (measured / model).is_finite() {
            measured / model
        } else {
            1.0
        }
    };
    let largest = ratio(check.xy_m, model_xy).max(ratio(check.theta_rad, sm_sigma[2]));
    let standard_error = 1.0 / (check.triples.max(1) as f64).sqrt();
    let evidence = (largest - 1.0) / standard_error;
    let weight = ((evidence - EVIDENCE_NONE) / (EVIDENCE_FULL - EVIDENCE_NONE)).clamp(0.0, 1.0);
    1.0 + weight * (largest - 1.0).max(0.0)
}

/// Standard errors of the self-check by which its ratio must exceed 1 for the σ to
/// grow at all …
const EVIDENCE_NONE: f64 = 1.0;
/// … and to grow by the full ratio.
const EVIDENCE_FULL: f64 = 3.0;

/// Scales `calibration`'s σ by the matcher's own error (`check`, when the log had
/// enough scan triples): [`sigma_inflation`] against its scan-matching noise. Returns
/// the factor (1 without a check or below the tolerance).
pub(crate) fn scale_by_self_check(
    calibration: &mut odocal_solver::Calibration,
    check: Option<&MatchSelfCheck>,
) -> f64 {
    let Some(check) = check else { return 1.0 };
    let factor = sigma_inflation(check, calibration.sm_sigma);
    odocal_solver::inflate_sigma(calibration, factor);
    factor
}

/// The motion per pair the parameters are determined from: RMS over the samples.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MotionPerPair {
    /// Rotation (rad).
    pub rotation_rad: f64,
    /// Translation of the laser (m).
    pub translation_m: f64,
}

impl MotionPerPair {
    /// From the scan matcher's ŝ of every sample; `None` without samples.
    pub fn of(samples: &[PairSample]) -> Option<Self> {
        if samples.is_empty() {
            return None;
        }
        let n = samples.len() as f64;
        let (mut rot, mut trans) = (0.0, 0.0);
        for s in samples {
            let p = &s.icp.pose;
            rot += p.theta * p.theta;
            trans += p.x * p.x + p.y * p.y;
        }
        Some(MotionPerPair {
            rotation_rad: (rot / n).sqrt(),
            translation_m: (trans / n).sqrt(),
        })
    }
}

/// Scan matching too poor for the motion in the pairs: the parameters it leaves
/// weak, and the sentence saying so.
#[derive(Debug, Clone, PartialEq)]
pub struct PoorMatching {
    /// Indices (r_L, r_R, b, ℓx, ℓy, ℓθ = 0 … 5) of the parameters it leaves weak.
    pub parameters: Vec<usize>,
    /// "scan matching on this log: … per pair, …× the laser's range noise, …% of the
    /// rotation per pair …; pair scans further apart: `--stride K`".
    pub statement: String,
}

/// Judges the self-check against the motion per pair of `samples` (matched with
/// scans `stride` apart); `None` when the matching is good enough for every
/// parameter.
pub fn judge(
    check: &MatchSelfCheck,
    samples: &[PairSample],
    stride: usize,
) -> Option<PoorMatching> {
    let motion = MotionPerPair::of(samples)?;
    let share = |err: f64, signal: f64| {
        if signal > 0.0 {
            err / signal
        } else {
            f64::INFINITY
        }
    };
    let rotation = share(check.theta_rad, motion.rotation_rad);
    let translation = share(check.xy_m, motion.translation_m);
    let mut parameters = Vec::new();
    let mut against = Vec::new();
    if rotation > COMPARABLE_SHARE {
        parameters.extend([0, 1, 2]);
        against.push(format!(
            "{:.0} % of the rotation per pair ({:.2}° RMS), which determines b",
            100.0 * rotation.min(99.0),
            motion.rotation_rad.to_degrees()
        ));
    }
    if translation > COMPARABLE_SHARE {
        parameters.extend([0, 1, 3, 4, 5]);
        against.push(format!(
            "{:.0} % of the translation per pair ({:.1} mm RMS), which determines the \
             radii's scale and the laser's pose",
            100.0 * translation.min(99.0),
            motion.translation_m * 1e3
        ));
    }
    if parameters.is_empty() {
        return None;
    }
    parameters.sort_unstable();
    parameters.dedup();
    Some(PoorMatching {
        parameters,
        statement: format!(
            "{}: {}; pair scans further apart so that each pair holds more motion \
             (`--stride {}`), or match better scans",
            describe(check),
            against.join(", and "),
            2 * stride.max(1)
        ),
    })
}

/// "scan matching on this log: 7.1 mm / 0.35° per pair, 9× the laser's range noise".
pub fn describe(check: &MatchSelfCheck) -> String {
    let ratio = if check.range_noise_m > 0.0 {
        format!(
            ", {:.1}× the laser's range noise",
            check.xy_m / check.range_noise_m
        )
    } else {
        String::new()
    };
    format!(
        "scan matching on this log: {:.2} mm / {:.3}° per pair{ratio}",
        check.xy_m * 1e3,
        check.theta_rad.to_degrees()
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check(xy_m: f64, theta_rad: f64) -> MatchSelfCheck {
        MatchSelfCheck {
            triples: 60,
            tried: 60,
            left_out: 0,
            xy_m,
            theta_rad,
            range_noise_m: 0.001,
            ray_spacing_rad: 0.006,
            tilt_sigma_rad: None,
            sigma_factor: 1.0,
        }
    }

    #[test]
    fn sigma_grows_only_when_the_matcher_clearly_exceeds_the_model() {
        let model = [0.004, 0.002, 0.01];
        // Below the model on every axis: unchanged.
        assert_eq!(sigma_inflation(&check(0.001, 0.005), model), 1.0);
        // Within one standard error of 60 triples (1 + 1/√60 = 1.13): unchanged.
        assert_eq!(sigma_inflation(&check(0.001, 0.0112), model), 1.0);
        // Between one and three: part of the ratio, growing with it without a jump.
        let se = 1.0 / 60f64.sqrt();
        let at = |q: f64| sigma_inflation(&check(0.001, 0.01 * q), model);
        assert!((at(1.0 + 2.0 * se) - (1.0 + se)).abs() < 1e-12);
        let steps: Vec<f64> = (0..=40).map(|i| at(1.0 + 0.1 * se * i as f64)).collect();
        for w in steps.windows(2) {
            assert!(w[1] >= w[0] && w[1] - w[0] < 0.05, "{steps:?}");
        }
        // From three standard errors on: the full ratio.
        assert!((at(1.0 + 3.0 * se) - (1.0 + 3.0 * se)).abs() < 1e-12);
        // Translation 2× the RMS of the x and y model (√((16+4)/2) mm = 3.16 mm).
        let k = sigma_inflation(&check(2.0 * 10f64.sqrt() * 1e-3, 0.005), model);
        assert!((k - 2.0).abs() < 1e-12, "{k}");
        // Rotation 3× the model wins.
        assert!((sigma_inflation(&check(0.001, 0.03), model) - 3.0).abs() < 1e-12);
        // A model of zero says nothing.
        assert_eq!(sigma_inflation(&check(0.001, 0.03), [0.0; 3]), 1.0);
    }

    #[test]
    fn statement_names_the_figures_and_the_way_out() {
        let c = check(0.0071, 0.35f64.to_radians());
        let text = describe(&c);
        assert_eq!(
            text,
            "scan matching on this log: 7.10 mm / 0.350° per pair, 7.1× the laser's range noise"
        );
    }
}
