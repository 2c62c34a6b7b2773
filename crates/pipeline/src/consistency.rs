//! The two-halves check: the samples of the first and the second half of the log
//! are calibrated separately, and their difference is compared with its covariance
//! (the sum of the halves' covariances: they share no sample). Halves that differ
//! by more than 3σ show that something the model does not include changed during
//! the log or acts unevenly on it (an unmodelled sweep, a clock offset, wheel slip,
//! a sensor mounting that moved), even when each half, and the whole, look fine.

use crate::lateral_slip::{check_and_apply, SlideModel};
use crate::match_quality::scale_by_self_check;
use crate::self_check::MatchSelfCheck;
use nalgebra::DMatrix;
use odocal_solver::{
    calibrate, Calibration, Constraint, Sample, SolveOptions, Verdict, PARAMETER_NAMES,
};
use serde::Serialize;

/// 99.73 % quantiles of χ² with 1 … 6 degrees of freedom (the "3σ" level).
const CHI2_3SIGMA: [f64; 6] = [9.0, 11.83, 14.16, 16.25, 18.21, 20.06];

/// |difference| / σ above which a parameter counts as disagreeing.
pub const Z_LIMIT: f64 = 3.0;

/// The result of the check.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Consistency {
    /// Both halves were calibrated.
    Checked(Box<HalvesCheck>),
    /// A half could not be calibrated (too few samples, not excited, …).
    NotAvailable {
        /// Why, in words.
        reason: String,
    },
}

/// Both halves' estimates and how far apart they are.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct HalvesCheck {
    /// Samples used by each half's calibration.
    pub samples_used: [usize; 2],
    /// First half's estimate minus the second's (r_L, r_R, b, ℓx, ℓy, ℓθ).
    pub difference: [f64; 6],
    /// Standard deviation of the difference (0 for held parameters).
    pub sigma: [f64; 6],
    /// Difference in σ (0 for held parameters).
    pub z: [f64; 6],
    /// `dᵀ (C₁ + C₂)⁻¹ d` over the parameters not held.
    pub chi2: f64,
    /// Its degrees of freedom (parameters not held).
    pub dof: usize,
    /// The 3σ (99.73 %) level of χ² with `dof` degrees of freedom.
    pub chi2_limit: f64,
    /// Parameters whose halves differ by more than [`Z_LIMIT`] σ.
    pub disagreeing: Vec<String>,
    /// Whether the halves agree (χ² and every parameter within 3σ).
    pub agree: bool,
    /// In words; when they disagree, the parameters and the likely causes.
    pub sentence: String,
}

/// Calibrates the first and the second half of `samples` (in time order) with
/// `options` (weak halves still give numbers) and compares them. Each half is
/// checked for a sideways slide in turns and weighs it in as `slide` says, as the
/// log is ([`crate::lateral_slip::check_and_apply`]): solved without it, the halves
/// of a robot that slides are each biased by their own turns (60 simulated 120 s
/// MinesRover logs, k = 0.05 s: 8 disagreed beyond 3σ, their differences in ℓx and
/// ℓθ 1.67σ and 1.51σ RMS; with the slide weighed in, 1 disagreed, at 0.79σ and
/// 0.74σ, while the whole logs' estimates were within 1.08σ and 0.62σ). Each half's σ are
/// scaled by the matcher's own error `self_check` (the log's, when it had enough
/// scan triples) as the log's σ are ([`crate::match_quality::sigma_inflation`]
/// against the half's scan-matching noise): without it, a log whose matches err more
/// than their residuals show had its halves judged by σ known to be too small (20 %
/// of simulated rover logs disagreed, 6 of 30; 2 with the scaling).
pub fn check_halves(
    samples: &[Sample],
    options: &SolveOptions,
    self_check: Option<&MatchSelfCheck>,
    slide: SlideModel,
) -> Consistency {
    let half = samples.len() / 2;
    let opts = SolveOptions {
        accept_weak: true,
        ..*options
    };
    let solve = |part: &[Sample], name: &str| {
        calibrate(part, &opts)
            .map(|mut c| {
                check_and_apply(&mut c, part, &opts, slide);
                scale_by_self_check(&mut c, self_check);
                c
            })
            .map_err(|e| format!("the {name} half alone: {e}"))
    };
    // Both halves are solved (on two threads when the pool has them).
    match rayon::join(
        || solve(&samples[..half], "first"),
        || solve(&samples[half..], "second"),
    ) {
        (Ok(a), Ok(b)) => match undetermined_half(&a, &b, options) {
            Err(reason) => Consistency::NotAvailable { reason },
            Ok(weak) => {
                let sum = std::array::from_fn(|i| {
                    std::array::from_fn(|j| a.covariance[i][j] + b.covariance[i][j])
                });
                let compared = leaving_out(options, &weak, &a);
                let what = if weak.is_empty() {
                    "the two halves of the log".to_string()
                } else {
                    format!(
                        "the two halves of the log, on the parameters both determine well \
                         (not {}: weak in a half),",
                        weak.iter()
                            .map(|&i| PARAMETER_NAMES[i])
                            .collect::<Vec<_>>()
                            .join(", ")
                    )
                };
                Consistency::Checked(Box::new(compare(&a, &b, &sum, &compared, &what)))
            }
        },
        (Err(reason), _) | (_, Err(reason)) => Consistency::NotAvailable { reason },
    }
}

