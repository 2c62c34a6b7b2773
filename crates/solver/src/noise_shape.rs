//! Each sample's noise shaped as the scan matcher's covariance of it says.
//!
//! The residuals measure the noise's level, one per component (x, y, θ); they
//! cannot tell which samples are the noisy ones. The matcher can: its covariance
//! of `ŝ` is large for a spin matched through intermediate scans, for a pair that
//! shares few points. Each sample's noise is taken as the typical match's level
//! shaped by the matcher's covariance relative to the typical match's,
//! `Σ_k = M_k Σ̄ M_kᵀ` with `Σ̄ = diag(σ²)` and `M_k = diag(σ) L_k diag(1/σ)`,
//! `L_k L_kᵀ` the matcher's covariance divided, per component, by its median over
//! the samples used; `σ` is measured on the residuals divided by their shapes
//! ([`NoiseShaping::weight_level`]). The samples are weighted by `Σ_k⁻¹`.
//!
//! Weighted so, the simulated realistic presets (30 logs × 120 s each) calibrate
//! 1.1–2.2× nearer the truth than with one level for all (ℓx on the TurtleBot 4,
//! 1.19 → 0.67 mm RMS; the Neato's b, 2.25 → 1.58 mm; the rover's ℓθ, 2.83 → 1.26
//! mrad), and a short log's few spins, which the matcher finds 3–5× noisier than
//! its straights, no longer decide the laser's offsets alone.
//!
//! The matcher's covariance predicts the residuals only in part, and not evenly: its
//! shape (which direction of a match is the well-determined one) holds, its size
//! (how much noisier one match is than another) is overstated. Measured against the
//! simulator's truth on 60 MinesRover logs, along each match's best-determined axis
//! the squared error over the shape's variance was 1.23, 1.00, 0.87, 0.62 from the
//! smallest quarter of the matches to the largest, while the error's whole
//! Mahalanobis size over three went 1.34 → 0.65 (docs/benchmarks.md, stop 52). How
//! far the sizes hold is measured on the log: the share `w` of the spread in sizes
//! `s_k = det(R_k)^⅓` for which the residuals, whitened by their shapes at the
//! typical size, squared and divided by `(1 − w) + w·s_k`, have the same median among
//! the largest matches as among the smallest ([`NoiseShapes::share_followed`]). The
//! covariance of the estimate takes each sample's noise as its shape at that blend of
//! sizes, `R̃_k = R_k·((1 − w) + w·s_k)/s_k`: the shared-scan model
//! (`crate::shared_scans`) is estimated on the residuals whitened by its map
//! `M̃_k⁻¹`, where one level holds, and its score mapped back by `M̃_k`. Weighting by
//! the matcher's full covariances is what makes the estimate precise; taking their
//! sizes at their word in its covariance would make it overconfident (the
//! TurtleBot 4's ℓθ at 1.35 RMS error/σ). An earlier blend per component,
//! `(I − W) + W^½ R_k W^½`, lost the shapes too: along each match's best-determined
//! axis, where the weights trust it most, it took the noise 2–2.7× too large, and
//! the realistic presets' σ were wide (the rover's ℓθ and ℓy at 0.53 and 0.63 RMS
//! error/σ).

use crate::calibrate::{Calibration, NoiseSource};
use crate::kinematics::Predictor;
use crate::noise::NoiseWeights;
use crate::packed::Packed;
use crate::params::Params;
use crate::sample::Sample;
use crate::shared_scans::weight;
use nalgebra::{Matrix3, SMatrix, Vector3};
use serde::Serialize;

/// Fewest samples with the matcher's covariance for their shapes to be used: the
/// typical match is a median over them.
pub const MIN_SHAPED_SAMPLES: usize = 10;

/// Each sample's covariance as the matcher gives it, relative to the typical match:
/// divided, per component, by its median over the samples used.
#[derive(Debug, Clone)]
pub(crate) struct NoiseShapes {
    /// Per sample (indexed like the samples given to the solver), `R_k`; `None` for a
    /// sample without a usable covariance (it keeps the level).
    relative: Vec<Option<Matrix3<f64>>>,
}

