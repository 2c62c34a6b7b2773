//! The solve stage for skid-steer robots: does the robot slide sideways in its turns
//! (`v_y = −k·v·ω`, see [`odocal_solver::fit_lateral_slip`]), and if so, the seven-
//! parameter estimate instead of the six-parameter one.
//!
//! The check is the seven-parameter fit itself: `k` with its σ, from the lateral
//! residuals' dependence on the slide's predicted displacement (the same turn driven
//! faster slides more), the six parameters re-fitted with it. The estimate weighs the
//! two models by the evidence for an outward slide ([`slide_weight`]: `k > 0`, what a
//! skid-steer robot's wheels do; even odds at [`PRECAUTION`] σ, all but certain from
//! [`SIGNIFICANCE`] σ), and its covariance holds both models and the difference
//! between them, so that neither moves by a jump when `k` crosses a threshold. A
//! finding says so when the slide carries weight or would move a parameter by more
//! than its σ in full; an inward `k` as significant is no slide a robot does: named,
//! not used.

use crate::finding::{Finding, FindingKind};
use odocal_solver::{fit_lateral_slip, Calibration, LateralSlip, Sample, SolveOptions};
use serde::Serialize;

/// `|k| / σ` above which the slide counts as found: the robot slides.
pub const SIGNIFICANCE: f64 = 4.0;

/// `|k| / σ` at which an outward slide weighs as much as no slide in the estimate
/// ([`slide_weight`]), as a precaution: estimating a slide that is not there costs
/// only σ (the estimate of the six stays unbiased), ignoring one that is there
/// biases them. Before the weighing (stop 43) the slide was estimated in full from
/// here: on the simulated MinesRover (truth k = 0.05 s, 12 seeds × 120 s) that from
/// 2σ instead of 4σ took the RMS error/σ of ℓx from 1.26 to 1.04 and of ℓθ from 1.91
/// to 1.44; no TurtleBot 4 log (no slide, 12 seeds, |k|/σ at most 0.9) estimated it.
pub const PRECAUTION: f64 = 2.0;

/// The share of the model with the slide in the estimate of [`SlideModel::Auto`]:
/// 0 for an inward or zero `k`, rising smoothly with the evidence for an outward
/// one. It is the probability of the model with the slide against the one without
/// when the slide's likelihood gain, `z²/2` for `z = k/σ`, is weighed against a
/// penalty of `PRECAUTION²/2` (even odds at `z` = [`PRECAUTION`]), rescaled so that
/// `k = 0` weighs nothing: 0.06 at 0.9σ, 0.43 at 2σ, 0.91 at 3σ, 0.999 at 4σ.
///
/// A switch at `PRECAUTION` instead made the estimate jump with the samples: the
/// real MinesRover exp2 has `k` at 2.1σ, and redrawing a fifth of its ranges by
/// ±1 mm put it on either side of 2σ, so that ℓx took one of two values 40 mm apart
/// while each value's σ claimed 11–26 mm (`docs/benchmarks.md`, stops 42 and 43). Weighed,
/// the estimate and its covariance move continuously with `k`, and near the
/// threshold the σ hold the difference between the two models.
pub fn slide_weight(slip: &LateralSlip) -> f64 {
    // An inward k, zero or NaN: no slide a robot does.
    if slip.k.is_nan() || slip.k <= 0.0 {
        return 0.0;
    }
    let z = slip.significance();
    if !z.is_finite() {
        return 1.0;
    }
    let probability = |z2: f64| 1.0 / (1.0 + (-(z2 - PRECAUTION * PRECAUTION) / 2.0).exp());
    let at_zero = probability(0.0);
    ((probability(z * z) - at_zero) / (1.0 - at_zero)).clamp(0.0, 1.0)
}

/// Whether the robot of `slip`'s log more likely slides than not: the slide is
/// weighed into its estimate at half or more (from about 2.1σ). A robot that does
/// not slide has an outward `k` on half its logs, weighed in at a few per cent at
/// most; naming it as sliding (say, to refuse a model without the slide) would give
/// a false cause.
pub fn more_likely_than_not(slip: &LateralSlip) -> bool {
    slip.applied && slip.weight >= 0.5
}