/// The free parameters that a half leaves weak (compared on the others), or why the
/// halves cannot be compared at all: a half that does not excite a free parameter or
/// leaves every one weak, or halves that land on different signs of the radii (the
/// mirror solution of reversed wheels): their covariances then describe a
/// linearization that is not valid, and χ² of the difference means nothing (on
/// 20–60 s logs such halves gave χ² in the tens of thousands). A weak parameter's
/// marginal is left out; the others' are compared (the real MinesRover logs, driven
/// without spins, leave ℓx and ℓy weak in a half, exp2 b too, and are compared on the
/// other four, or three).
fn undetermined_half(
    a: &Calibration,
    b: &Calibration,
    options: &SolveOptions,
) -> Result<Vec<usize>, String> {
    let mut weak: Vec<usize> = Vec::new();
    for (half, name) in [(a, "first"), (b, "second")] {
        match left_out(half, options) {
            Ok(not_well) => weak.extend(not_well),
            Err(not_well) => {
                return Err(format!(
                    "the {name} half alone does not determine {} well ({} samples): the log \
                     is too short, or its motion too uneven, for the two-halves check",
                    names_of(half, &not_well),
                    half.samples_used
                ))
            }
        }
    }
    weak.sort_unstable();
    weak.dedup();
    let sign = |c: &Calibration| (c.params.r_l.signum(), c.params.r_r.signum());
    if sign(a) != sign(b) {
        return Err(
            "the two halves alone land on opposite signs of the wheel radii (the \
                    mirror solution): each half is too short to tell them apart, so the \
                    two-halves check is left out"
                .to_string(),
        );
    }
    Ok(weak)
}

/// The free parameters (not held in `options`) that `c` does not determine well:
/// `Ok` when they are only weak and some free parameter is well determined (a
/// comparison leaves them out, [`leaving_out`]); `Err` when one is not excited at all
/// or none is well determined (no comparison is valid).
pub(crate) fn left_out(c: &Calibration, options: &SolveOptions) -> Result<Vec<usize>, Vec<usize>> {
    let verdict = |i: usize| c.observability.parameters[i].verdict;
    let free: Vec<usize> = (0..6)
        .filter(|&i| !options.constraints.is_held(i))
        .collect();
    let not_well: Vec<usize> = free
        .iter()
        .copied()
        .filter(|&i| verdict(i) != Verdict::WellDetermined)
        .collect();
    if not_well.len() == free.len() || not_well.iter().any(|&i| verdict(i) == Verdict::NotExcited) {
        Err(not_well)
    } else {
        Ok(not_well)
    }
}

/// The names of parameters `which` as `c`'s observability gives them, joined.
pub(crate) fn names_of(c: &Calibration, which: &[usize]) -> String {
    which
        .iter()
        .map(|&i| c.observability.parameters[i].name.as_str())
        .collect::<Vec<_>>()
        .join(", ")
}

