//! Observability report: how well the data determine each parameter (standard
//! deviation from the covariance, verdict), what kind of motion the samples contain,
//! a sentence saying which motion is missing, and detection of reversed or swapped
//! wheel encoders. Also builds the "not excited" errors for degenerate data.

use crate::constraints::{Constraint, Constraints};
use crate::error::SolveError;
use crate::packed::Packed;
use crate::params::{Params, PARAMETER_NAMES};
use crate::step1::Step1;
use serde::Serialize;

/// Radii and wheel distance: relative σ below which they are well determined.
pub const RELATIVE_SIGMA_WELL: f64 = 0.02;
/// Radii and wheel distance: relative σ above which they count as not excited.
pub const RELATIVE_SIGMA_NOT_EXCITED: f64 = 0.2;
/// ℓx, ℓy: σ as a fraction of the wheel distance below which they are well determined.
pub const OFFSET_SIGMA_WELL: f64 = 0.05;
/// ℓx, ℓy: σ as a fraction of the wheel distance above which they count as not excited.
pub const OFFSET_SIGMA_NOT_EXCITED: f64 = 0.2;
/// ℓθ: σ (rad) below which it is well determined (about 3°).
pub const ANGLE_SIGMA_WELL: f64 = 0.05;
/// ℓθ: σ (rad) above which it counts as not excited (20°).
pub const ANGLE_SIGMA_NOT_EXCITED: f64 = 0.35;
/// A sample turns "in place" when its forward wheel travel is below this fraction
/// of its turning wheel travel, and goes "straight" in the opposite case.
pub const MOTION_CLASS_RATIO: f64 = 0.1;

/// How well the data determine a parameter.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Verdict {
    /// Small standard deviation.
    WellDetermined,
    /// Determined, but with a standard deviation large enough to matter.
    Weak,
    /// The data do not determine it.
    NotExcited,
}

impl Verdict {
    /// The verdict in words.
    pub fn as_str(&self) -> &'static str {
        match self {
            Verdict::WellDetermined => "well determined",
            Verdict::Weak => "weak",
            Verdict::NotExcited => "not excited",
        }
    }
}

/// One parameter's line of the report.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ParameterReport {
    /// Parameter name (`r_L`, `r_R`, `b`, `l_x`, `l_y`, `l_theta`).
    pub name: String,
    /// Estimated value (m or rad).
    pub value: f64,
    /// Standard deviation (m or rad).
    pub sigma: f64,
    /// The verdict.
    pub verdict: Verdict,
    /// Held at a known value, given a prior, or estimated from the data alone.
    pub constraint: Constraint,
}

/// How many samples contain each kind of motion (classified from the wheel
/// rotations scaled by the estimated radii).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct MotionContent {
    /// Turning in place (forward travel < 10 % of turning travel).
    pub spins: usize,
    /// Going straight (turning travel < 10 % of forward travel).
    pub straight: usize,
    /// Turning while translating (arcs).
    pub turning_while_translating: usize,
    /// Wheels (almost) still.
    pub still: usize,
}

impl MotionContent {
    /// Classifies the samples with radii `r_l`, `r_r` (any consistent scale; only
    /// their signs and ratio matter).
    pub(crate) fn classify(samples: &[Packed], r_l: f64, r_r: f64) -> Self {
        let mut m = MotionContent::default();
        let scale = 0.5 * (r_l.abs() + r_r.abs());
        for s in samples {
            let forward = 0.5 * (r_l * s.dphi_l + r_r * s.dphi_r);
            let turning = 0.5 * (r_r * s.dphi_r - r_l * s.dphi_l);
            let (f, t) = (forward.abs(), turning.abs());
            if f.max(t) <= 1e-6 * scale {
                m.still += 1;
            } else if f < MOTION_CLASS_RATIO * t {
                m.spins += 1;
            } else if t < MOTION_CLASS_RATIO * f {
                m.straight += 1;
            } else {
                m.turning_while_translating += 1;
            }
        }
        m
    }

    fn total(&self) -> usize {
        self.spins + self.straight + self.turning_while_translating + self.still
    }

    /// Names of the kinds of motion that are (nearly) absent: fewer than 2 samples
    /// or fewer than 1 % of them.
    pub fn missing(&self) -> Vec<&'static str> {
        let few = |c: usize| c < 2 || (c as f64) < 0.01 * self.total() as f64;
        let mut out = Vec::new();
        if few(self.spins) {
            out.push("spins in place");
        }
        if few(self.straight) {
            out.push("straight runs");
        }
        if few(self.turning_while_translating) {
            out.push("turning while translating");
        }
        out
    }

    pub(crate) fn describe(&self) -> String {
        format!(
            "{} spins in place, {} straight, {} turning while translating, {} still",
            self.spins, self.straight, self.turning_while_translating, self.still
        )
    }
}

