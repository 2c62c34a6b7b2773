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
//! That tilt noise is what the figures scale with. The log measures it: the median
//! tilt σ of its scans' local lines ([`odocal_icp::PreparedScan::typical_tilt_sigma`],
//! [`crate::matching::ScanNoise`]), 0.089–0.106 rad on the Table I rows and the
//! Khepera preset (reference [`REFERENCE_TILT_SIGMA_RAD`]). Raising the range noise
//! of 300 s Khepera logs (16 seeds each) from 3 to 6 and 12 mm raised that tilt by
//! 1.82× and 2.84× and moved the rotation by −3.8e-5 ± 2.2e-5, −1.54e-4 ± 0.30e-4
//! and −8.8e-4 ± 0.9e-4 of itself (about the cube of the tilt ratio: 6× and 23×
//! where the cube says 6.0× and 22.9×), ℓx by +39 ± 14, +96 ± 31 and +217 ± 140 µm
//! and ℓy by +27 ± 18, +53 ± 43 and +381 ± 126 µm (about its square: 3.3× and 8.1×).
//! So the standard deviations are the reference figures times the tilt ratio cubed
//! (rotation) and squared (translation).
//!
//! An earlier version took the tilt noise as (range noise / ray spacing)², which
//! leaves out the range: a TurtleBot 4 / RPLIDAR in an office (10 mm noise, rays
//! 0.5° apart, walls 1–5 m away) came out at 17× the reference where its lines'
//! tilt is the reference's (0.094–0.103 rad), and the term made ℓx's and ℓy's σ
//! 1.5× too wide (RMS error/σ 0.58 and 0.49 over 30 seeds; 0.90 and 0.68 without
//! the term), while its rotations showed no bias (−8e-5 ± 7e-5 of themselves). It
//! is still the rule for scans without local lines (sparse scans matched point to
//! point), whose tilt is not measured. The sign depends on the scene (which side of
//! the laser the walls are), so it is a standard deviation, not a correction.

/// Typical range noise (m) of the logs the figures below were measured on.
pub const REFERENCE_RANGE_NOISE_M: f64 = 1.71e-3;

/// Angle between neighbouring rays (rad) of the logs the figures were measured on
/// (the URG-04LX's 2π/1024).
pub const REFERENCE_RAY_SPACING_RAD: f64 = std::f64::consts::TAU / 1024.0;

/// Typical tilt σ of the local lines (rad) of the logs the figures were measured on
/// (the median over the Table I rows and the Khepera preset, two seeds each).
pub const REFERENCE_TILT_SIGMA_RAD: f64 = 0.097;

/// The rotation bias's standard deviation at the reference noise and spacing
/// (rad/rad).
pub const REFERENCE_ROTATION_BIAS: f64 = 4.0e-5;

/// The translation bias's standard deviation per axis at the reference noise and
/// spacing (m/rad).
pub const REFERENCE_TRANSLATION_BIAS_M: f64 = 35e-6;

/// The standard deviations `(x, y, θ)` of the matcher's bias on a log whose local
/// lines' typical tilt σ is `tilt_sigma_rad`: the reference figures times the tilt
/// ratio squared (translation) and cubed (rotation). Without a measured tilt (`None`,
/// not finite or not positive), from the typical range noise `range_noise_m` and the
/// rays' spacing `ray_spacing_rad` (0 or not finite: the reference spacing), both
/// squared. No noise: no term.
pub fn matcher_bias_sd(
    range_noise_m: f64,
    ray_spacing_rad: f64,
    tilt_sigma_rad: Option<f64>,
) -> [f64; 3] {
    if !(range_noise_m.is_finite() && range_noise_m > 0.0) {
        return [0.0; 3];
    }
    if let Some(tilt) = tilt_sigma_rad.filter(|t| t.is_finite() && *t > 0.0) {
        let ratio = tilt / REFERENCE_TILT_SIGMA_RAD;
        let t = REFERENCE_TRANSLATION_BIAS_M * ratio.powi(2);
        return [t, t, REFERENCE_ROTATION_BIAS * ratio.powi(3)];
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
/// self-check's tilt, range noise and ray spacing; none without a self-check).
pub fn with_matcher_bias(
    options: odocal_solver::SolveOptions,
    synced: &crate::synchronized::Synchronized,
) -> odocal_solver::SolveOptions {
    let matcher_bias = synced.match_self_check.as_ref().map_or([0.0; 3], |c| {
        matcher_bias_sd(c.range_noise_m, c.ray_spacing_rad, c.tilt_sigma_rad)
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
        assert_eq!(matcher_bias_sd(0.0, 0.006, None), [0.0; 3]);
        assert_eq!(matcher_bias_sd(f64::NAN, 0.006, Some(0.1)), [0.0; 3]);
        let one = matcher_bias_sd(REFERENCE_RANGE_NOISE_M, REFERENCE_RAY_SPACING_RAD, None);
        assert_eq!(one, [35e-6, 35e-6, 4e-5]);
        // Unknown spacing: the reference's.
        assert_eq!(matcher_bias_sd(REFERENCE_RANGE_NOISE_M, 0.0, None), one);
        let noisier = matcher_bias_sd(
            2.0 * REFERENCE_RANGE_NOISE_M,
            REFERENCE_RAY_SPACING_RAD,
            None,
        );
        assert!((noisier[2] / one[2] - 4.0).abs() < 1e-12);
        // Rays twice as far apart: lines twice as long, a quarter of the tilt variance.
        let sparser = matcher_bias_sd(
            REFERENCE_RANGE_NOISE_M,
            2.0 * REFERENCE_RAY_SPACING_RAD,
            None,
        );
        assert!((sparser[2] / one[2] - 0.25).abs() < 1e-12);
    }

    /// A measured tilt decides, whatever the range noise and spacing: the reference
    /// tilt gives the reference figures (a noisy, coarse laser whose walls are far
    /// has no more bias than the reference); twice the tilt, 4× the translation and
    /// 8× the rotation term.
    #[test]
    fn a_measured_tilt_decides() {
        let reference = Some(REFERENCE_TILT_SIGMA_RAD);
        let rplidar = matcher_bias_sd(0.0102, 0.0087, reference);
        let [t, _, r] = rplidar;
        assert!((t - 35e-6).abs() < 1e-15 && (r - 4e-5).abs() < 1e-15);
        let doubled = matcher_bias_sd(0.0102, 0.0087, Some(2.0 * REFERENCE_TILT_SIGMA_RAD));
        assert!((doubled[0] / t - 4.0).abs() < 1e-12);
        assert!((doubled[2] / r - 8.0).abs() < 1e-12);
        // No usable tilt: the range-noise rule.
        for tilt in [None, Some(0.0), Some(f64::NAN)] {
            assert_eq!(
                matcher_bias_sd(0.0102, 0.0087, tilt),
                matcher_bias_sd(0.0102, 0.0087, None)
            );
        }
    }
}
