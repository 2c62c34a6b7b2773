//! A refusal's true cause and its way out: why the data do not determine some
//! parameters (the trajectory lacks a kind of motion, most scan pairs failed to match),
//! and which parameters, held at known values, leave the others well determined.

use crate::sync::DiscardReason;
use crate::synchronized::Synchronized;
use odocal_solver::{Calibration, Constraint, Params, Sample, SolveOptions, Verdict};

/// Most scan pairs failed to match when failures exceed this share of the pairs tried.
pub const FAILED_MATCH_SHARE: f64 = 0.5;

/// A set of parameters is proposed for holding only if the others stay well
/// determined with their σ this much larger: the run with them held matches the scans
/// anew (guesses and sweep compensation from the held values), which moves σ a little.
pub const HOLD_SIGMA_MARGIN: f64 = 1.1;

/// The order in which parameters are proposed for holding: the laser's offset across
/// the robot first (most robots mount it on the centre line), then its offset along it,
/// its heading, then the wheels (harder to know: a skid-steered robot's effective
/// wheel distance is not its track).
const HOLD_ORDER: [usize; 6] = [4, 3, 5, 2, 0, 1];

/// Why a refusal happened and the way out, carried by
/// [`PipelineError::NotDetermined`](crate::PipelineError::NotDetermined).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Diagnosis {
    /// The causes found, with their evidence (the trajectory lacks a kind of motion,
    /// most scan pairs failed to match); empty when neither explains it.
    pub causes: Vec<String>,
    /// The fewest parameters that, held, leave the others well determined.
    pub holds: Vec<Hold>,
    /// What else weakens the verdicts (read-time jitter left after repair).
    pub caveat: Option<String>,
    /// Data faults found that are not the cause (set by
    /// [`PipelineError::with_faults`](crate::PipelineError::with_faults)).
    pub faults: Option<String>,
    /// Holding known parameters would not help: the cause is in the data (timing,
    /// a heading not from the wheels, scan matching), not in the motion, so the
    /// refusal does not suggest `--fix` or `--prior`.
    pub no_hold: bool,
    /// The stride the refused calibration paired its scans at (0: not known): above 1,
    /// the pairs starting at the other scans were not used (`--all-pairs` uses them).
    pub stride: usize,
}

/// A parameter to hold with `--fix`, with the value to hold it at when one is known.
#[derive(Debug, Clone, PartialEq)]
pub struct Hold {
    /// The parameter's name (`r_L`, `r_R`, `b`, `l_x`, `l_y`, `l_theta`).
    pub name: &'static str,
    /// The value (SI units) when known, else `None`: the user must measure it.
    pub value: Option<f64>,
    /// Where the value comes from, in words.
    pub source: &'static str,
}

impl Hold {
    /// The `--fix` argument: `l_y=0`, or `b=MEASURED` when the value is not known.
    pub fn argument(&self) -> String {
        match self.value {
            Some(v) => format!("--fix {}={v}", self.name),
            None => format!("--fix {}=MEASURED", self.name),
        }
    }
}

/// The causes found, as evidence in words (empty when neither the trajectory nor the
/// matching explains the refusal).
pub fn causes(calibration: &Calibration, synced: &Synchronized) -> Vec<String> {
    let mut out = Vec::new();
    let motion = &calibration.observability.motion;
    let missing = motion.missing();
    if !missing.is_empty() {
        out.push(format!(
            "the trajectory has no {} ({} spins in place, {} straight, {} turning while \
             translating among the samples used)",
            missing.join(" and no "),
            motion.spins,
            motion.straight,
            motion.turning_while_translating
        ));
    }
    let failed = synced.discarded.get(DiscardReason::MatchFailed);
    let tried = failed + synced.samples.len();
    if tried > 0 && failed as f64 > FAILED_MATCH_SHARE * tried as f64 {
        out.push(format!(
            "too few matched scan pairs: {failed} of {tried} failed to match (sparse, \
             cluttered or fast-changing scans), leaving {} samples",
            synced.samples.len()
        ));
    }
    out
}

/// The value to propose for holding parameter `i`: from `--nominal` when given, else the
/// usual mounting for the laser's offset across the robot and its heading.
fn known_value(i: usize, nominal: Option<&Params>) -> (Option<f64>, &'static str) {
    // A three-value --nominal leaves ℓ at 0, which is no measurement of ℓx; a six-value
    // one (some ℓ not 0) gives all of ℓ.
    let v = nominal.map(|p| p.to_vector());
    let laser_given = v.is_some_and(|v| v[3..].iter().any(|x| *x != 0.0));
    match (i, v) {
        (0..=2, Some(v)) => (Some(v[i]), "from --nominal"),
        (3..=5, Some(v)) if laser_given => (Some(v[i]), "from --nominal"),
        (4, _) => (
            Some(0.0),
            "the laser on the robot's centre line, as most are mounted; measure to confirm",
        ),
        (5, _) => (
            Some(0.0),
            "the laser facing straight ahead; measure to confirm",
        ),
        _ => (None, "measure it on the robot, in m"),
    }
}

