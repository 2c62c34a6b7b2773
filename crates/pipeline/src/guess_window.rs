//! How far a match of the second pass may end from its first guess.
//!
//! The second pass guesses every pair by odometry with the first pass's estimate,
//! over the pair's own interval: the guess is wrong by what the solver's residuals
//! are, `ŝ_pred − ŝ`, whose spread the first solve measured
//! ([`odocal_solver::Calibration::sm_sigma`]), and by the estimate's own error, a few per cent of
//! the motion. A match much farther from its guess is one the solver's outlier
//! rejection would trim: it is refused at once, and the matcher searches no farther.
//! That matters for the sparse matcher, whose correlative search otherwise looks
//! 0.3 m and 50° around the guess, and can find there a wrong alignment that
//! explains a sparse scan better than the right one (a wall's structure repeated
//! 0.3 m on). The first pass's guesses (the identity, a nominal typed by hand, a rough
//! bootstrap estimate) keep the matcher's fixed window, except for the pairs of sparse
//! scans matched with their neighbours ([`crate::local_map`]): those are guessed by
//! odometry with the bootstrap's estimate, and take the window of its residuals.

use odocal_icp::GuessWindow;

/// Residual σ's of the first solve a match may end from its guess (beyond the
/// 99.99 % region of three Gaussian components, where the solver trims, at 4.6).
pub const RESIDUAL_SIGMAS: f64 = 5.0;

/// The window's fixed part at least (m, rad): 5 cm and 3°.
pub const FLOOR: (f64, f64) = (0.05, 0.0524);

/// The share of the guessed motion added: the estimate's error, generously.
pub const MOTION_SHARE: f64 = 0.2;

/// The window of matches guessed by odometry with an estimate (the second pass's,
/// and the clouds' of [`crate::local_map`]), from the residuals' σ of the solve that
/// gave it, `sm_sigma` (x, y, θ; m, m, rad; [`odocal_solver::Calibration::sm_sigma`]):
/// [`RESIDUAL_SIGMAS`] of them, at least [`FLOOR`], plus [`MOTION_SHARE`] of the
/// guess. `None` (the matcher's fixed window) when a σ is not finite: that solve says
/// nothing of the guesses' error.
pub fn from_residuals(sm_sigma: [f64; 3]) -> Option<GuessWindow> {
    if !sm_sigma.iter().all(|s| s.is_finite()) {
        return None;
    }
    let [sx, sy, st] = sm_sigma;
    Some(GuessWindow {
        xy: FLOOR.0.max(RESIDUAL_SIGMAS * sx.hypot(sy)),
        theta: FLOOR.1.max(RESIDUAL_SIGMAS * st),
        share: MOTION_SHARE,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_window_is_the_residuals_spread_or_the_floor() {
        // The simulated Neato's first solve: σ of 3–5 mm, 0.2°: the floor.
        let w = from_residuals([0.004, 0.003, 0.003]).unwrap();
        assert_eq!((w.xy, w.theta, w.share), (FLOOR.0, FLOOR.1, MOTION_SHARE));
        // The real MinesRover's (exp1): 20 and 15 mm, 1.0°.
        let w = from_residuals([0.0204, 0.0154, 0.0175]).unwrap();
        assert!(
            (w.xy - 5.0 * 0.0204f64.hypot(0.0154)).abs() < 1e-12,
            "{w:?}"
        );
        assert!((w.theta - 5.0 * 0.0175).abs() < 1e-12, "{w:?}");
        assert_eq!(from_residuals([0.004, f64::NAN, 0.003]), None);
        assert_eq!(from_residuals([0.004, 0.003, f64::INFINITY]), None);
    }
}
