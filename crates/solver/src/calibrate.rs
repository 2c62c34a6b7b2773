//! The whole chain: checks, closed form (step 1 + step 2) with outlier trimming,
//! noise estimate, maximum-likelihood refinement, covariance, observability.

use crate::constraints::{Constraint, Constraints};
use crate::covariance::{invert_information, Inversion};
use crate::error::SolveError;
use crate::kinematics::{residual_of, Predictor, RawOdometry};
use crate::matcher_bias::bias_covariance;
use crate::noise::{residual_sigmas, NoiseWeights};
use crate::noise_shape::{independent_score, NoiseShapes, NoiseShaping};
use crate::observability::{
    full_sentence, information_not_excited, judged, null_direction_names, step1_not_excited,
    step2_not_excited, wheel_signs, MotionContent, Observability, Verdict,
};
use crate::one_sample::resting_on_one_sample;
use crate::packed::Packed;
use crate::params::Params;
use crate::partial::{step1_held, step2_held};
use crate::refine::{constrained_normal_equations, refine, Refinement};
use crate::sample::{measured_part, Sample};
use crate::shared_scans::{score_covariance, SharedScanNoise};
use crate::step1::{step1, Step1};
use crate::step2::{build_m, solve_m, Step2, A_SINGULAR_CONDITION};
use crate::trimming::{robust_location_scale, Trim, CHI2_3DOF_9999};
use nalgebra::SMatrix;
use serde::{Deserialize, Serialize};

/// Fewest samples the solver accepts (input and after each trimming round).
pub const MIN_SAMPLES: usize = 10;

/// Condition number of step 1's normal matrix above which `J21`, `J22` are
/// numerically undetermined (an error, not a warning; below it the covariance
/// decides).
pub const STEP1_SINGULAR_CONDITION: f64 = 1e12;

/// The first-round noise estimate is taken as the original package takes it unless
/// it exceeds, in some component, this many times the same samples' residual σ at the
/// estimate re-solved without the first round's outliers.
pub const PULLED_ESTIMATE_RATIO: f64 = 1.5;

/// The scan-matching σ of [`SigmaEstimate::FirstRound`]: the residuals of the first
/// (untrimmed) estimate over the samples the first round kept — unless one gross
/// outlier pulled that estimate so far that every kept residual grew (a 10 m failure
/// among 300 samples made σ 35× the noise, and every parameter's σ with it): then the
/// residuals of the same samples at the estimate re-solved without the outliers
/// (`resolved`). On clean data the two agree and the package's estimate stands.
fn first_round_sigmas(first: &[[f64; 3]], resolved: Option<&[[f64; 3]]>) -> [f64; 3] {
    let s_first = residual_sigmas(first);
    let Some(resolved) = resolved else {
        return s_first;
    };
    let s_resolved = residual_sigmas(resolved);
    let pulled = (0..3).any(|c| s_first[c] > PULLED_ESTIMATE_RATIO * s_resolved[c]);
    if pulled {
        s_resolved
    } else {
        s_first
    }
}

/// Settings of [`calibrate`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SolveOptions {
    /// Outlier trimming between closed-form solves (default: χ² on the residuals
    /// whitened by their robust scale, [`Trim::CHI2`], which works at any sample
    /// count; [`Trim::TRO`] is the original package's rule).
    pub trim: Trim,
    /// Refine all six parameters by maximum likelihood (default true).
    pub refine: bool,
    /// Use the wheel-speed profile of samples that have one (default true).
    pub use_profile: bool,
    /// Weight step 1 by 1/σθ² when every sample has a covariance (default true).
    pub weighted_step1: bool,
    /// Which residuals the scan-matching σ's come from (default: as the original
    /// package, [`SigmaEstimate::FirstRound`]).
    pub sigma_from: SigmaEstimate,
    /// Parameters held at known values or given priors (default: all free).
    pub constraints: Constraints,
    /// Return numbers even when the covariance says some parameters are not
    /// excited (σ beyond the verdict's limit); by default that is an error. A
    /// singular information matrix is an error regardless.
    pub accept_weak: bool,
    /// Standard deviations of a scan-matching bias common to every sample and
    /// proportional to its rotation (`ŝ` moved by `β·θ`; x, y in m/rad, θ in
    /// rad/rad, sensor frame), added to the covariance as a systematic term (see
    /// `matcher_bias.rs`). Default zero: none.
    pub matcher_bias: [f64; 3],
}

