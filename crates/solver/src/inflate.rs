//! Scaling a calibration's covariance when its noise model is found too small by a
//! measurement outside the solver (the scan matcher's own error, say): the σ (the
//! slide's too), the verdicts and the sentence follow.

use crate::calibrate::Calibration;

/// Multiplies every σ of `calibration` by `factor` (the covariance by `factor²`) and
/// judges the parameters again; a `factor` that is not finite or below 1 changes
/// nothing (the covariance is only ever made more conservative here).
pub fn inflate_sigma(calibration: &mut Calibration, factor: f64) {
    if !(factor.is_finite() && factor > 1.0) {
        return;
    }
    let f2 = factor * factor;
    for row in calibration.covariance.iter_mut() {
        for v in row.iter_mut() {
            *v *= f2;
        }
    }
    if let Some(slip) = calibration.lateral_slip.as_mut() {
        slip.sigma *= factor;
        slip.covariance_with_params = slip.covariance_with_params.map(|c| c * f2);
    }
    calibration
        .observability
        .rejudge(&calibration.params, &calibration.covariance);
}
