//! Scaling a calibration's covariance when its noise model is found too small by a
//! measurement outside the solver (the scan matcher's own error, say): the σ (the
//! slide's too), the verdicts and the sentence follow; or widening it by the
//! uncertainty of a quantity the estimate was computed at (the clock offset).

use crate::calibrate::Calibration;
use crate::lasers::LasersCalibration;

/// Multiplies every σ of `calibration` by `factor` (the covariance by `factor²`) and
/// judges the parameters again; a `factor` that is not finite or below 1 changes
/// nothing (the covariance is only ever made more conservative here).
pub fn inflate_sigma(calibration: &mut Calibration, factor: f64) {
    inflate_sigma_per_parameter(calibration, [factor; 6]);
}

/// Multiplies the σ of parameter `i` (r_L, r_R, b, ℓx, ℓy, ℓθ) of `calibration` by
/// `factors[i]` (row and column `i` of the covariance: correlations kept) and judges
/// the parameters again; factors that are not finite or below 1 count as 1. The
/// slide's σ follow the largest factor.
pub fn inflate_sigma_per_parameter(calibration: &mut Calibration, factors: [f64; 6]) {
    let factors = factors.map(|f| if f.is_finite() && f > 1.0 { f } else { 1.0 });
    if factors.iter().all(|&f| f == 1.0) {
        return;
    }
    for (i, row) in calibration.covariance.iter_mut().enumerate() {
        for (j, v) in row.iter_mut().enumerate() {
            *v *= factors[i] * factors[j];
        }
    }
    let factor = factors.iter().copied().fold(1.0, f64::max);
    if let Some(slip) = calibration.lateral_slip.as_mut() {
        slip.sigma *= factor;
        slip.covariance_with_params = slip.covariance_with_params.map(|c| c * factor * factor);
    }
    calibration
        .observability
        .rejudge(&calibration.params, &calibration.covariance);
}

/// Adds `shift · shiftᵀ` to the covariance of `calibration` and judges the parameters
/// again: the uncertainty of a quantity the estimate was computed at (the clock
/// offset, say), `shift` being how far the parameters (r_L, r_R, b, ℓx, ℓy, ℓθ) move
/// when that quantity moves by its σ. Entries that are not finite count as 0.
pub fn widen_along(calibration: &mut Calibration, shift: &[f64; 6]) {
    if add_outer(&mut calibration.covariance, shift) {
        calibration
            .observability
            .rejudge(&calibration.params, &calibration.covariance);
    }
}

/// [`widen_along`] for the joint estimate of several lasers: adds `shift · shiftᵀ` to
/// its `(3+3K)×(3+3K)` covariance, `shift` in the order of
/// [`LasersCalibration::params`] (a shorter `shift` widens its leading parameters
/// only). Entries that are not finite count as 0. Its views
/// ([`LasersCalibration::view`], [`LasersCalibration::covariance_of`],
/// [`LasersCalibration::from_first`]) read the widened covariance; its `first` and
/// `own` estimates are left as they are.
pub fn widen_lasers_along(lasers: &mut LasersCalibration, shift: &[f64]) {
    add_outer(&mut lasers.covariance, shift);
}

/// Adds `shift · shiftᵀ` to `covariance` (entries of `shift` that are not finite
/// counting as 0, rows and columns beyond it untouched); whether anything was added.
fn add_outer<R: AsMut<[f64]>>(covariance: &mut [R], shift: &[f64]) -> bool {
    let finite = |s: &f64| if s.is_finite() { *s } else { 0.0 };
    if shift.iter().map(finite).all(|s| s == 0.0) {
        return false;
    }
    for (row, a) in covariance.iter_mut().zip(shift.iter().map(finite)) {
        for (v, b) in row.as_mut().iter_mut().zip(shift.iter().map(finite)) {
            *v += a * b;
        }
    }
    true
}