/// Which residuals `ŝ_pred − ŝ` the scan-matching standard deviations are estimated
/// from (they weight the refinement and scale the covariance, unless every sample
/// carries its own `sm_cov`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SigmaEstimate {
    /// As the original package: residuals of the first (untrimmed) closed-form
    /// estimate over the samples kept after the first trimming round. Conservative
    /// when outliers survive the first round.
    FirstRound,
    /// Residuals of the final closed-form estimate over the final samples.
    FinalSet,
}

impl Default for SolveOptions {
    fn default() -> Self {
        SolveOptions {
            trim: Trim::CHI2,
            refine: true,
            use_profile: true,
            weighted_step1: true,
            sigma_from: SigmaEstimate::FirstRound,
            constraints: Constraints::default(),
            accept_weak: false,
            matcher_bias: [0.0; 3],
        }
    }
}

/// Where the weights of the residuals (and the covariance's noise level) came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum NoiseSource {
    /// Standard deviations estimated from the closed form's residuals.
    Estimated,
    /// Each sample's own `sm_cov`.
    SampleCovariance,
    /// Standard deviations estimated from the residuals, shaped per sample by the
    /// scan matcher's covariance of it relative to the typical match
    /// ([`Sample::matcher_cov`]).
    Shaped,
}

/// The closed-form solution on one set of samples.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ClosedForm {
    /// The parameters.
    pub params: Params,
    /// Step 1.
    pub step1: Step1,
    /// Step 2.
    pub step2: Step2,
}

/// Everything [`calibrate`] finds.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Calibration {
    /// The estimate (refined unless refinement was switched off).
    pub params: Params,
    /// The closed-form estimate after trimming (before refinement).
    pub closed_form: Params,
    /// `J = [[r_L/2, r_R/2], [−r_L/b, r_R/b]]` of the estimate.
    pub j: [[f64; 2]; 2],
    /// Covariance of (r_L, r_R, b, ℓx, ℓy, ℓθ) at the estimate.
    pub covariance: [[f64; 6]; 6],
    /// Standard deviations (x, y, θ) of `ŝ_pred − ŝ` (m, m, rad), from the residuals
    /// chosen by [`SolveOptions::sigma_from`].
    pub sm_sigma: [f64; 3],
    /// Source of the residual weights used by the refinement and the covariance.
    pub noise_source: NoiseSource,
    /// Number of samples used by the final estimate.
    pub samples_used: usize,
    /// Per input sample: whether it survived trimming.
    pub used: Vec<bool>,
    /// Number of samples after each trimming round (first entry: the input).
    pub samples_per_round: Vec<usize>,
    /// Weighted cost `Σ (ŝ_pred − ŝ)ᵀ Σ⁻¹ (ŝ_pred − ŝ)` at the closed form.
    pub cost_before: f64,
    /// The same cost at the returned estimate.
    pub cost_after: f64,
    /// `cost_after / (3·samples_used − 6)`: about 1 when the noise model fits the
    /// samples used; well below 1 means the covariance is conservative (σ's inflated
    /// by outliers that only later rounds removed), well above 1 that it is optimistic.
    pub reduced_chi2: f64,
    /// Details of the refinement, when it ran.
    pub refinement: Option<Refinement>,
    /// Observability report.
    pub observability: Observability,
    /// With the samples weighted by the matcher's shapes ([`NoiseSource::Shaped`]):
    /// the levels and the share of the noise that follows the shapes.
    pub noise_shaping: Option<NoiseShaping>,
    /// The noise shared by samples that share a scan, when the samples carry their
    /// scans' times (the covariance then accounts for it); `None`: the samples
    /// were treated as independent.
    pub shared_scan_noise: Option<SharedScanNoise>,
    /// The sideways slide in turns, when it was checked for (see
    /// [`crate::fit_lateral_slip`]); `applied` when the estimate includes it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lateral_slip: Option<crate::LateralSlip>,
    /// With held parameters or priors: how the estimate moves per unit of the
    /// laser's range scale, in the order of [`crate::PARAMETER_NAMES`] (held entries
    /// 0; see `range_scale.rs`). `None` when every parameter is free: then it is
    /// [`crate::range_scale_direction`] of the estimate, whatever later replaces the
    /// estimate (the slide's seven-parameter fit). See
    /// [`Calibration::scale_direction`].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub range_scale_response: Option<[f64; 6]>,
}

