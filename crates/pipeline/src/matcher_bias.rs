//! How large the scan matcher's bias on rotations is on a log, for the systematic
//! term of σ ([`odocal_solver::SolveOptions::matcher_bias`]).
//!
//! Measured on simulated Khepera III / URG-04LX logs (3 mm range noise correlated
//! over 4 rays, rays 2π/1024 apart; the matcher's typical range noise on them,
//! `range_noise_m` of the self-check, is 1.71 mm): the rotation of a pair comes out
//! short by a share of 4.3e-5 ± 2.2e-5 (the mean attenuation of |J21| over the 19
//! single rows of Table I), and the translation moves by 31–36 µm per radian of
//! rotation (ℓx, which a spin's translation determines, off by +33 ± 15 µm on average
//! over those rows and +36 ± 15 µm over 16 seeds of 15-minute k28 logs). Noise-free
//! logs show neither (ℓx within 1.4 µm, ℓθ within 5e-6 rad), and doubling the range
//! noise makes both about 3–5× larger (ℓx +102 ± 25 µm): an errors-in-variables
//! effect of the local lines' tilt noise.
//!
//! That tilt noise is what the figures scale with: the variance of a line fitted to
//! a fixed number of neighbouring points goes as (range noise / ray spacing)² at a
//! given range, so the bias's standard deviations are the figures above times
//! `((noise / 1.71 mm) · (2π/1024 / spacing))²`. The sign depends on the scene
//! (which side of the laser the walls are), so it is a standard deviation, not a
//! correction.

/// Typical range noise (m) of the logs the figures below were measured on.
pub const REFERENCE_RANGE_NOISE_M: f64 = 1.71e-3;

/// Angle between neighbouring rays (rad) of the logs the figures were measured on
/// (the URG-04LX's 2π/1024).
pub const REFERENCE_RAY_SPACING_RAD: f64 = std::f64::consts::TAU / 1024.0;

/// The rotation bias's standard deviation at the reference noise and spacing
/// (rad/rad).
pub const REFERENCE_ROTATION_BIAS: f64 = 4.0e-5;

/// The translation bias's standard deviation per axis at the reference noise and
/// spacing (m/rad).
pub const REFERENCE_TRANSLATION_BIAS_M: f64 = 35e-6;

/// The standard deviations `(x, y, θ)` of the matcher's bias on a log whose typical
/// range noise is `range_noise_m` and whose rays are `ray_spacing_rad` apart (0 or
/// not finite: the reference spacing). No noise: no term.
pub fn matcher_bias_sd(range_noise_m: f64, ray_spacing_rad: f64) -> [f64; 3] {
    if !(range_noise_m.is_finite() && range_noise_m > 0.0) {
        return [0.0; 3];
    }
    let spacing = if ray_spacing_rad.is_finite() && ray_spacing_rad > 0.0 {
        ray_spacing_rad
    } else {
        REFERENCE_RAY_SPACING_RAD
    };
    let ratio = (range_noise_m / REFERENCE_RANGE_NOISE_M) * (REFERENCE_RAY_SPACING_RAD / spacing);
    let scale = ratio * ratio;
    let t = REFERENCE_TRANSLATION_BIAS_M * scale;
    [t, t, REFERENCE_ROTATION_BIAS * scale]
}

/// `options` with the matcher-bias term of the log(s) behind `synced` (from its
/// self-check's range noise and ray spacing; none without a self-check).
pub fn with_matcher_bias(
    options: odocal_solver::SolveOptions,
    synced: &crate::synchronized::Synchronized,
) -> odocal_solver::SolveOptions {
    let matcher_bias = synced.match_self_check.as_ref().map_or([0.0; 3], |c| {
        matcher_bias_sd(c.range_noise_m, c.ray_spacing_rad)
    });
    odocal_solver::SolveOptions {
        matcher_bias,
        ..options
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grows_with_the_tilt_noise_and_vanishes_without_noise() {
        assert_eq!(matcher_bias_sd(0.0, 0.006), [0.0; 3]);
        assert_eq!(matcher_bias_sd(f64::NAN, 0.006), [0.0; 3]);
        let one = matcher_bias_sd(REFERENCE_RANGE_NOISE_M, REFERENCE_RAY_SPACING_RAD);
        assert_eq!(one, [35e-6, 35e-6, 4e-5]);
        // Unknown spacing: the reference's.
        assert_eq!(matcher_bias_sd(REFERENCE_RANGE_NOISE_M, 0.0), one);
        let noisier = matcher_bias_sd(2.0 * REFERENCE_RANGE_NOISE_M, REFERENCE_RAY_SPACING_RAD);
        assert!((noisier[2] / one[2] - 4.0).abs() < 1e-12);
        // Rays twice as far apart: lines twice as long, a quarter of the tilt variance.
        let sparser = matcher_bias_sd(REFERENCE_RANGE_NOISE_M, 2.0 * REFERENCE_RAY_SPACING_RAD);
        assert!((sparser[2] / one[2] - 0.25).abs() < 1e-12);
    }
}