/// The observability part of a calibration.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Observability {
    /// Condition number of step 1's 2×2 normal matrix (the original tools refused
    /// above 75; here it is reported, and the verdicts come from the covariance).
    pub step1_condition: f64,
    /// Condition number of the 3×3 block `A` of step 2.
    pub a_condition: f64,
    /// Condition number of `A` with its diagonal scaled to one.
    pub a_condition_scaled: f64,
    /// Per parameter: value, σ and verdict, in the order r_L, r_R, b, ℓx, ℓy, ℓθ.
    pub parameters: Vec<ParameterReport>,
    /// Kinds of motion in the samples used.
    pub motion: MotionContent,
    /// In words: what is well or poorly determined and which motion is missing.
    pub sentence: String,
    /// Set when a radius came out negative: reversed encoder signs or swapped wheels.
    pub wheel_signs: Option<String>,
    /// Parameters that one sample determines almost alone (see
    /// [`crate::OneSampleSupport`]): none of them is "well determined".
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub one_sample: Vec<crate::OneSampleSupport>,
}

impl Observability {
    /// Judges the parameters again after their estimate or covariance changed (σ
    /// inflated, a slide term added): verdicts from the new σ, the same constraints,
    /// the parameters resting on one sample still not "well determined", and the
    /// sentence anew.
    pub(crate) fn rejudge(&mut self, params: &Params, covariance: &[[f64; 6]; 6]) {
        let constraints = Constraints(std::array::from_fn(|i| {
            self.parameters
                .get(i)
                .map_or(Default::default(), |p| p.constraint)
        }));
        self.parameters = judged(params, covariance, &constraints, &mut self.one_sample);
        self.sentence = full_sentence(&self.parameters, &self.motion, &self.one_sample);
    }
}

/// [`parameter_reports`], with a parameter judged weak where one sample decides its
/// verdict: "well determined" with the sample, not without it (σ times its
/// [`crate::OneSampleSupport::sigma_ratio`]); marks those supports as deciding.
pub(crate) fn judged(
    params: &Params,
    covariance: &[[f64; 6]; 6],
    constraints: &Constraints,
    one_sample: &mut [crate::OneSampleSupport],
) -> Vec<ParameterReport> {
    let mut reports = parameter_reports(params, covariance, constraints);
    let size = robot_size(params, covariance);
    for s in one_sample.iter_mut() {
        s.decides_verdict = false;
        for (i, r) in reports.iter_mut().enumerate() {
            if r.name != s.parameter || r.verdict != Verdict::WellDetermined {
                continue;
            }
            let without = s.sigma_ratio.map_or(f64::INFINITY, |k| k * r.sigma);
            if verdict(i, r.value, without, size) != Verdict::WellDetermined {
                r.verdict = Verdict::Weak;
                s.decides_verdict = true;
            }
        }
    }
    reports
}

/// [`sentence`], followed by what rests on one sample.
pub(crate) fn full_sentence(
    reports: &[ParameterReport],
    motion: &MotionContent,
    one_sample: &[crate::OneSampleSupport],
) -> String {
    if !one_sample.iter().any(|s| s.decides_verdict) {
        sentence(reports, motion)
    } else {
        format!(
            "{}; {}",
            sentence(reports, motion),
            crate::one_sample::describe(one_sample)
        )
    }
}

/// The robot's size that ℓx's and ℓy's σ are judged against: the wheel distance
/// less two of its σ (zero when that is not positive). The estimate alone would let
/// a wheel distance the data do not determine vouch for the laser's offsets: on a
/// simulated 20 s Khepera log that only turned along arcs, `b` came out at 25.7 m
/// (not excited) and ℓx at 1.21 ± 0.30 m, 1 % of it, "well determined" 4σ from the
/// truth (−5.8 mm).
fn robot_size(params: &Params, covariance: &[[f64; 6]; 6]) -> f64 {
    (params.b.abs() - 2.0 * covariance[2][2].max(0.0).sqrt()).max(0.0)
}