impl Calibration {
    /// How the estimate moves per unit of the laser's range scale: the range scale's
    /// covariance lies along it ([`crate::with_scale_along`]).
    pub fn scale_direction(&self) -> [f64; 6] {
        self.range_scale_response
            .unwrap_or_else(|| crate::range_scale_direction(&self.params))
    }
}

/// Closed form (step 1 and step 2) on all `samples`, without trimming: the
/// papers' estimate, or the "not excited" error.
pub fn closed_form(samples: &[Sample], use_profile: bool) -> Result<ClosedForm, SolveError> {
    for (k, s) in samples.iter().enumerate() {
        s.check(k)?;
    }
    closed_form_packed(
        &Packed::all(samples, use_profile),
        None,
        &Constraints::default(),
        &mut Scratch::default(),
    )
}

/// Buffers reused by the closed-form solves of successive trimming rounds.
#[derive(Default)]
struct Scratch {
    /// Per-sample odometry for `b = 1`.
    unit: Vec<RawOdometry>,
    /// Residuals `ŝ_pred − ŝ` of the last solve.
    residuals: Vec<[f64; 3]>,
}

/// Closed form on packed samples with the held parameters of `held` (priors are
/// ignored here); leaves the residuals `ŝ_pred − ŝ` in `scratch.residuals`.
fn closed_form_packed(
    samples: &[Packed],
    theta_weights: Option<&[f64]>,
    held: &Constraints,
    scratch: &mut Scratch,
) -> Result<ClosedForm, SolveError> {
    let s1 = step1(samples, theta_weights);
    if (0..6).any(|i| held.is_held(i)) {
        return closed_form_held(samples, theta_weights, held, s1, scratch);
    }
    if s1.condition.is_nan()
        || s1.condition > STEP1_SINGULAR_CONDITION
        || !s1.j21.is_finite()
        || !s1.j22.is_finite()
    {
        return Err(step1_not_excited(samples, &s1));
    }
    let m = build_m(samples, s1.j21, s1.j22, &mut scratch.unit);
    let s2 = match solve_m(&m) {
        Some(s2) if s2.a_condition_scaled <= A_SINGULAR_CONDITION && s2.b > 0.0 => s2,
        Some(s2) => {
            return Err(step2_not_excited(
                samples,
                &s1,
                Some(s2.a_weakest_direction),
            ))
        }
        None => return Err(step2_not_excited(samples, &s1, None)),
    };
    let params = Params {
        r_l: -s2.b * s1.j21,
        r_r: s2.b * s1.j22,
        b: s2.b,
        laser: s2.laser,
    };
    // Residuals ŝ_pred − ŝ from the cached unit odometry: o = (b·c_x, b·c_y, oθ).
    let pred = Predictor::new(&params, true);
    scratch.residuals.clear();
    scratch.residuals.extend(
        samples.iter().zip(&scratch.unit).map(|(s, u)| {
            residual_of(pred.sensor_from_odometry(&u.scale_translation(s2.b)), &s.sm)
        }),
    );
    Ok(ClosedForm {
        params,
        step1: s1,
        step2: s2,
    })
}

/// Residuals `ŝ_pred − ŝ` of packed samples at `params`.
fn residuals_at(samples: &[Packed], params: &Params) -> Vec<[f64; 3]> {
    let pred = Predictor::new(params, true);
    samples
        .iter()
        .map(|s| residual_of(pred.predict_pieces(s.pieces()), &s.sm))
        .collect()
}

/// The samples of `free` (each with a [`Sample::free_direction`]) to keep beside the
/// samples that fix every direction, whose residuals at the closed form `params`
/// are `fixed_residuals`: under `trim`, a free sample is kept when its residual,
/// whitened by the fixed residuals' robust location and scale and with its free
/// direction projected out, has a squared norm within the χ² rule's threshold
/// ([`CHI2_3DOF_9999`] for the other rules; every one without trimming).
fn free_kept<'a>(
    free: &[Packed<'a>],
    params: &Params,
    fixed_residuals: &[[f64; 3]],
    trim: Trim,
) -> Vec<Packed<'a>> {
    let threshold = match trim {
        Trim::None => return free.to_vec(),
        Trim::Chi2 { threshold, .. } => threshold,
        Trim::Icra { .. } | Trim::Tro { .. } => CHI2_3DOF_9999,
    };
    let (loc, scale) = robust_location_scale(fixed_residuals);
    free.iter()
        .zip(residuals_at(free, params))
        .filter(|(p, e)| {
            let Some(d) = p.free_direction else {
                return true;
            };
            // Whitened, then projected as `Sample::measured_part` does.
            let z: [f64; 3] = std::array::from_fn(|c| (e[c] - loc[c]) / scale[c]);
            let d: [f64; 3] = std::array::from_fn(|c| d[c] / scale[c]);
            let q: f64 = measured_part(z, Some(d)).iter().map(|v| v * v).sum();
            q <= threshold
        })
        .map(|(p, _)| *p)
        .collect()
}