/// A weight from which the slide counts as estimated in full in the words (4σ).
const FULL_WEIGHT: f64 = 0.995;

/// Which odometry model the solve uses.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum SlideModel {
    /// Differential drive, unless the check finds the robot sliding sideways in its
    /// turns: then the slide is estimated too (the default).
    #[default]
    Auto,
    /// Always estimate the slide (`--lateral-slip`): a skid-steer robot.
    Estimate,
    /// Never (`--no-lateral-slip`): plain differential drive, no check.
    Off,
}

/// Whether a slide matters: ignoring it moves some parameter by more than its σ in
/// `covariance` (the calibration's); the parameter and by how many σ.
fn matters(slip: &LateralSlip, covariance: &[[f64; 6]; 6]) -> Option<(usize, f64)> {
    slip.largest_shift(covariance).filter(|(_, n)| *n > 1.0)
}

/// Share of a parameter's variance from not knowing `k` above which it is said.
const UNKNOWN_K_SAID: f64 = 0.5;

/// "not knowing k makes up 97 % of ℓx's variance (σ 29.4 mm)": the parameter whose
/// variance in `covariance` (the calibration's) is most not knowing `k`, when that
/// is more than [`UNKNOWN_K_SAID`] of it.
fn unknown_k_words(slip: &LateralSlip, covariance: &[[f64; 6]; 6]) -> Option<String> {
    let share = slip.unknown_k_share(covariance);
    let (i, most) = share
        .iter()
        .copied()
        .enumerate()
        .max_by(|a, b| a.1.total_cmp(&b.1))?;
    (most > UNKNOWN_K_SAID).then(|| {
        let sigma = covariance[i][i].sqrt();
        let sigma = if i == 5 {
            format!("{:.4} rad ({:.2}°)", sigma, sigma.to_degrees())
        } else {
            format!("{:.1} mm", 1e3 * sigma)
        };
        format!(
            "not knowing k makes up {:.0} % of {}'s variance (σ {sigma}): spins in place \
             determine the laser's pose without it; if the wheels cannot slide sideways \
             (differential drive), `--no-lateral-slip` leaves it out",
            100.0 * most,
            odocal_solver::PARAMETER_NAMES[i]
        )
    })
}

/// "ℓθ by −0.0050 rad (−0.29°), 2.2 times its σ": what ignoring the slide does to
/// parameter `i`, moved `n` σ.
fn shift_words(slip: &LateralSlip, i: usize, n: f64) -> String {
    let off = if i == 5 {
        format!(
            "{:+.4} rad ({:+.2}°)",
            -slip.shifts[i],
            -slip.shifts[i].to_degrees()
        )
    } else {
        format!("{:+.1} mm", -1e3 * slip.shifts[i])
    };
    format!(
        "{} by {off}, {n:.1} times its σ",
        odocal_solver::PARAMETER_NAMES[i]
    )
}

/// The least weight of the model with the slide for its noise to be measured on its
/// own residuals ([`odocal_solver::SlideFit::measure_noise_with_slide`]); a clean
/// Khepera's slide weighs 0.03 %.
const MEASURED_WEIGHT: f64 = 0.01;

/// Checks `calibration` (computed from `samples` with `options`) for the slide and,
/// as `model` says, weighs the estimate with the slide into it ([`slide_weight`]).
/// The slide is recorded in `calibration.lateral_slip` whenever it was checked.
pub fn check_and_apply(
    calibration: &mut Calibration,
    samples: &[Sample],
    options: &SolveOptions,
    model: SlideModel,
) {
    if model == SlideModel::Off {
        return;
    }
    let Some(mut fit) = fit_lateral_slip(samples, calibration, options) else {
        return;
    };
    let weight = match model {
        SlideModel::Estimate => 1.0,
        _ => slide_weight(&fit.slip),
    };
    // The model with the slide, where it weighs in, takes its noise from the
    // residuals it leaves (a solve more; below MEASURED_WEIGHT its share of the σ is
    // too small to matter).
    if weight >= MEASURED_WEIGHT {
        fit.measure_noise_with_slide(samples, options);
    }
    fit.blend(calibration, weight);
}

