//! Parameters that rest on one sample.
//!
//! When a single sample carries most of the information about a parameter (the one
//! spin in place of a log driven straight, the one pair matched in a turn), its σ is
//! honest only if that sample is right, and nothing in the data can check it: the
//! sample fits its own direction exactly, so no residual, outlier rule or consistency
//! check sees its error. Such a parameter is not "well determined", whatever its σ.
//!
//! For each sample k the parameter's variance without it follows from the
//! covariance `C = F⁻¹` by the Sherman–Morrison–Woodbury identity,
//! `C₋ₖ = C + C Gₖᵀ (Wₖ⁻¹ − Gₖ C Gₖᵀ)⁻¹ Gₖ C`, a 3×3 inversion per sample; a
//! parameter whose σ would grow more than [`ONE_SAMPLE_SIGMA_RATIO`]-fold without
//! one sample rests on it; when that sample is also what makes it "well determined"
//! (without it, its σ would fail the verdict's threshold), it is judged weak.

use crate::kinematics::Predictor;
use crate::noise::NoiseWeights;
use crate::packed::Packed;
use crate::params::{Params, PARAMETER_NAMES};
use nalgebra::{Matrix3, SMatrix};
use serde::Serialize;

/// A parameter whose σ would grow more than this factor without one sample rests on
/// that sample (the sample carries more than 1 − 1/ratio² = 75 % of the information
/// about it).
pub const ONE_SAMPLE_SIGMA_RATIO: f64 = 2.0;

/// A parameter that one sample determines almost alone.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct OneSampleSupport {
    /// The parameter's name (`r_L`, `r_R`, `b`, `l_x`, `l_y`, `l_theta`).
    pub parameter: String,
    /// The sample's index among the samples given to the solver.
    pub sample: usize,
    /// Its scan timestamps, when known (s).
    pub scan_times: Option<[f64; 2]>,
    /// How many times larger the parameter's σ would be without the sample (from
    /// the inverse Fisher information); `None` when the rest of the data do not
    /// determine it at all.
    pub sigma_ratio: Option<f64>,
    /// The sample decides the verdict: with it the parameter would be "well
    /// determined", without it not; the parameter is then judged weak.
    pub decides_verdict: bool,
}

/// The parameters (not held: zero variance in `inverse`) that one sample of `active`
/// determines almost alone, with that sample; `inverse` is the inverse Fisher
/// information at `params` with `weights`.
pub(crate) fn resting_on_one_sample(
    active: &[Packed],
    params: &Params,
    weights: &NoiseWeights,
    inverse: &[[f64; 6]; 6],
) -> Vec<OneSampleSupport> {
    let c = SMatrix::<f64, 6, 6>::from_fn(|i, j| inverse[i][j]);
    let pred = Predictor::new(params, true);
    // Per parameter: the largest variance ratio found, and its sample.
    let mut worst: [(f64, Option<usize>); 6] = [(1.0, None); 6];
    for (k, s) in active.iter().enumerate() {
        let (_, jac) = pred.predict_with_jacobian_pieces(s.pieces());
        let g = SMatrix::<f64, 3, 6>::from_fn(|r, i| jac[r][i]);
        let Some(noise) = sample_covariance(weights, s.index) else {
            continue;
        };
        let b = g * c; // 3×6
        let m = noise - b * g.transpose();
        let m = 0.5 * (m + m.transpose());
        let eig = m.symmetric_eigen();
        let scale = noise.diagonal().max().max(f64::MIN_POSITIVE);
        for p in 0..6 {
            let var = c[(p, p)];
            if var <= 0.0 {
                continue;
            }
            // [Bᵀ M⁻¹ B]_pp over M's eigenvectors; a (near) zero eigenvalue: the rest
            // of the data do not determine the direction this sample alone does.
            let mut extra = 0.0;
            for (i, &lambda) in eig.eigenvalues.iter().enumerate() {
                let u = eig.eigenvectors.column(i);
                let proj: f64 = (0..3).map(|r| u[r] * b[(r, p)]).sum();
                if proj * proj <= 1e-12 * var * scale {
                    continue;
                }
                if lambda <= 1e-9 * scale {
                    extra = f64::INFINITY;
                    break;
                }
                extra += proj * proj / lambda;
            }
            let ratio = (var + extra) / var;
            if ratio > worst[p].0 {
                worst[p] = (ratio, Some(k));
            }
        }
    }
    let threshold = ONE_SAMPLE_SIGMA_RATIO * ONE_SAMPLE_SIGMA_RATIO;
    worst
        .iter()
        .enumerate()
        .filter_map(|(p, &(ratio, k))| {
            let k = k?;
            (ratio > threshold).then(|| OneSampleSupport {
                parameter: PARAMETER_NAMES[p].to_string(),
                sample: active[k].index,
                scan_times: active[k].scan_times,
                sigma_ratio: ratio.is_finite().then(|| ratio.sqrt()),
                decides_verdict: false,
            })
        })
        .collect()
}