/// Verdict for parameter `index` with value `value`, σ `sigma` and robot size `b`
/// (see [`robot_size`]).
fn verdict(index: usize, value: f64, sigma: f64, b: f64) -> Verdict {
    let (measure, well, not_excited) = match index {
        0..=2 => (
            sigma / value.abs(),
            RELATIVE_SIGMA_WELL,
            RELATIVE_SIGMA_NOT_EXCITED,
        ),
        3 | 4 => (sigma / b.abs(), OFFSET_SIGMA_WELL, OFFSET_SIGMA_NOT_EXCITED),
        _ => (sigma, ANGLE_SIGMA_WELL, ANGLE_SIGMA_NOT_EXCITED),
    };
    if !measure.is_finite() || measure > not_excited {
        Verdict::NotExcited
    } else if measure > well {
        Verdict::Weak
    } else {
        Verdict::WellDetermined
    }
}

/// Per-parameter reports from the estimate and its covariance (held parameters,
/// with zero variance, are "well determined").
pub fn parameter_reports(
    params: &Params,
    covariance: &[[f64; 6]; 6],
    constraints: &Constraints,
) -> Vec<ParameterReport> {
    let v = params.to_vector();
    let size = robot_size(params, covariance);
    (0..6)
        .map(|i| {
            let sigma = covariance[i][i].max(0.0).sqrt();
            ParameterReport {
                name: PARAMETER_NAMES[i].to_string(),
                value: v[i],
                sigma,
                verdict: if constraints.is_held(i) {
                    Verdict::WellDetermined
                } else {
                    verdict(i, v[i], sigma, size)
                },
                constraint: constraints.0[i],
            }
        })
        .collect()
}

fn join_names(names: &[&str]) -> String {
    match names.len() {
        0 => String::new(),
        1 => names[0].to_string(),
        n => format!("{} and {}", names[..n - 1].join(", "), names[n - 1]),
    }
}

/// Which motion would excite these parameters, given what is missing.
fn advice(names: &[&str], motion: &MotionContent) -> String {
    let missing = motion.missing();
    let lacks = |m: &str| missing.contains(&m);
    let mut tips: Vec<&str> = Vec::new();
    let odometry = names.iter().any(|n| matches!(*n, "r_L" | "r_R" | "b"));
    let offset = names.iter().any(|n| matches!(*n, "l_x" | "l_y"));
    let heading = names.contains(&"l_theta");
    if odometry && lacks("straight runs") {
        tips.push("straight runs");
    }
    if odometry && lacks("spins in place") {
        tips.push("spins in place");
    }
    let turns_present = !(lacks("spins in place") && lacks("turning while translating"));
    if offset && !turns_present && !tips.contains(&"spins in place") {
        tips.push("turns (spins in place or arcs)");
    }
    let translation_present = !(lacks("straight runs") && lacks("turning while translating"));
    if heading && !translation_present && !tips.contains(&"straight runs") {
        tips.push("translation (straight runs or arcs)");
    }
    tips.dedup();
    if tips.is_empty() {
        if missing.is_empty() {
            "every kind of motion is present, but too little of it for the scan-matching \
             noise: drive longer or more varied paths"
                .to_string()
        } else {
            format!(
                "the data have no {}; drive longer or more varied paths",
                missing.join(" and no ")
            )
        }
    } else {
        let have = if missing.is_empty() {
            String::new()
        } else {
            format!("the data have no {}; ", missing.join(" and no "))
        };
        format!("{have}add {}", join_names(&tips))
    }
}

/// The sentence of a successful calibration.
pub fn sentence(reports: &[ParameterReport], motion: &MotionContent) -> String {
    let names_with = |v: Verdict| -> Vec<&str> {
        reports
            .iter()
            .filter(|r| r.verdict == v)
            .map(|r| r.name.as_str())
            .collect()
    };
    let weak = names_with(Verdict::Weak);
    let not_excited = names_with(Verdict::NotExcited);
    if weak.is_empty() && not_excited.is_empty() {
        return format!(
            "all six parameters are well determined ({})",
            motion.describe()
        );
    }
    let mut parts = Vec::new();
    if !not_excited.is_empty() {
        parts.push(format!("{} not excited", join_names(&not_excited)));
    }
    if !weak.is_empty() {
        parts.push(format!("{} weak", join_names(&weak)));
    }
    let mut bad = not_excited.clone();
    bad.extend(weak.iter());
    format!(
        "{} ({}): {}",
        parts.join(", "),
        motion.describe(),
        advice(&bad, motion)
    )
}