/// `options` with the parameters `left_out` counting as held (at `at`'s values), so
/// that [`compare`] compares the others' marginal: the parameters one side leaves
/// weak.
pub(crate) fn leaving_out(
    options: &SolveOptions,
    left_out: &[usize],
    at: &Calibration,
) -> SolveOptions {
    let values = at.params.to_vector();
    let mut o = *options;
    for &i in left_out {
        o.constraints.0[i] = Constraint::Held(values[i]);
    }
    o
}

/// Compares `a` with `b` given the covariance of their difference; `what` names the
/// two in the sentence ("the two halves of the log").
pub(crate) fn compare(
    a: &Calibration,
    b: &Calibration,
    difference_covariance: &[[f64; 6]; 6],
    options: &SolveOptions,
    what: &str,
) -> HalvesCheck {
    let difference = a.params.difference(&b.params);
    let free: Vec<usize> = (0..6)
        .filter(|&i| !options.constraints.is_held(i))
        .collect();
    let combined = |i: usize, j: usize| difference_covariance[i][j];
    let mut sigma = [0.0; 6];
    let mut z = [0.0; 6];
    for &i in &free {
        sigma[i] = combined(i, i).max(0.0).sqrt();
        z[i] = if sigma[i] > 0.0 {
            difference[i] / sigma[i]
        } else {
            0.0
        };
    }
    let n = free.len();
    let c = DMatrix::from_fn(n, n, |p, q| combined(free[p], free[q]));
    let d = DMatrix::from_fn(n, 1, |p, _| difference[free[p]]);
    let chi2 = c
        .cholesky()
        .map(|ch| (d.transpose() * ch.solve(&d))[(0, 0)])
        .unwrap_or(f64::INFINITY);
    let chi2_limit = CHI2_3SIGMA[n.clamp(1, 6) - 1];
    let disagreeing: Vec<String> = free
        .iter()
        .filter(|&&i| z[i].abs() > Z_LIMIT)
        .map(|&i| PARAMETER_NAMES[i].to_string())
        .collect();
    let agree = disagreeing.is_empty() && chi2 <= chi2_limit;
    let sentence = if agree {
        format!(
            "{what} agree (χ² {chi2:.1} for {n} parameters, 3σ level {chi2_limit:.1}; largest difference {:.1}σ)",
            free.iter().map(|&i| z[i].abs()).fold(0.0, f64::max)
        )
    } else {
        disagreement_sentence(what, &free, &z, chi2, n, chi2_limit)
    };
    HalvesCheck {
        samples_used: [a.samples_used, b.samples_used],
        difference,
        sigma,
        z,
        chi2,
        dof: n,
        chi2_limit,
        disagreeing,
        agree,
        sentence,
    }
}