impl NoiseShapes {
    /// The shapes of `samples`, the typical match taken over `active`; `None` when
    /// fewer than [`MIN_SHAPED_SAMPLES`] of those carry the matcher's covariance
    /// ([`Sample::matcher_cov`]). A covariance that is not finite or has a diagonal
    /// entry that is not positive is not used, nor that of a sample that leaves a
    /// direction free ([`Sample::free_direction`]).
    pub(crate) fn of(samples: &[Sample], active: &[Packed]) -> Option<Self> {
        // A sample that leaves a direction free is weighted without it: the matcher's
        // covariance, huge along it, would leak through any difference of the two.
        let covariance = |s: &Sample| {
            if s.free_direction.is_some() {
                return None;
            }
            let c = s.matcher_cov?;
            let c = Matrix3::from_fn(|r, k| c[r][k]);
            (c.iter().all(|v| v.is_finite()) && (0..3).all(|d| c[(d, d)] > 0.0)).then_some(c)
        };
        let diagonals: Vec<Vector3<f64>> = active
            .iter()
            .filter_map(|p| covariance(samples.get(p.index)?))
            .map(|c| c.diagonal())
            .collect();
        if diagonals.len() < MIN_SHAPED_SAMPLES {
            return None;
        }
        let unit = Vector3::from_fn(|d, _| {
            let mut v: Vec<f64> = diagonals.iter().map(|c| c[d]).collect();
            let mid = v.len() / 2;
            1.0 / v.select_nth_unstable_by(mid, f64::total_cmp).1.sqrt()
        });
        let unit = Matrix3::from_diagonal(&unit);
        Some(NoiseShapes {
            relative: samples
                .iter()
                .map(|s| covariance(s).map(|c| unit * c * unit))
                .collect(),
        })
    }

    /// Per sample, the map `M_k = diag(σ) L_k diag(1/σ)` from a noise of the typical
    /// match's `level` (σ) to the sample's own, `L_k L_kᵀ = R_k·((1 − w) + w·s_k)/s_k`:
    /// the matcher's shape `R_k` kept, its size `s_k = det(R_k)^⅓` blended with the
    /// typical match's by `share` (`w`; 1: the matcher's covariance as it is, 0: its
    /// shape at the typical size). The identity for a sample without a shape or whose
    /// shape is not positive definite.
    pub(crate) fn maps(&self, level: [f64; 3], share: f64) -> Vec<Matrix3<f64>> {
        let sigma = Vector3::from(level);
        let to_level = Matrix3::from_diagonal(&sigma);
        let from_level = Matrix3::from_diagonal(&sigma.map(|s| 1.0 / s));
        self.relative
            .iter()
            .map(|r| {
                r.and_then(|r| (r * size_blend(&r, share)?).cholesky())
                    .map_or_else(Matrix3::identity, |l| to_level * l.l() * from_level)
            })
            .collect()
    }

    /// The maps the covariance of an estimate takes each sample's noise through
    /// ([`NoiseShapes::maps`] at the blend `shaping` measured).
    pub(crate) fn covariance_maps(&self, shaping: &NoiseShaping) -> Vec<Matrix3<f64>> {
        self.maps(shaping.level, shaping.share)
    }

    /// The information `(M_k Σ̄ M_kᵀ)⁻¹` of each sample's noise under the matcher's
    /// full shapes, `Σ̄ = diag(level²)` (the typical match's σ); `None` when `level` has
    /// a component that is not positive or some noise is singular.
    pub(crate) fn information(&self, level: [f64; 3]) -> Option<Vec<[[f64; 3]; 3]>> {
        if level.iter().any(|s| !(s.is_finite() && *s > 0.0)) {
            return None;
        }
        let typical = Matrix3::from_diagonal(&Vector3::from(level.map(|s| s * s)));
        self.maps(level, 1.0)
            .iter()
            .map(|m| {
                let info = (m * typical * m.transpose()).try_inverse()?;
                let info = 0.5 * (info + info.transpose());
                Some(std::array::from_fn(|r| {
                    std::array::from_fn(|c| info[(r, c)])
                }))
            })
            .collect()
    }