/// The value at which a hold of parameter `i` is tried: the one the printed command
/// will hold it at ([`known_value`]), or the refused `estimate` for a value the user
/// is left to measure.
fn tried_value(i: usize, nominal: Option<&Params>, estimate: &[f64; 6]) -> f64 {
    known_value(i, nominal).0.unwrap_or(estimate[i])
}

/// True when every parameter not held is well determined.
fn all_determined(c: &Calibration) -> bool {
    c.observability
        .parameters
        .iter()
        .all(|p| p.verdict == Verdict::WellDetermined)
}

/// The fewest parameters (one, two, else three) that, held, leave every other parameter well
/// determined, preferring ℓy, ℓx, ℓθ, b, then the radii; empty when none does. Which ones is found
/// by holding them at the values proposed — from `--nominal`, the usual mounting (ℓy
/// and ℓθ at 0) — or, for a value left to measure, at the refused estimate (a held
/// value moves the others' σ: on the real exp2 log, ℓy held at its estimate left ℓx
/// well determined, held at the proposed 0 it did not). Each trial is judged as the
/// run proposed will be: `slide`, the run's sideways-slide model, weighed in, and the
/// σ scaled by `synced`'s self-check (the matcher's own error) and its phases' shared
/// errors.
pub fn holds(
    samples: &[Sample],
    options: &SolveOptions,
    refused: &Calibration,
    nominal: Option<&Params>,
    slide: crate::lateral_slip::SlideModel,
    synced: &crate::synchronized::Synchronized,
) -> Vec<Hold> {
    let estimate = refused.params.to_vector();
    let free: Vec<usize> = HOLD_ORDER
        .iter()
        .copied()
        .filter(|&i| !options.constraints.is_held(i))
        .collect();
    let mut sets: Vec<Vec<usize>> = free.iter().map(|&i| vec![i]).collect();
    for (a, &i) in free.iter().enumerate() {
        for &j in &free[a + 1..] {
            sets.push(vec![i, j]);
        }
    }
    for (a, &i) in free.iter().enumerate() {
        for (b, &j) in free.iter().enumerate().skip(a + 1) {
            for &k in &free[b + 1..] {
                sets.push(vec![i, j, k]);
            }
        }
    }
    let works = |set: &[usize]| {
        let mut o = *options;
        o.accept_weak = true;
        for &i in set {
            o.constraints.0[i] = Constraint::Held(tried_value(i, nominal, &estimate));
        }
        odocal_solver::calibrate(samples, &o).is_ok_and(|mut c| {
            // The sideways slide weighed in as the run proposed will (its share of
            // the σ is often ℓx's largest on a skid-steer robot).
            crate::lateral_slip::check_and_apply(&mut c, samples, &o, slide);
            // The matcher's own error scales the σ as it does the run's.
            crate::match_quality::scale_by_self_check(&mut c, synced.match_self_check.as_ref());
            // With a margin: the command proposed is run on data matched anew with
            // the held values, and must not land just past a threshold.
            // The phases' shared errors scale the σ of the run proposed as they did
            // this one's.
            odocal_solver::inflate_sigma(
                &mut c,
                HOLD_SIGMA_MARGIN * synced.shared_error_factor.max(1.0),
            );
            all_determined(&c)
        })
    };
    let Some(set) = sets.into_iter().find(|s| works(s)) else {
        return Vec::new();
    };
    set.into_iter()
        .map(|i| {
            let (value, source) = known_value(i, nominal);
            Hold {
                name: odocal_solver::PARAMETER_NAMES[i],
                value,
                source,
            }
        })
        .collect()
}

/// The way out in words: what to hold, at which value and why.
pub fn describe_holds(holds: &[Hold]) -> String {
    let parts: Vec<String> = holds
        .iter()
        .map(|h| format!("{} ({})", h.argument(), h.source))
        .collect();
    format!(
        "the other parameters are well determined with {} held: {}",
        holds
            .iter()
            .map(|h| h.name)
            .collect::<Vec<_>>()
            .join(" and "),
        parts.join(", ")
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn holds_are_tried_at_the_values_the_command_proposes() {
        // A refused estimate with the laser 4 cm to the left and turned 0.1 rad.
        let estimate = [0.077, 0.078, 0.31, 0.15, 0.04, 0.1];
        // Without --nominal: ℓy and ℓθ at the usual mounting (0), not at the
        // estimate; ℓx and the odometry, left to measure, at the estimate.
        let tried: Vec<f64> = (0..6).map(|i| tried_value(i, None, &estimate)).collect();
        assert_eq!(tried, [0.077, 0.078, 0.31, 0.15, 0.0, 0.0]);
        // With a six-value --nominal, every value is the nominal's.
        let nominal = Params::from_vector([0.076, 0.076, 0.33, 0.145, 0.001, 0.002]);
        for (i, want) in nominal.to_vector().iter().enumerate() {
            assert_eq!(tried_value(i, Some(&nominal), &estimate), *want);
        }
        // A three-value --nominal (ℓ all 0) measures the odometry only.
        let odometry = Params::from_vector([0.076, 0.076, 0.33, 0.0, 0.0, 0.0]);
        let tried: Vec<f64> = (0..6)
            .map(|i| tried_value(i, Some(&odometry), &estimate))
            .collect();
        assert_eq!(tried, [0.076, 0.076, 0.33, 0.15, 0.0, 0.0]);
    }
}
