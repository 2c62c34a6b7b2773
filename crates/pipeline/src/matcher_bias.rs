//! How large the scan matcher's bias on rotations is on a log, for the systematic
//! term of σ ([`odocal_solver::SolveOptions::matcher_bias`]).
//!
//! Measured on simulated Khepera III / URG-04LX logs (3 mm range noise correlated
//! over 4 rays; the matcher's typical range noise on them, `range_noise_m` of the
//! self-check, is 1.71 mm): the rotation of a pair comes out short by a share of
//! 4.3e-5 ± 2.0e-5 (the mean attenuation of |J21| and |J22| over the 19 single rows
//! of Table I), and the translation moves by 31–36 µm per radian of rotation (ℓx,
//! which a spin's translation determines, off by +31 µm on average over those rows
//! and +36 ± 15 µm over 16 seeds of 15-minute k28 logs). Noise-free logs show
//! neither (ℓx within 1.4 µm, ℓθ within 5e-6 rad), and doubling the range noise
//! makes both about 3–4× larger (ℓx +102 ± 25 µm): an errors-in-variables effect
//! that grows with the noise variance. So the bias's standard deviations are these
//! figures scaled by (range noise / 1.71 mm)²; the sign depends on the scene (which
//! side of the laser the walls are), so it is a standard deviation, not a
//! correction.

/// Typical range noise (m) of the logs the figures below were measured on.
pub const REFERENCE_RANGE_NOISE_M: f64 = 1.71e-3;

/// The rotation bias's standard deviation at [`REFERENCE_RANGE_NOISE_M`] (rad/rad).
pub const REFERENCE_ROTATION_BIAS: f64 = 4.0e-5;

/// The translation bias's standard deviation per axis at
/// [`REFERENCE_RANGE_NOISE_M`] (m/rad).
pub const REFERENCE_TRANSLATION_BIAS_M: f64 = 35e-6;

/// The standard deviations `(x, y, θ)` of the matcher's bias on a log whose
/// typical range noise is `range_noise_m` (0 or not finite: no term).
pub fn matcher_bias_sd(range_noise_m: f64) -> [f64; 3] {
    if !(range_noise_m.is_finite() && range_noise_m > 0.0) {
        return [0.0; 3];
    }
    let scale = (range_noise_m / REFERENCE_RANGE_NOISE_M).powi(2);
    let t = REFERENCE_TRANSLATION_BIAS_M * scale;
    [t, t, REFERENCE_ROTATION_BIAS * scale]
}

/// `options` with the matcher-bias term of the log(s) behind `synced` (from its
/// self-check's range noise; none without a self-check).
pub fn with_matcher_bias(
    options: odocal_solver::SolveOptions,
    synced: &crate::synchronized::Synchronized,
) -> odocal_solver::SolveOptions {
    let noise = synced
        .match_self_check
        .as_ref()
        .map_or(0.0, |c| c.range_noise_m);
    odocal_solver::SolveOptions {
        matcher_bias: matcher_bias_sd(noise),
        ..options
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grows_with_the_noise_variance_and_vanishes_without_noise() {
        assert_eq!(matcher_bias_sd(0.0), [0.0; 3]);
        assert_eq!(matcher_bias_sd(f64::NAN), [0.0; 3]);
        let one = matcher_bias_sd(REFERENCE_RANGE_NOISE_M);
        assert_eq!(one, [35e-6, 35e-6, 4e-5]);
        let two = matcher_bias_sd(2.0 * REFERENCE_RANGE_NOISE_M);
        assert!((two[2] / one[2] - 4.0).abs() < 1e-12);
    }
}