    /// The share `w` of the spread in the matches' sizes that the residuals follow:
    /// the `w` in `[0, 1]` for which the residuals (`residuals`, one per sample of
    /// `active`), each whitened by its shape at the typical size (`level`, the typical
    /// match's σ), squared and divided by `(1 − w) + w·s_k`, have the same median among
    /// the samples the matcher finds largest (its top quarter by `s_k`) as among the
    /// smallest (its bottom quarter). Medians, because a few confident wrong matches
    /// would decide a mean. 0 where the sizes do not vary; samples that leave a
    /// direction free are left out (their residual along it is no noise).
    pub(crate) fn share_followed(
        &self,
        active: &[Packed],
        residuals: &[[f64; 3]],
        level: [f64; 3],
    ) -> f64 {
        if level.iter().any(|s| !(s.is_finite() && *s > 0.0)) {
            return 0.0;
        }
        let from_level = Matrix3::from_diagonal(&Vector3::from(level.map(|s| 1.0 / s)));
        let mut points: Vec<(f64, f64)> = active
            .iter()
            .zip(residuals)
            .filter(|(p, _)| p.free_direction.is_none())
            .filter_map(|(p, e)| {
                let r = self.relative.get(p.index)?.as_ref()?;
                let size = size_of(r)?;
                let e = from_level * Vector3::from(*e);
                let whitened = (r / size).cholesky()?.solve(&e);
                Some((size, e.dot(&whitened) / 3.0))
            })
            .collect();
        if points.len() < MIN_SHAPED_SAMPLES {
            return 0.0;
        }
        points.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
        let quarter = points.len() / 4;
        let (low, high) = (&points[..quarter], &points[points.len() - quarter..]);
        // The sizes vary between the quarters (else nothing to follow).
        if high[high.len() / 2].0.partial_cmp(&low[low.len() / 2].0)
            != Some(std::cmp::Ordering::Greater)
        {
            return 0.0;
        }
        // ln(median of the large quarter / median of the small one), falling in w.
        let gap = |w: f64| {
            let scaled = |part: &[(f64, f64)]| {
                let mut v: Vec<f64> = part.iter().map(|&(s, q)| q / (1.0 - w + w * s)).collect();
                let mid = v.len() / 2;
                *v.select_nth_unstable_by(mid, f64::total_cmp).1
            };
            (scaled(high) / scaled(low)).ln()
        };
        if gap(0.0).partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
            return 0.0;
        }
        if gap(1.0) >= 0.0 {
            return 1.0;
        }
        let (mut lo, mut hi) = (0.0, 1.0);
        for _ in 0..30 {
            let mid = 0.5 * (lo + hi);
            if gap(mid) > 0.0 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        0.5 * (lo + hi)
    }

    /// Per component, the noise's level under the blend `share`: the root mean square
    /// of the residuals (`residuals`, one per sample of `active`) each divided by its
    /// relative standard deviation under the blend ([`NoiseShapes::maps`]), over
    /// `n − 2` (six parameters fitted on three components). Samples that leave a
    /// direction free are left out.
    pub(crate) fn level(&self, active: &[Packed], residuals: &[[f64; 3]], share: f64) -> [f64; 3] {
        std::array::from_fn(|c| {
            let scaled: Vec<f64> = active
                .iter()
                .zip(residuals)
                .filter(|(p, _)| p.free_direction.is_none())
                .map(|(p, e)| {
                    let g = self
                        .relative
                        .get(p.index)
                        .and_then(|r| r.as_ref())
                        .and_then(|r| Some(r[(c, c)] * size_blend(r, share)?))
                        .unwrap_or(1.0);
                    e[c] * e[c] / g
                })
                .collect();
            let dof = scaled.len().saturating_sub(2).max(1) as f64;
            (scaled.iter().sum::<f64>() / dof).sqrt()
        })
    }
}

/// The size of a relative covariance: `det(R)^⅓` (1 for the typical match's);
/// `None` when it is not positive and finite.
fn size_of(r: &Matrix3<f64>) -> Option<f64> {
    let det = r.determinant();
    (det.is_finite() && det > 0.0).then(|| det.cbrt())
}

/// The factor `((1 − w) + w·s)/s` that takes `r`, of size `s`, to its size blended
/// with the typical match's by the share `w` (clamped to `[0, 1]`).
fn size_blend(r: &Matrix3<f64>, share: f64) -> Option<f64> {
    let w = share.clamp(0.0, 1.0);
    let s = size_of(r)?;
    Some((1.0 - w + w * s) / s)
}