/// "The halves disagree on …: likely …", naming the parameters beyond 3σ (or the
/// largest ones when only χ² is beyond its level) and the causes that fit them.
fn disagreement_sentence(
    what: &str,
    free: &[usize],
    z: &[f64; 6],
    chi2: f64,
    n: usize,
    limit: f64,
) -> String {
    let mut named: Vec<usize> = free
        .iter()
        .copied()
        .filter(|&i| z[i].abs() > Z_LIMIT)
        .collect();
    if named.is_empty() {
        let mut by_size = free.to_vec();
        by_size.sort_by(|&p, &q| z[q].abs().total_cmp(&z[p].abs()));
        named = by_size.into_iter().take(2).collect();
    }
    let list: Vec<String> = named
        .iter()
        .map(|&i| format!("{} by {:.1}σ", PARAMETER_NAMES[i], z[i].abs()))
        .collect();
    let radii = named.iter().any(|&i| i < 2);
    let base = named.contains(&2);
    let laser = named.iter().any(|&i| i >= 3);
    let sweep = "a range finder that sweeps while the robot moves (give --time-increment \
                 or the log's laser time increment)";
    let clock = "a clock offset between laser and encoders (try --estimate-time-offset)";
    let slip = "wheel slip or a changing load or tyre";
    let mounting = "a sensor mounting that moved during the log";
    let drift = "a laser whose ranges drifted in scale during the log (one still warming \
                 up: start recording after it has run for some minutes)";
    // Both radii moved the same way: a change of scale (of the ranges, or of the
    // wheels' rolling radius).
    let scaled = radii && free.contains(&0) && free.contains(&1) && z[0] * z[1] > 0.0;
    let causes: Vec<&str> = if laser {
        vec![sweep, clock, mounting, slip]
    } else if base {
        vec![sweep, clock, slip, mounting]
    } else if scaled {
        vec![slip, drift, clock, sweep, mounting]
    } else if radii {
        vec![slip, clock, sweep, mounting]
    } else {
        vec![sweep, clock, slip, mounting]
    };
    format!(
        "{what} disagree beyond 3σ ({}; χ² {chi2:.1} for {n} parameters, 3σ \
         level {limit:.1}): something the model does not include changed or acts unevenly, so \
         the reported σ understate the error; likely causes: {}",
        list.join(", "),
        causes.join(", or ")
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use odocal_geom::Pose2;
    use odocal_solver::{Params, Predictor};

    /// Deterministic noise in [−0.5, 0.5).
    fn noise(k: usize) -> f64 {
        let v = ((k as f64) * 12.9898).sin() * 43758.5453;
        v - v.floor() - 0.5
    }

    /// The robot of the tests.
    fn robot() -> Params {
        Params {
            r_l: 0.03,
            r_r: 0.031,
            b: 0.3,
            laser: Pose2::new(0.1, 0.02, 0.5),
        }
    }

    /// 400 samples of a mixed drive; the second half with `second` parameters.
    fn drive(first: &Params, second: &Params) -> Vec<Sample> {
        (0..400)
            .map(|k| {
                let p = if k < 200 { first } else { second };
                let scale = 1.0 + 0.5 * noise(7 * k + 1);
                let (l, r) = [(5.0, 5.0), (-4.0, 4.0), (2.0, 6.0)][k % 3];
                let s = Sample::from_rotations(0.4, l * scale, r * scale, Pose2::IDENTITY);
                let sm = Predictor::new(p, true).predict(&s);
                let e = |c: usize| 2e-3 * noise(7 * k + 2 + c);
                Sample {
                    sm: Pose2::new(sm[0] + e(0), sm[1] + e(1), sm[2] + e(2)),
                    ..s
                }
            })
            .collect()
    }

    /// 400 samples of a robot that slides sideways in its turns, `v_y = −k·v·ω` with
    /// k = 0.05 s: the first half turns fast (its arcs slide 8 mm a sample), the
    /// second slowly (2 mm), so that the six-parameter model takes up a different
    /// part of the slide in each.
    fn sliding_drive() -> Vec<Sample> {
        let p = robot();
        let k_slide = 0.05;
        (0..400)
            .map(|k| {
                let scale = 1.0 + 0.2 * noise(7 * k + 1);
                let arcs = if k < 200 { (3.0, 7.0) } else { (1.5, 3.5) };
                let (l, r) = [(5.0, 5.0), (-4.0, 4.0), arcs][k % 3];
                let (l, r) = (l * scale, r * scale);
                let s = Sample::from_rotations(0.4, l, r, Pose2::IDENTITY);
                let v = 0.5 * (p.r_l * l + p.r_r * r) / 0.4;
                let w = (p.r_r * r - p.r_l * l) / p.b / 0.4;
                let lateral = -k_slide * v * w;
                let steps = 400;
                let dt = 0.4 / steps as f64;
                let mut body = Pose2::IDENTITY;
                for _ in 0..steps {
                    body = body.compose(&Pose2::new(v * dt, lateral * dt, w * dt));
                }
                let sm = p.laser.inverse().compose(&body).compose(&p.laser);
                let e = |c: usize| 2e-3 * noise(7 * k + 2 + c);
                Sample {
                    sm: Pose2::new(sm.x + e(0), sm.y + e(1), sm.theta + e(2)),
                    ..s
                }
            })
            .collect()
    }

    #[test]
    fn the_halves_of_a_sliding_robot_weigh_the_slide_as_the_log_does() {
        let samples = sliding_drive();
        let opts = SolveOptions::default();
        let Consistency::Checked(without) = check_halves(&samples, &opts, None, SlideModel::Off)
        else {
            panic!("not checked")
        };
        let Consistency::Checked(with) = check_halves(&samples, &opts, None, SlideModel::Auto)
        else {
            panic!("not checked")
        };
        println!(
            "without the slide: {}\nwith it: {}",
            without.sentence, with.sentence
        );
        assert!(!without.agree, "{}", without.sentence);
        assert!(with.agree, "{}", with.sentence);
        assert!(
            with.chi2 < 0.1 * without.chi2,
            "{} vs {}",
            with.chi2,
            without.chi2
        );
    }

    #[test]
    fn same_robot_agrees_and_a_moved_sensor_does_not() {
        let robot = robot();
        let opts = SolveOptions::default();
        let Consistency::Checked(same) =
            check_halves(&drive(&robot, &robot), &opts, None, SlideModel::Auto)
        else {
            panic!("not checked")
        };
        assert!(same.agree, "{}", same.sentence);
        assert_eq!(same.dof, 6);
        let moved = Params {
            laser: Pose2::new(0.1, 0.035, 0.5),
            ..robot
        };
        let Consistency::Checked(c) =
            check_halves(&drive(&robot, &moved), &opts, None, SlideModel::Auto)
        else {
            panic!("not checked")
        };
        assert!(!c.agree, "{}", c.sentence);
        assert!(c.disagreeing.contains(&"l_y".to_string()), "{c:?}");
        assert!(c.sentence.contains("mounting"), "{}", c.sentence);
        // Holding b removes it from the χ².
        let mut held = opts;
        held.constraints.0[2] = odocal_solver::Constraint::Held(0.3);
        let Consistency::Checked(h) =
            check_halves(&drive(&robot, &robot), &held, None, SlideModel::Auto)
        else {
            panic!("not checked")
        };
        assert_eq!((h.dof, h.z[2]), (5, 0.0));
        // Too few samples for a half: not available, with the reason.
        let few = drive(&robot, &robot)[..16].to_vec();
        assert!(matches!(
            check_halves(&few, &opts, None, SlideModel::Auto),
            Consistency::NotAvailable { .. }
        ));
    }

    #[test]
    fn the_halves_are_judged_with_the_matchers_own_error_as_the_log_is() {
        let robot = robot();
        let opts = SolveOptions::default();
        // The laser moved by 0.6 mm sideways between the halves.
        let moved = Params {
            laser: Pose2::new(0.1, 0.0206, 0.5),
            ..robot
        };
        let samples = drive(&robot, &moved);
        let Consistency::Checked(plain) = check_halves(&samples, &opts, None, SlideModel::Auto)
        else {
            panic!("not checked")
        };
        // A matcher whose error per pair is 3× the halves' scan-matching noise: every
        // σ of the log is 3× larger, and so are the halves'.
        let sm = calibrate(&samples, &opts).expect("calibrates").sm_sigma;
        let check = MatchSelfCheck {
            triples: 60,
            tried: 60,
            left_out: 0,
            xy_m: 3.0 * (0.5 * (sm[0] * sm[0] + sm[1] * sm[1])).sqrt(),
            theta_rad: 3.0 * sm[2],
            range_noise_m: 0.01,
            ray_spacing_rad: 0.006,
            tilt_sigma_rad: None,
            sigma_factor: 1.0,
        };
        let Consistency::Checked(scaled) =
            check_halves(&samples, &opts, Some(&check), SlideModel::Auto)
        else {
            panic!("not checked")
        };
        assert!(!plain.agree && scaled.agree, "{plain:?}\n{scaled:?}");
        let ratio = plain.chi2 / scaled.chi2;
        assert!(
            (8.0..16.0).contains(&ratio),
            "χ² {} → {}",
            plain.chi2,
            scaled.chi2
        );
        // Within the self-check's sampling error of the noise: not scaled.
        let close = MatchSelfCheck {
            xy_m: check.xy_m / 3.0,
            theta_rad: check.theta_rad / 3.0,
            ..check
        };
        assert_eq!(
            check_halves(&samples, &opts, Some(&close), SlideModel::Auto),
            Consistency::Checked(plain)
        );
    }

    #[test]
    fn a_half_that_leaves_a_parameter_weak_is_compared_on_the_others() {
        let robot = robot();
        let opts = SolveOptions::default();
        let samples = drive(&robot, &robot);
        let solve = |part: &[Sample]| calibrate(part, &opts).expect("a half calibrates");
        let (first, second) = (solve(&samples[..200]), solve(&samples[200..]));
        assert_eq!(undetermined_half(&first, &second, &opts), Ok(vec![]));
        // A half with a weak parameter: left out, the others compared.
        let mut weak = second.clone();
        weak.observability.parameters[3].verdict = Verdict::Weak;
        assert_eq!(undetermined_half(&first, &weak, &opts), Ok(vec![3]));
        // ... and not named when held.
        let mut held = opts;
        held.constraints.0[3] = odocal_solver::Constraint::Held(0.1);
        assert_eq!(undetermined_half(&first, &weak, &held), Ok(vec![]));
        // Left out, the parameter counts as held for the comparison: one fewer degree
        // of freedom, no z for it.
        let sum = std::array::from_fn(|i| {
            std::array::from_fn(|j| first.covariance[i][j] + second.covariance[i][j])
        });
        let h = compare(
            &first,
            &second,
            &sum,
            &leaving_out(&opts, &[3], &first),
            "x",
        );
        assert_eq!((h.dof, h.z[3], h.sigma[3]), (5, 0.0, 0.0));
        // A parameter a half does not excite, or every parameter weak: not compared.
        let mut unexcited = second.clone();
        unexcited.observability.parameters[3].verdict = Verdict::NotExcited;
        let reason = undetermined_half(&first, &unexcited, &opts).expect_err("not compared");
        assert!(
            reason.contains("second half")
                && reason.contains("l_x")
                && reason.contains("too short"),
            "{reason}"
        );
        let mut all_weak = second.clone();
        for p in all_weak.observability.parameters.iter_mut() {
            p.verdict = Verdict::Weak;
        }
        assert!(undetermined_half(&all_weak, &second, &opts).is_err());
        // A half on the mirror solution (reversed wheels).
        let mut mirror = second;
        mirror.params.r_l = -mirror.params.r_l;
        mirror.params.r_r = -mirror.params.r_r;
        let reason = undetermined_half(&first, &mirror, &opts).expect_err("not compared");
        assert!(reason.contains("opposite signs"), "{reason}");
    }

    #[test]
    fn sentence_names_parameters_and_causes() {
        let z = [0.5, 0.4, 4.2, 1.0, 3.5, 0.2];
        let s = disagreement_sentence("the halves", &[0, 1, 2, 3, 4, 5], &z, 40.0, 6, 20.06);
        assert!(s.contains("b by 4.2σ") && s.contains("l_y by 3.5σ"), "{s}");
        assert!(!s.contains("r_L"), "{s}");
        assert!(s.contains("sweeps") && s.contains("clock offset"), "{s}");
        assert!(s.contains("slip") && s.contains("mounting"), "{s}");
        let radii = disagreement_sentence(
            "the halves",
            &[0, 1],
            &[3.5, 3.2, 0.0, 0.0, 0.0, 0.0],
            15.0,
            2,
            11.83,
        );
        assert!(radii.contains("likely causes: wheel slip"), "{radii}");
        // Both radii larger in one half: a change of scale, the laser's drift among
        // the causes; opposite ways, not.
        assert!(radii.contains("drifted in scale"), "{radii}");
        let opposite = disagreement_sentence(
            "the halves",
            &[0, 1],
            &[3.5, -3.2, 0.0, 0.0, 0.0, 0.0],
            15.0,
            2,
            11.83,
        );
        assert!(!opposite.contains("drifted"), "{opposite}");
    }
}
