//! The solve stage for skid-steer robots: does the robot slide sideways in its turns
//! (`v_y = −k·v·ω`, see [`odocal_solver::fit_lateral_slip`]), and if so, the seven-
//! parameter estimate instead of the six-parameter one.
//!
//! The check is the seven-parameter fit itself: `k` with its σ, from the lateral
//! residuals' dependence on the slide's predicted displacement (the same turn driven
//! faster slides more), the six parameters re-fitted with it. It fires when `k` is
//! outward (`k > 0`, what a skid-steer robot's wheels do), likely (above
//! [`PRECAUTION`] σ; above [`SIGNIFICANCE`] σ the finding says the robot slides) and matters (it moves some parameter — ℓx in most logs, ℓθ
//! where the arcs are what fix the heading — by more than its own σ); then the
//! estimate includes it and a finding says so. An outward `k` too uncertain to be
//! sure of that would still move a parameter by more than its σ gets a note naming
//! `--lateral-slip`; an inward `k` as significant is no slide a robot does: named,
//! not used.

use crate::finding::{Finding, FindingKind};
use odocal_solver::{fit_lateral_slip, Calibration, LateralSlip, Sample, SolveOptions};
use serde::Serialize;

/// `|k| / σ` above which the slide counts as found: the robot slides.
pub const SIGNIFICANCE: f64 = 4.0;

/// `|k| / σ` above which an outward slide that matters is estimated all the same, as
/// a precaution: estimating a slide that is not there costs only σ (the estimate of
/// the six stays unbiased), ignoring one that is there biases them. On the simulated
/// MinesRover (truth k = 0.05 s, 12 seeds × 120 s) estimating from 2σ instead of 4σ
/// took the RMS error/σ of ℓx from 1.26 to 1.04 and of ℓθ from 1.91 to 1.44; no
/// TurtleBot 4 log (no slide, 12 seeds, |k|/σ at most 0.9) estimated it.
pub const PRECAUTION: f64 = 2.0;

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
/// `covariance` (the six-parameter estimate's); the parameter and by how many σ.
fn matters(slip: &LateralSlip, covariance: &[[f64; 6]; 6]) -> Option<(usize, f64)> {
    slip.largest_shift(covariance).filter(|(_, n)| *n > 1.0)
}

/// Whether a checked slide is one to estimate: outward, above [`PRECAUTION`] σ, and
/// moving some parameter by more than its σ without it.
fn found(slip: &LateralSlip, covariance: &[[f64; 6]; 6]) -> bool {
    slip.k > 0.0 && slip.significance() > PRECAUTION && matters(slip, covariance).is_some()
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

/// Checks `calibration` (computed from `samples` with `options`) for the slide and,
/// as `model` says, replaces its estimate by the one with the slide. The slide is
/// recorded in `calibration.lateral_slip` whenever it was checked.
pub fn check_and_apply(
    calibration: &mut Calibration,
    samples: &[Sample],
    options: &SolveOptions,
    model: SlideModel,
) {
    if model == SlideModel::Off {
        return;
    }
    let Some(fit) = fit_lateral_slip(samples, calibration, options) else {
        return;
    };
    if model == SlideModel::Estimate || found(&fit.slip, &calibration.covariance) {
        fit.apply(calibration);
    } else {
        calibration.lateral_slip = Some(fit.slip);
    }
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
    if slip.applied {
        let why = match model {
            SlideModel::Estimate => "estimated as asked (`--lateral-slip`)",
            _ if slip.significance() > SIGNIFICANCE => {
                "estimated as a seventh parameter (`--no-lateral-slip` leaves it out)"
            }
            _ => {
                "estimated as a seventh parameter as a precaution, since ignoring a slide \
                 that is there would bias the parameters while estimating one that is not \
                 only widens σ (`--no-lateral-slip` leaves it out)"
            }
        };
        let what = if slip.k > 0.0 && slip.significance() > SIGNIFICANCE {
            "the robot slides sideways in turns"
        } else if slip.k > 0.0 && slip.significance() > PRECAUTION {
            "the robot likely slides sideways in turns"
        } else {
            "sideways slide in turns"
        };
        return Some(Finding::warning(
            FindingKind::LateralSlip,
            format!(
                "{what}: {numbers}; {shift}; {why}: the σ of every parameter include \
                 not knowing k"
            ),
        ));
    }
    let moved = matters(slip, &calibration.covariance);
    if let (true, Some((i, n))) = (slip.k > 0.0, moved) {
        // Too uncertain to estimate, but it would matter: a skid-steer robot's user
        // should know what the slide would do to the parameters.
        let also = if i == 3 {
            String::new()
        } else {
            format!(" (ℓx by {:+.1} mm)", -1e3 * slip.l_x_shift)
        };
        return Some(Finding::note(
            FindingKind::LateralSlip,
            format!(
                "a sideways slide in turns is not excluded: {numbers}, {:.1}σ, too little \
                 to be sure; if the robot slides (a skid-steer robot does), ignoring it moves \
                 {}{also}: `--lateral-slip` estimates the slide with the six parameters",
                slip.significance(),
                shift_words(slip, i, n)
            ),
        ));
    }
    (slip.significance() > SIGNIFICANCE && slip.k < 0.0).then(|| {
        Finding::warning(
            FindingKind::LateralSlip,
            format!(
                "the lateral residuals grow with v·ω inward of the turns ({numbers}): no \
                 wheel slides that way, so it is not estimated; {shift}, likely from \
                 another cause (laser timing, a mis-scaled range); `--lateral-slip` \
                 estimates it anyway"
            ),
        )
    })
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
        }
    }

    #[test]
    fn a_slide_asked_for_that_the_data_cannot_give_is_said() {
        use odocal_geom::Pose2;
        use odocal_solver::{calibrate, Params, Predictor};
        let truth = Params {
            r_l: 0.03,
            r_r: 0.031,
            b: 0.3,
            laser: Pose2::new(0.1, 0.02, 1.0),
        };
        let predictor = Predictor::new(&truth, true);
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
    fn only_an_outward_significant_slide_that_moves_a_parameter_is_found() {
        // σ: 1 mm for the distances, 2 mrad for ℓθ.
        let mut cov = [[0.0; 6]; 6];
        for (i, row) in cov.iter_mut().enumerate() {
            row[i] = if i == 5 { 4e-6 } else { 1e-6 };
        }
        assert!(found(&slip(0.05, 0.01, 0.005), &cov));
        // Inward: no wheel slides that way.
        assert!(!found(&slip(-0.05, 0.01, -0.005), &cov));
        // Below 4σ but above 2σ: estimated as a precaution; below 2σ: not.
        assert!(found(&slip(0.035, 0.01, 0.005), &cov));
        assert!(!found(&slip(0.015, 0.01, 0.005), &cov));
        // Significant but moving ℓx by less than its σ, and nothing else.
        assert!(!found(&slip(0.05, 0.01, 0.0005), &cov));
        // ℓx barely, ℓθ by 3σ: found (the rover's heading in its arcs).
        let mut s = slip(0.05, 0.01, 0.0005);
        s.shifts[5] = 0.006;
        assert!(found(&s, &cov));
        assert_eq!(matters(&s, &cov).map(|(i, _)| i), Some(5));
        // A held parameter (zero variance) does not count.
        let mut held = cov;
        held[5][5] = 0.0;
        assert!(!found(&s, &held));
    }
}