/// How a solve shaped its samples' noise (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct NoiseShaping {
    /// The typical match's noise σ (x, y, θ; m, m, rad) the samples were weighted by,
    /// each shaped by the matcher's covariance of it: the residuals at the closed
    /// form divided by their shapes.
    pub weight_level: [f64; 3],
    /// The share of the spread in the matches' sizes (`det^⅓` of the matcher's
    /// covariance) that the residuals follow, measured on the residuals at the
    /// estimate (0: every match at the typical size, its shape kept; 1: the matcher's
    /// covariance as it is).
    pub share: f64,
    /// The noise's level under that blend (x, y, θ): what the covariance of the
    /// estimate takes each sample's noise as, with the blended shape.
    pub level: [f64; 3],
}

/// `Σ_k G_kᵀ W_k (M_k Σ M_kᵀ) W_k G_k` over `active` at `params`, `Σ = diag(level²)`
/// and `M_k` = `maps` (per sample index): the score's covariance of samples that are
/// independent, with the noise the maps give them; held parameters and priors are
/// the sandwich's business.
pub(crate) fn independent_score(
    active: &[Packed],
    params: &Params,
    weights: &NoiseWeights,
    maps: &[Matrix3<f64>],
    level: [f64; 3],
) -> [[f64; 6]; 6] {
    let pred = Predictor::new(params, true);
    let level = Matrix3::from_diagonal(&Vector3::from(level.map(|s| s * s)));
    let mut meat = SMatrix::<f64, 6, 6>::zeros();
    for p in active {
        let (_, jac) = pred.predict_with_jacobian_pieces(p.pieces());
        let g = SMatrix::<f64, 3, 6>::from_fn(|r, i| jac[r][i]);
        let gw = g.transpose() * weight(weights, p.index);
        let m = maps.get(p.index).copied().unwrap_or_else(Matrix3::identity);
        meat += gw * (m * level * m.transpose()) * gw.transpose();
    }
    std::array::from_fn(|i| std::array::from_fn(|j| 0.5 * (meat[(i, j)] + meat[(j, i)])))
}

/// The noise shapes `calibration`'s solve weighted `samples` by (the samples it
/// used give the typical match), when it did.
pub(crate) fn shapes_used(calibration: &Calibration, samples: &[Sample]) -> Option<NoiseShapes> {
    if calibration.noise_source != NoiseSource::Shaped {
        return None;
    }
    let used: Vec<Packed> = Packed::all(samples, false)
        .into_iter()
        .filter(|p| calibration.used.get(p.index).copied().unwrap_or(false))
        .collect();
    NoiseShapes::of(samples, &used)
}

/// The weights `calibration`'s solve used for `samples` (`shapes`: [`shapes_used`]),
/// free directions taken out.
pub(crate) fn weights_used(
    calibration: &Calibration,
    samples: &[Sample],
    shapes: Option<&NoiseShapes>,
) -> NoiseWeights {
    let sigma = calibration.sm_sigma;
    let shaped = shapes
        .zip(calibration.noise_shaping)
        .and_then(|(m, n)| m.information(n.weight_level));
    match (calibration.noise_source, shaped) {
        // Every sample carried a covariance, or the solve would not have used them.
        (NoiseSource::SampleCovariance, _) => {
            NoiseWeights::from_samples(samples).unwrap_or_else(|| NoiseWeights::from_sigmas(sigma))
        }
        (NoiseSource::Shaped, Some(info)) => NoiseWeights::PerSample(info),
        (NoiseSource::Estimated | NoiseSource::Shaped, _) => NoiseWeights::from_sigmas(sigma),
    }
    .with_free_directions(samples)
}

#[cfg(test)]
mod tests {
    use super::*;
    use odocal_geom::Pose2;

    fn sample(cov: Option<[f64; 3]>) -> Sample {
        let mut s = Sample::from_rotations(0.4, 1.0, 1.0, Pose2::IDENTITY);
        s.matcher_cov = cov.map(|d| [[d[0], 0.0, 0.0], [0.0, d[1], 0.0], [0.0, 0.0, d[2]]]);
        s
    }