/// The closed form with some parameters held (see [`crate::partial`]).
fn closed_form_held(
    samples: &[Packed],
    theta_weights: Option<&[f64]>,
    held: &Constraints,
    s1: Step1,
    scratch: &mut Scratch,
) -> Result<ClosedForm, SolveError> {
    let (j21, j22) = step1_held(samples, theta_weights, held, &s1)?;
    let s2 = step2_held(samples, j21, j22, held, &s1, &mut scratch.unit)?;
    let params = held.apply_held(&Params {
        r_l: -s2.b * j21,
        r_r: s2.b * j22,
        b: s2.b,
        laser: s2.laser,
    });
    let pred = Predictor::new(&params, true);
    scratch.residuals.clear();
    scratch.residuals.extend(
        samples
            .iter()
            .map(|s| residual_of(pred.predict_pieces(s.pieces()), &s.sm)),
    );
    Ok(ClosedForm {
        params,
        step1: Step1 { j21, j22, ..s1 },
        step2: s2,
    })
}

/// `H⁻¹ (M + P) H⁻¹`: the covariance of the estimate when the score `Σ GᵀWe` has
/// covariance `M` (not `H`: samples sharing scans) and the priors add their
/// information `P`. `inverse` is `H⁻¹` with held rows zero.
fn sandwich(
    inverse: &[[f64; 6]; 6],
    score: &[[f64; 6]; 6],
    constraints: &Constraints,
) -> [[f64; 6]; 6] {
    let mut meat = *score;
    for (i, c) in constraints.0.iter().enumerate() {
        if let Constraint::Prior { sigma, .. } = c {
            meat[i][i] += 1.0 / (sigma * sigma);
        }
    }
    let hi = SMatrix::<f64, 6, 6>::from_fn(|i, j| inverse[i][j]);
    let m = SMatrix::<f64, 6, 6>::from_fn(|i, j| meat[i][j]);
    let c = hi * m * hi;
    std::array::from_fn(|i| std::array::from_fn(|j| 0.5 * (c[(i, j)] + c[(j, i)])))
}

/// The covariance with the rows and columns of held parameters set to zero.
fn zero_held_rows(mut c: [[f64; 6]; 6], constraints: &Constraints) -> [[f64; 6]; 6] {
    for i in (0..6).filter(|&i| constraints.is_held(i)) {
        for j in 0..6 {
            c[i][j] = 0.0;
            c[j][i] = 0.0;
        }
    }
    c
}