/// The covariance `W⁻¹` of sample `index`'s ŝ under `weights`; `None` when `W` is
/// singular (a free direction) or not finite.
fn sample_covariance(weights: &NoiseWeights, index: usize) -> Option<Matrix3<f64>> {
    match weights {
        NoiseWeights::Shared(w) => Some(Matrix3::from_diagonal(&nalgebra::Vector3::new(
            1.0 / w[0],
            1.0 / w[1],
            1.0 / w[2],
        ))),
        NoiseWeights::PerSample(info) => {
            let w = info.get(index)?;
            let w = Matrix3::from_fn(|r, c| w[r][c]);
            // A sample with a free direction (no weight along it: singular) determines
            // nothing along it; it is left out.
            let eigenvalues = w.symmetric_eigenvalues();
            let largest = eigenvalues.max();
            let smallest = eigenvalues.min();
            if smallest.is_nan() || smallest <= 1e-12 * largest {
                return None;
            }
            w.try_inverse()
        }
    }
}

/// The sentence part that names those deciding a verdict, grouped by sample: "b and
/// l_x rest on one sample (scans at 31.10–31.50 s): without it their σ would be 37× and 78× larger,
/// and nothing else in the data checks it".
pub fn describe(supports: &[OneSampleSupport]) -> String {
    let supports: Vec<&OneSampleSupport> = supports.iter().filter(|s| s.decides_verdict).collect();
    let mut samples: Vec<usize> = supports.iter().map(|s| s.sample).collect();
    samples.sort_unstable();
    samples.dedup();
    samples
        .iter()
        .map(|&k| {
            let these: Vec<&&OneSampleSupport> =
                supports.iter().filter(|s| s.sample == k).collect();
            let names: Vec<&str> = these.iter().map(|s| s.parameter.as_str()).collect();
            let at = match these[0].scan_times {
                Some([t0, t1]) => format!("scans at {t0:.2}–{t1:.2} s"),
                None => format!("sample {k}"),
            };
            let growth: Vec<String> = these
                .iter()
                .map(|s| match s.sigma_ratio {
                    Some(r) => format!("{r:.0}×"),
                    None => "infinitely".to_string(),
                })
                .collect();
            let (verb, their) = if names.len() == 1 {
                ("rests", "its")
            } else {
                ("rest", "their")
            };
            format!(
                "{} {verb} on one sample ({at}): without it {their} σ would be {} larger, \
                 and nothing else in the data checks that sample",
                join(&names),
                join(&growth.iter().map(String::as_str).collect::<Vec<_>>())
            )
        })
        .collect::<Vec<_>>()
        .join("; ")
}

/// "a", "a and b", "a, b and c".
fn join(items: &[&str]) -> String {
    match items {
        [] => String::new(),
        [one] => one.to_string(),
        [rest @ .., last] => format!("{} and {last}", rest.join(", ")),
    }
}