    #[test]
    fn the_typical_match_keeps_the_level_and_a_noisier_one_scales_it() {
        let mut samples: Vec<Sample> = (0..20).map(|_| sample(Some([1e-6, 4e-6, 1e-7]))).collect();
        samples.push(sample(Some([16e-6, 4e-6, 1e-7])));
        samples.push(sample(None));
        let active = Packed::all(&samples, false);
        let sigma = [2e-3, 1e-3, 5e-4];
        let shapes = NoiseShapes::of(&samples, &active).expect("shapes");
        let maps = shapes.maps(sigma, 1.0);
        assert!((maps[0] - Matrix3::identity()).norm() < 1e-12);
        // Four times the typical σ in x, the level in y and θ.
        assert!((maps[20][(0, 0)] - 4.0).abs() < 1e-12);
        assert!((maps[20][(1, 1)] - 1.0).abs() < 1e-12);
        assert_eq!(maps[21], Matrix3::identity());
        // Half the sizes' spread followed: the shape diag(16, 1, 1) kept, its size
        // s = 16^⅓ taken as 0.5 + 0.5·s.
        let half = shapes.maps(sigma, 0.5);
        let s = 16f64.cbrt();
        let f = (0.5 + 0.5 * s) / s;
        assert!((half[20][(0, 0)] - (16.0 * f).sqrt()).abs() < 1e-12);
        assert!((half[20][(1, 1)] - f.sqrt()).abs() < 1e-12);
        // None of it: the typical size, the shape kept.
        let none = shapes.maps(sigma, 0.0);
        assert!((none[20].determinant() - 1.0).abs() < 1e-12);
        assert!((none[20][(0, 0)] / none[20][(1, 1)] - 4.0).abs() < 1e-12);
        let info = shapes.information(sigma).expect("information");
        assert!((info[0][0][0] - 1.0 / 4e-6).abs() < 1e-3);
        assert!((info[20][0][0] - 1.0 / 64e-6).abs() < 1e-3);
    }

    #[test]
    fn the_share_followed_is_measured_on_the_residuals() {
        // Relative variances 1 (the typical match) and 9 in x (size 9^⅓); residuals
        // whose squares follow their sizes fully, half, or not at all, their shapes
        // kept.
        let mut samples = Vec::new();
        for k in 0..40 {
            let g = if k % 3 == 0 { 9.0 } else { 1.0 };
            samples.push(sample(Some([g * 1e-6, 1e-6, 1e-7])));
        }
        let active = Packed::all(&samples, false);
        let shapes = NoiseShapes::of(&samples, &active).expect("shapes");
        let level = [1e-3, 1e-3, 3.16e-4];
        for share in [1.0, 0.5, 0.0] {
            let residuals: Vec<[f64; 3]> = (0..40)
                .map(|k| {
                    let g: f64 = if k % 3 == 0 { 9.0 } else { 1.0 };
                    let s = g.cbrt();
                    [1e-3 * (g * (1.0 - share + share * s) / s).sqrt(), 0.0, 0.0]
                })
                .collect();
            let got = shapes.share_followed(&active, &residuals, level);
            assert!((got - share).abs() < 1e-6, "{got} against {share}");
            // The level: the typical match's σ, whatever the blend.
            let level = shapes.level(&active, &residuals, got);
            assert!(
                (level[0] / 1e-3 - (40.0f64 / 38.0).sqrt()).abs() < 1e-6,
                "{level:?}"
            );
        }
        // Sizes that do not vary: nothing to follow.
        let alike: Vec<Sample> = (0..40).map(|_| sample(Some([1e-6, 1e-6, 1e-7]))).collect();
        let shapes = NoiseShapes::of(&alike, &active).expect("shapes");
        let residuals = vec![[1e-3, 0.0, 0.0]; 40];
        assert_eq!(shapes.share_followed(&active, &residuals, level), 0.0);
    }

    #[test]
    fn too_few_covariances_keep_one_level() {
        let samples: Vec<Sample> = (0..12)
            .map(|k| sample((k < 9).then_some([1e-6, 1e-6, 1e-7])))
            .collect();
        let active = Packed::all(&samples, false);
        assert!(NoiseShapes::of(&samples, &active).is_none());
    }
}