/// Calibrates: the six parameters, their covariance and the observability report.
pub fn calibrate(samples: &[Sample], options: &SolveOptions) -> Result<Calibration, SolveError> {
    for (k, s) in samples.iter().enumerate() {
        s.check(k)?;
    }
    if samples.len() < MIN_SAMPLES {
        return Err(SolveError::TooFewSamples {
            got: samples.len(),
            needed: MIN_SAMPLES,
            stage: "input".into(),
        });
    }
    let sample_weights = NoiseWeights::from_samples(samples);
    let theta_weights: Option<Vec<f64>> = match (&sample_weights, options.weighted_step1) {
        (Some(_), true) => Some(
            samples
                .iter()
                .map(|s| s.sm_cov.map_or(1.0, |c| 1.0 / c[2][2]))
                .collect(),
        ),
        _ => None,
    };
    let tw = theta_weights.as_deref();

    // The closed form, the trimming and the noise estimate use the samples that fix
    // every direction of ŝ: along a free direction ŝ is not a measurement.
    let (mut active, free): (Vec<Packed>, Vec<Packed>) = Packed::all(samples, options.use_profile)
        .into_iter()
        .partition(|p| p.free_direction.is_none());
    if active.len() < MIN_SAMPLES {
        return Err(SolveError::TooFewSamples {
            got: active.len(),
            needed: MIN_SAMPLES,
            stage: "samples that fix every direction of ŝ (the others leave one free)".into(),
        });
    }
    let mut samples_per_round = vec![active.len()];
    let mut scratch = Scratch::default();
    // Held parameters enter the closed form; priors only the refinement, unless the
    // data alone do not determine the closed form: then it holds the priors' means.
    let constraints = options.constraints;
    let mut held = constraints;
    let mut cf = match closed_form_packed(&active, tw, &held, &mut scratch) {
        Err(SolveError::NotExcited { .. }) if constraints.has_priors() => {
            held = constraints.priors_held();
            closed_form_packed(&active, tw, &held, &mut scratch)?
        }
        other => other?,
    };
    // Scan-matching noise as the original package estimates it: residuals of the
    // first (untrimmed) closed-form estimate over the samples kept after the first
    // trimming round (all samples when there is no trimming).
    let mut noise_residuals: Option<Vec<[f64; 3]>> = None;
    // The same samples' residuals at the estimate re-solved without the first round's
    // outliers: when an outlier pulled the first estimate, these are the noise.
    let mut resolved_residuals: Option<Vec<[f64; 3]>> = None;
    // Rules that judge every sample at the current estimate (samples may come back)
    // stop when the kept set no longer changes; the others drop from the active set.
    let whole = options.trim.judges_all_samples();
    let all = if whole { active.clone() } else { Vec::new() };
    let mut previous = vec![true; all.len()];
    for round in 0..options.trim.rounds() {
        let at_estimate;
        let residuals: &[[f64; 3]] = if whole {
            at_estimate = residuals_at(&all, &cf.params);
            &at_estimate
        } else {
            &scratch.residuals
        };
        let keep = options.trim.keep(residuals);
        if round == 0 {
            noise_residuals = Some(
                residuals
                    .iter()
                    .zip(&keep)
                    .filter(|(_, &k)| k)
                    .map(|(r, _)| *r)
                    .collect(),
            );
        }
        if whole {
            if keep == previous {
                break;
            }
            active = all
                .iter()
                .zip(&keep)
                .filter(|(_, &k)| k)
                .map(|(p, _)| *p)
                .collect();
            previous = keep;
        } else {
            let mut kept = keep.iter();
            active.retain(|_| kept.next().copied().unwrap_or(false));
        }
        samples_per_round.push(active.len());
        if active.len() < MIN_SAMPLES {
            return Err(SolveError::TooFewSamples {
                got: active.len(),
                needed: MIN_SAMPLES,
                stage: format!("after trimming round {}", round + 1),
            });
        }
        cf = closed_form_packed(&active, tw, &held, &mut scratch)?;
        if round == 0 {
            resolved_residuals = Some(residuals_at(&active, &cf.params));
        }
    }
    let sm_sigma = match options.sigma_from {
        SigmaEstimate::FirstRound => first_round_sigmas(
            noise_residuals.as_deref().unwrap_or(&scratch.residuals),
            resolved_residuals.as_deref(),
        ),
        SigmaEstimate::FinalSet => residual_sigmas(&scratch.residuals),
    };

    // The samples that leave a direction free join for the refinement, unless their
    // residual in the directions they fix is an outlier at the closed form.
    active.extend(free_kept(
        &free,
        &cf.params,
        &scratch.residuals,
        options.trim,
    ));
    active.sort_unstable_by_key(|p| p.index);
    // Without weights of their own, the residuals' level shaped per sample by the
    // matcher's covariance of it, when the samples carry one (the samples used give
    // the typical match).
    let shapes = match sample_weights {
        Some(_) => None,
        None => NoiseShapes::of(samples, &active),
    };
    let weight_level = shapes
        .as_ref()
        .map(|m| m.level(&active, &residuals_at(&active, &cf.params), 1.0));
    let shaped = shapes
        .as_ref()
        .zip(weight_level)
        .and_then(|(m, level)| m.information(level));
    let (weights, noise_source) = match (sample_weights, shaped) {
        (Some(w), _) => (w, NoiseSource::SampleCovariance),
        (None, Some(info)) => (NoiseWeights::PerSample(info), NoiseSource::Shaped),
        (None, None) => (NoiseWeights::from_sigmas(sm_sigma), NoiseSource::Estimated),
    };
    let shapes = shapes.filter(|_| noise_source == NoiseSource::Shaped);
    let weights = weights.with_free_directions(samples);

    // The last pass of the refinement (or one pass at the closed form) gives the
    // cost and the Fisher information at the estimate.
    let (params, refinement, cost_before, cost_after, information) = if options.refine {
        let (r, h) = refine(&active, &cf.params, &weights, &constraints);
        (r.params, Some(r), r.cost_before, r.cost_after, h)
    } else {
        let ne = constrained_normal_equations(&active, &cf.params, &weights, &constraints);
        (cf.params, None, ne.cost, ne.cost, ne.h)
    };
    if !params.to_vector().iter().all(|v| v.is_finite()) {
        return Err(SolveError::Numerical(format!(
            "the estimate is not finite ({params:?})"
        )));
    }

    // Motion classes with the estimated radii; for the "not excited" errors, where
    // the estimate is not trustworthy, with equal radii.
    let motion_equal_radii = || MotionContent::classify(&active, 1.0, 1.0);
    // The covariance takes the noise as the blend of the level and the shapes that
    // the residuals support (`crate::noise_shape`).
    let noise_shaping = shapes.as_ref().zip(weight_level).map(|(m, weight_level)| {
        let residuals = residuals_at(&active, &params);
        let share = m.share_followed(&active, &residuals, weight_level);
        NoiseShaping {
            weight_level,
            share,
            level: m.level(&active, &residuals, share),
        }
    });
    let noise_maps = shapes
        .as_ref()
        .zip(noise_shaping.as_ref())
        .map(|(m, n)| m.covariance_maps(n));
    let (covariance, shared_scan_noise, inverse) = match invert_information(&information) {
        Inversion::Covariance(c) => {
            let inverse = zero_held_rows(*c, &constraints);
            let bias = bias_covariance(&active, &params, &weights, &inverse, options.matcher_bias);
            let (random, model) =
                match score_covariance(&active, &params, &weights, &inverse, noise_maps.as_deref())
                {
                    Some((score, model)) => (sandwich(&inverse, &score, &constraints), Some(model)),
                    None => match noise_maps.as_deref().zip(noise_shaping) {
                        Some((maps, n)) => {
                            let score =
                                independent_score(&active, &params, &weights, maps, n.level);
                            (sandwich(&inverse, &score, &constraints), None)
                        }
                        None => (inverse, None),
                    },
                };
            (
                std::array::from_fn(|i| std::array::from_fn(|j| random[i][j] + bias[i][j])),
                model,
                inverse,
            )
        }
        Inversion::Singular(null) => {
            return Err(information_not_excited(
                null_direction_names(&null),
                &motion_equal_radii(),
            ))
        }
    };
    // A parameter that one sample determines almost alone is not well determined:
    // nothing in the data checks that sample.
    let mut one_sample = resting_on_one_sample(&active, &params, &weights, &inverse);
    let reports = judged(&params, &covariance, &constraints, &mut one_sample);
    let not_excited: Vec<String> = reports
        .iter()
        .filter(|r| r.verdict == Verdict::NotExcited)
        .map(|r| r.name.clone())
        .collect();
    if !not_excited.is_empty() && !options.accept_weak {
        return Err(information_not_excited(not_excited, &motion_equal_radii()));
    }
    let motion = MotionContent::classify(&active, params.r_l, params.r_r);
    let observability = Observability {
        step1_condition: cf.step1.condition,
        a_condition: cf.step2.a_condition,
        a_condition_scaled: cf.step2.a_condition_scaled,
        sentence: full_sentence(&reports, &motion, &one_sample),
        parameters: reports,
        motion,
        wheel_signs: wheel_signs(&params),
        one_sample,
    };
    let mut used = vec![false; samples.len()];
    for p in &active {
        used[p.index] = true;
    }
    let range_scale_response = (!constraints.is_empty()).then(|| {
        crate::range_scale::constrained_scale_direction(&active, &params, &weights, &constraints)
    });
    Ok(Calibration {
        range_scale_response,
        j: params.j(),
        params,
        closed_form: cf.params,
        covariance,
        sm_sigma,
        noise_source,
        samples_used: active.len(),
        used,
        samples_per_round,
        cost_before,
        cost_after,
        reduced_chi2: cost_after / (3 * active.len()).saturating_sub(6).max(1) as f64,
        refinement,
        observability,
        shared_scan_noise,
        noise_shaping,
        lateral_slip: None,
    })
}