/// A note when a radius is negative.
pub fn wheel_signs(params: &Params) -> Option<String> {
    match (params.r_l < 0.0, params.r_r < 0.0) {
        (true, true) => Some(format!(
            "both wheel radii came out negative (r_L = {:.6} m, r_R = {:.6} m): the encoder \
             signs are reversed on both wheels, or the left and right wheels are swapped (in \
             that case ℓθ is also off by π); fix the wheel assignment or the encoder signs",
            params.r_l, params.r_r
        )),
        (true, false) => Some(format!(
            "r_L came out negative ({:.6} m): the left encoder counts backwards (reversed sign)",
            params.r_l
        )),
        (false, true) => Some(format!(
            "r_R came out negative ({:.6} m): the right encoder counts backwards (reversed sign)",
            params.r_r
        )),
        (false, false) => None,
    }
}

/// Parameter names whose component in any of the unit `directions` exceeds 0.3.
fn names_in(directions: &[Vec<f64>], offset: usize) -> Vec<String> {
    let mut names = Vec::new();
    for (i, name) in PARAMETER_NAMES.iter().enumerate().skip(offset) {
        let involved = directions
            .iter()
            .any(|d| d.get(i - offset).is_some_and(|c| c.abs() > 0.3));
        if involved {
            names.push(name.to_string());
        }
    }
    names
}

/// The error for data whose step-1 normal matrix is singular: the wheel rotations
/// of all samples lie along one direction.
pub(crate) fn step1_not_excited(samples: &[Packed], s1: &Step1) -> SolveError {
    let motion = MotionContent::classify(samples, 1.0, 1.0);
    let n = s1.normal;
    let names = |v: &[&str]| v.iter().map(|s| s.to_string()).collect::<Vec<_>>();
    if n[0][0] + n[1][1] <= 0.0 {
        return SolveError::NotExcited {
            parameters: names(&PARAMETER_NAMES),
            sentence: "the wheels never turned: drive the robot (straight runs, spins in place \
                       and turns)"
                .into(),
        };
    }
    // The excited direction is orthogonal to the weakest one; classify it like a
    // sample (forward and turning wheel travel, radii taken equal).
    let u = [-s1.weakest_direction[1], s1.weakest_direction[0]];
    let forward = (0.5 * (u[0] + u[1])).abs();
    let turning = (0.5 * (u[1] - u[0])).abs();
    if turning < MOTION_CLASS_RATIO * forward {
        SolveError::NotExcited {
            parameters: names(&["b", "l_x", "l_y"]),
            sentence: format!(
                "only straight runs, no turning ({}): the wheels always turned equally, so the \
                 wheel distance b and the sensor offset ℓx, ℓy are not excited (and the closed \
                 form cannot separate r_L from r_R); add spins in place and turns",
                motion.describe()
            ),
        }
    } else if forward < MOTION_CLASS_RATIO * turning {
        SolveError::NotExcited {
            parameters: names(&PARAMETER_NAMES),
            sentence: format!(
                "only spins in place, no translation ({}): the data fix (r_L + r_R)/b and the \
                 sensor's distance from the rotation centre, but not r_L, r_R, b separately nor \
                 the direction of ℓ; add straight runs",
                motion.describe()
            ),
        }
    } else {
        SolveError::NotExcited {
            parameters: names(&["r_L", "r_R", "b"]),
            sentence: format!(
                "every sample has the same ratio of wheel rotations ({:.4}, one curvature; {}): \
                 r_L, r_R and b are not excited separately; add straight runs and spins in place",
                u[1] / u[0],
                motion.describe()
            ),
        }
    }
}

/// The error for data whose step-2 block `A` is singular.
pub(crate) fn step2_not_excited(
    samples: &[Packed],
    s1: &Step1,
    weakest: Option<[f64; 3]>,
) -> SolveError {
    let motion = MotionContent::classify(samples, -s1.j21, s1.j22);
    let mut parameters = match weakest {
        Some(d) => names_in(&[d.to_vec()], 2),
        None => Vec::new(),
    };
    if parameters.is_empty() {
        parameters = vec!["b".into(), "l_x".into(), "l_y".into()];
    }
    let refs: Vec<&str> = parameters.iter().map(|s| s.as_str()).collect();
    SolveError::NotExcited {
        sentence: format!(
            "the motion does not excite them ({}); {}; {PARTIAL_CALIBRATION_HINT}",
            motion.describe(),
            advice(&refs, &motion)
        ),
        parameters,
    }
}