/// The finding for the slide of a calibration, when it was estimated, is
/// significant, would matter, or was asked for and cannot be had; `None` otherwise.
pub fn finding(calibration: &Calibration, model: SlideModel) -> Option<Finding> {
    let Some(slip) = calibration.lateral_slip.as_ref() else {
        // Asked for, but the data cannot give it: said, not left silent.
        return (model == SlideModel::Estimate).then(|| {
            Finding::warning(
                FindingKind::LateralSlip,
                "`--lateral-slip` asked for the sideways slide in turns, but this log \
                 cannot determine it (no turns while translating at different speeds): \
                 the estimate is the six-parameter one; drive the same arcs slowly and \
                 fast",
            )
        });
    };
    let numbers = format!(
        "v_y = −k·v·ω with k = {:.3} ± {:.3} s (a {:.1}° slip angle at 1 rad/s; at the \
         data's typical turn, {:.2} m/s and {:.2} rad/s, {:.0} mm/s sideways)",
        slip.k,
        slip.sigma,
        slip.slip_angle_deg(1.0),
        slip.turning_speed,
        slip.turn_rate,
        1e3 * slip.k * slip.turning_speed * slip.turn_rate,
    );
    let shift = format!("ignoring it moves ℓx by {:+.1} mm", -1e3 * slip.l_x_shift);
    let what = if slip.k > 0.0 && slip.significance() > SIGNIFICANCE {
        "the robot slides sideways in turns"
    } else if slip.k > 0.0 && slip.significance() > PRECAUTION {
        "the robot likely slides sideways in turns"
    } else {
        "sideways slide in turns"
    };
    if slip.applied && slip.weight >= FULL_WEIGHT {
        let why = match model {
            SlideModel::Estimate => "estimated as asked (`--lateral-slip`)",
            _ => "estimated as a seventh parameter (`--no-lateral-slip` leaves it out)",
        };
        return Some(Finding::warning(
            FindingKind::LateralSlip,
            format!(
                "{what}: {numbers}; {shift}; {why}: the σ of every parameter include \
                 not knowing k"
            ),
        ));
    }
    let unknown = unknown_k_words(slip, &calibration.covariance);
    if slip.applied {
        // Weighed: said when it carries weight, would matter in full, or its not
        // being known makes up most of a σ.
        let moved = matters(slip, &calibration.covariance);
        if slip.weight < 0.5 && moved.is_none() && unknown.is_none() {
            return None;
        }
        let also = match moved {
            Some((i, n)) if i != 3 => format!(" and {}", shift_words(slip, i, n)),
            _ => String::new(),
        };
        let message = format!(
            "{what}: {numbers}; {shift}{also}; the estimate weighs the model with the \
             slide at {:.0} % and the one without at {:.0} %, by the evidence for it (k at \
             {:.1}σ of the residuals' noise; even odds at {PRECAUTION}σ, all but certain from \
             {SIGNIFICANCE}σ), and the σ of every parameter include not knowing k and the \
             difference between the models (`--lateral-slip` estimates the slide in full, \
             as a skid-steer robot needs; `--no-lateral-slip` leaves it out){}",
            100.0 * slip.weight,
            100.0 * (1.0 - slip.weight),
            slip.evidence,
            unknown.map_or(String::new(), |u| format!("; {u}")),
        );
        return Some(if slip.weight >= 0.5 {
            Finding::warning(FindingKind::LateralSlip, message)
        } else {
            Finding::note(FindingKind::LateralSlip, message)
        });
    }
    if slip.significance() <= SIGNIFICANCE || slip.k >= 0.0 {
        // Not weighed in (k inward or zero), yet not knowing it may be most of a σ.
        return unknown.map(|u| {
            Finding::note(
                FindingKind::LateralSlip,
                format!(
                    "{what}: {numbers}; the data do not show the slide, nor rule it out: \
                     {u}"
                ),
            )
        });
    }
    // Significant and inward of the turns.
    Some(Finding::warning(
        FindingKind::LateralSlip,
        format!(
            "the lateral residuals grow with v·ω inward of the turns ({numbers}): no \
             wheel slides that way, so it is not estimated; {shift}, likely from another \
             cause (laser timing, a mis-scaled range); `--lateral-slip` estimates it \
             anyway"
        ),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn slip(k: f64, sigma: f64, l_x_shift: f64) -> LateralSlip {
        LateralSlip {
            k,
            sigma,
            covariance_with_params: [0.0; 6],
            l_x_shift,
            shifts: [0.0, 0.0, 0.0, l_x_shift, 0.0, 0.0],
            turning_speed: 0.3,
            turn_rate: 0.5,
            applied: false,
            weight: 0.0,
            evidence: k / sigma,
        }
    }

    /// A robot whose laser is turned by `laser_theta` (rad).
    fn robot(laser_theta: f64) -> odocal_solver::Params {
        odocal_solver::Params {
            r_l: 0.03,
            r_r: 0.031,
            b: 0.3,
            laser: odocal_geom::Pose2::new(0.1, 0.02, laser_theta),
        }
    }

    #[test]
    fn a_slide_asked_for_that_the_data_cannot_give_is_said() {
        use odocal_geom::Pose2;
        use odocal_solver::{calibrate, Predictor};
        let predictor = Predictor::new(&robot(1.0), true);
        let samples: Vec<Sample> = (0..60)
            .map(|k| {
                let (l, r) = [(5.0, 5.0), (-4.0, 4.0), (2.0, 6.0)][k % 3];
                let f = 1.0 + 0.01 * k as f64;
                let s = Sample::from_rotations(0.5, l * f, r * f, Pose2::IDENTITY);
                Sample {
                    sm: Pose2::from_array(predictor.predict(&s)),
                    ..s
                }
            })
            .collect();
        let mut cal = calibrate(&samples, &SolveOptions::default()).unwrap();
        cal.lateral_slip = None;
        let said = finding(&cal, SlideModel::Estimate).expect("a warning");
        assert!(
            said.message.contains("cannot determine it"),
            "{}",
            said.message
        );
        assert!(finding(&cal, SlideModel::Auto).is_none());
    }

    #[test]
    fn the_slide_weighs_as_its_evidence_and_nothing_inward() {
        // k / σ = 0, 0.9, 2, 3, 4; inward.
        let w = |k: f64| slide_weight(&slip(k, 0.01, 0.005));
        assert_eq!(w(0.0), 0.0);
        assert_eq!(w(-0.05), 0.0);
        assert!((w(0.009) - 0.057).abs() < 0.005, "{}", w(0.009));
        assert!((w(0.02) - 0.433).abs() < 0.005, "{}", w(0.02));
        assert!((w(0.03) - 0.914).abs() < 0.005, "{}", w(0.03));
        assert!(w(0.04) > 0.995 && w(0.04) < 1.0, "{}", w(0.04));
        // Rising, without a jump: no step of 0.1σ changes the weight by more than 0.06.
        let mut last = 0.0;
        for i in 1..=100 {
            let now = w(0.0005 * i as f64);
            assert!(now >= last && now - last < 0.06, "{i}: {last} -> {now}");
            last = now;
        }
        // A σ of zero: certain.
        assert_eq!(slide_weight(&slip(0.05, 0.0, 0.005)), 1.0);
    }

    #[test]
    fn a_weighed_slide_moves_the_estimate_in_proportion_and_widens_sigma_by_k_and_the_gap() {
        use odocal_geom::Pose2;
        use odocal_solver::{calibrate, fit_lateral_slip, Predictor};
        let predictor = Predictor::new(&robot(0.1), true);
        // Turns while translating at two speeds, straights and spins, a little noise.
        let samples: Vec<Sample> = (0..120)
            .map(|k| {
                let (l, r) = [(5.0, 5.0), (-4.0, 4.0), (2.0, 6.0), (4.0, 12.0)][k % 4];
                let f = 1.0 + 0.01 * (k % 7) as f64;
                let s = Sample::from_rotations(0.5, l * f, r * f, Pose2::IDENTITY);
                let p = predictor.predict(&s);
                let e = 1e-3 * (((k * 7919) % 13) as f64 - 6.0);
                Sample {
                    sm: Pose2::from_array([p[0] + e, p[1] - 0.7 * e, p[2] + 0.3 * e]),
                    ..s
                }
            })
            .collect();
        let options = SolveOptions::default();
        let six = calibrate(&samples, &options).unwrap();
        let fit = fit_lateral_slip(&samples, &six, &options).expect("a fit");
        let (d, c7) = (fit.slip.shifts, fit.covariance);
        for w in [0.0, 0.3, 0.5, 1.0] {
            let mut cal = six.clone();
            fit.clone().blend(&mut cal, w);
            let (got, base) = (cal.params.to_vector(), six.params.to_vector());
            for i in 0..6 {
                assert!((got[i] - (base[i] + w * d[i])).abs() < 1e-12, "w {w}, {i}");
                // Not knowing k: in full with the slide (C₇), as far as a plausible
                // slide goes without it (C₀); and the gap between the models.
                let share = fit.slip.plausible_share();
                let c0 = six.covariance[i][i] + share * (c7[i][i] - six.covariance[i][i]);
                let want = (1.0 - w) * c0 + w * c7[i][i] + w * (1.0 - w) * d[i] * d[i];
                assert!(want >= six.covariance[i][i], "w {w}, {i}");
                assert!(
                    (cal.covariance[i][i] - want).abs() <= 1e-12 * want.abs().max(1e-30),
                    "w {w}, {i}"
                );
            }
            let slip = cal.lateral_slip.expect("recorded");
            assert_eq!(slip.applied, w > 0.0);
            assert_eq!(slip.weight, w);
        }
        // In full, exactly the joint estimate.
        let mut cal = six.clone();
        fit.clone().apply(&mut cal);
        assert_eq!(cal.params, fit.params);
        assert_eq!(cal.covariance, fit.covariance);
    }

    /// A slide the data neither show nor rule out, that makes up most of a σ, is said
    /// (with what to do); one the data rule out is not.
    #[test]
    fn a_slide_the_data_cannot_rule_out_is_said_when_it_makes_up_a_sigma() {
        // As the blend leaves it: ℓx's variance with k known (σ 5 mm) and what not
        // knowing k adds, as far as a plausible slide at 0.44 m/s goes.
        let calibration = |k: f64, sigma_k: f64, cross: f64| {
            let slip = LateralSlip {
                covariance_with_params: [0.0, 0.0, 0.0, cross, 0.0, 0.0],
                turning_speed: 0.44,
                ..slip(k, sigma_k, -0.025)
            };
            let mut cov = [[0.0; 6]; 6];
            for (i, row) in cov.iter_mut().enumerate() {
                row[i] = 1e-8;
            }
            cov[3][3] = 2.5e-5 + slip.plausible_share() * cross * cross / (sigma_k * sigma_k);
            (slip, cov)
        };
        // k = 0 ± 0.064 s, ℓx's covariance with k 1.84e-3: not knowing k is 8.3e-4 m²
        // with k free, 65 % of it kept (τ = 0.088 s): 96 % of ℓx's variance.
        let (slip, cov) = calibration(0.0, 0.064, 1.84e-3);
        let words = unknown_k_words(&slip, &cov).expect("said");
        assert!(words.contains("96 % of l_x's variance"), "{words}");
        assert!(words.contains("--no-lateral-slip"), "{words}");
        // k = 0 ± 0.005 s: the data rule a plausible slide out.
        let (slip, cov) = calibration(0.0, 0.005, 1e-6);
        assert_eq!(unknown_k_words(&slip, &cov), None);
    }
}