/// The error for a singular Fisher information (null directions in unit-diagonal
/// scaling) or for parameters whose verdict is "not excited".
pub(crate) fn information_not_excited(
    parameters: Vec<String>,
    motion: &MotionContent,
) -> SolveError {
    let mut parameters = parameters;
    if parameters.is_empty() {
        parameters = PARAMETER_NAMES.iter().map(|s| s.to_string()).collect();
    }
    let refs: Vec<&str> = parameters.iter().map(|s| s.as_str()).collect();
    SolveError::NotExcited {
        sentence: format!(
            "the motion does not excite them ({}); {}; {PARTIAL_CALIBRATION_HINT}",
            motion.describe(),
            advice(&refs, motion)
        ),
        parameters,
    }
}

/// What a refusal suggests when some of the parameters concerned are known
/// from elsewhere (a datasheet, a measurement, another calibration).
pub const PARTIAL_CALIBRATION_HINT: &str = "if some of them are known, hold them with \
     --fix NAME=VALUE or give a prior with --prior NAME=VALUE±SIGMA (SI units)";

/// Names of the parameters involved in the null directions of the information.
pub(crate) fn null_direction_names(null: &[[f64; 6]]) -> Vec<String> {
    let dirs: Vec<Vec<f64>> = null.iter().map(|d| d.to_vec()).collect();
    names_in(&dirs, 0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use odocal_geom::Pose2;

    /// ℓx and ℓy are judged against a wheel distance the data determine: a 25.7 m
    /// one that is itself not excited does not make ℓx's 0.30 m σ "well determined".
    #[test]
    fn laser_offsets_are_judged_against_a_determined_robot_size() {
        let diagonal = |s: [f64; 6]| {
            let mut c = [[0.0; 6]; 6];
            for i in 0..6 {
                c[i][i] = s[i] * s[i];
            }
            c
        };
        let nonsense = Params {
            r_l: 0.02,
            r_r: 0.02,
            b: 25.7,
            laser: Pose2::new(1.21, 0.0, 0.0),
        };
        let sigma = [1e-4, 1e-4, 209.0, 0.30, 0.30, 0.01];
        let r = parameter_reports(&nonsense, &diagonal(sigma), &Constraints::default());
        assert_eq!(r[2].verdict, Verdict::NotExcited);
        assert_eq!(r[3].verdict, Verdict::NotExcited, "{:?}", r[3]);
        // A determined wheel distance: ℓx's 0.2 mm σ is well determined.
        let khepera = Params {
            b: 0.089,
            laser: Pose2::new(-0.0058, 0.0, 0.0),
            ..nonsense
        };
        let sigma = [1e-5, 1e-5, 1e-4, 2e-4, 2e-4, 0.001];
        let r = parameter_reports(&khepera, &diagonal(sigma), &Constraints::default());
        assert_eq!(r[3].verdict, Verdict::WellDetermined);
    }

    fn params(r_l: f64, r_r: f64) -> Params {
        Params {
            r_l,
            r_r,
            b: 0.3,
            laser: Pose2::new(0.1, 0.0, 0.0),
        }
    }

    #[test]
    fn verdicts_follow_the_thresholds() {
        let p = params(0.03, 0.03);
        let mut cov = [[0.0; 6]; 6];
        // r_L: 1 % (well), r_R: 10 % (weak), b: 10 % (weak), ℓx: 1 cm of a 30 cm
        // base less two of its σ, 24 cm (well), ℓy: 3 cm (weak), ℓθ: 1 rad (not
        // excited).
        let sigmas = [0.0003, 0.003, 0.03, 0.01, 0.03, 1.0];
        for i in 0..6 {
            cov[i][i] = sigmas[i] * sigmas[i];
        }
        let v: Vec<Verdict> = parameter_reports(&p, &cov, &Constraints::default())
            .iter()
            .map(|r| r.verdict)
            .collect();
        use Verdict::*;
        assert_eq!(
            v,
            vec![WellDetermined, Weak, Weak, WellDetermined, Weak, NotExcited]
        );
    }

    #[test]
    fn wheel_sign_notes() {
        assert!(wheel_signs(&params(0.03, 0.03)).is_none());
        assert!(wheel_signs(&params(-0.03, 0.03))
            .unwrap()
            .contains("left encoder"));
        assert!(wheel_signs(&params(0.03, -0.03))
            .unwrap()
            .contains("right encoder"));
        assert!(wheel_signs(&params(-0.03, -0.03))
            .unwrap()
            .contains("swapped"));
    }

    #[test]
    fn advice_names_the_missing_motion() {
        let motion = MotionContent {
            spins: 0,
            straight: 50,
            turning_while_translating: 0,
            still: 0,
        };
        let text = advice(&["l_x", "l_y"], &motion);
        assert!(
            text.contains("no spins in place") && text.contains("turns"),
            "{text}"
        );
    }
}
