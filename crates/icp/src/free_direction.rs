//! A match that fixes two directions of the displacement and not the third: a robot
//! driving along a corridor, or along one wall, sees the walls' offsets and
//! directions but nothing that says how far it went along them.
//!
//! Such a result is ill-conditioned (condition number above
//! [`IcpParams::max_condition_number`](crate::IcpParams::max_condition_number)), and
//! where it lands along the weak direction is decided by a few returns (the cost is a
//! washboard there). Its other two directions are as well determined as any match's.
//! [`leave_free`] keeps them: the pose is moved along the weak direction to the first
//! guess, and the covariance gets [`FREE_VARIANCE`] along that direction, which
//! leaves it free — a calibration weighting the residuals by the inverse covariance
//! takes from the match only what the scans determined.
//!
//! The sparse scans' matcher (`sparse_fallback`) leaves such directions free: a
//! Neato-class LDS along a corridor sees a few dozen points of its walls. The primary
//! path still flags them ill-conditioned: on the simulated TurtleBot 4 and rover it
//! would gain 8 and 4 pairs of about 850, and on the real MinesRover logs one pair,
//! whose different first estimate moved every later match (docs/benchmarks.md,
//! stop 39).

use crate::IcpResult;
use nalgebra::{Matrix3, SymmetricEigen};
use odocal_geom::{wrap_angle, Pose2};

/// Variance (m² along the direction's unit motion) given to a free direction: a
/// metre's σ, 100–1,000× the matches' σ across a wall, so that a weighted fit takes
/// 10⁻⁴–10⁻⁶ of a direction's weight from it, and wider than any correction the
/// matcher accepts (30 cm).
pub const FREE_VARIANCE: f64 = 1.0;

/// `result` with its weakest direction left free ([`leave_free`]) when it is
/// ill-conditioned for its condition number (not for a failed basin test, which
/// doubts the whole result) and the other two directions are well conditioned;
/// otherwise `result` as it is. `rho`: the current scan's RMS range (m).
pub(crate) fn free_if_corridor(
    result: IcpResult,
    guess: &Pose2,
    rho: f64,
    max_condition_number: f64,
) -> IcpResult {
    if result.ill_conditioned && result.condition_number > max_condition_number {
        leave_free(&result, guess, rho, max_condition_number).unwrap_or(result)
    } else {
        result
    }
}

/// `result` with its weakest direction left free, or `None` when it cannot be:
/// the covariance is not finite, or the other two directions are not well
/// conditioned either (their condition number, with the rotation scaled by `rho`,
/// the current scan's RMS range, above `max_condition_number`).
///
/// The weak direction is the covariance's largest axis in `(x, y, ρθ)`; the pose is
/// moved along it to where `guess` is (so that residuals left unweighted, such as a
/// closed form's, see the guess there, not the washboard's minimum), and
/// [`FREE_VARIANCE`] is added along it. The result's
/// [`free_direction`](IcpResult::free_direction) is that axis as a motion
/// `(x, y, θ)` (m, m, rad per unit of the axis).
fn leave_free(
    result: &IcpResult,
    guess: &Pose2,
    rho: f64,
    max_condition_number: f64,
) -> Option<IcpResult> {
    let cov = &result.covariance;
    let finite = cov.iter().flatten().all(|v| v.is_finite());
    if !finite || !rho.is_finite() || rho <= 0.0 {
        return None;
    }
    // Covariance in (x, y, ρθ).
    let d = [1.0, 1.0, rho];
    let scaled = Matrix3::from_fn(|r, c| d[r] * cov[r][c] * d[c]);
    let eig = SymmetricEigen::new(scaled);
    let mut order = [0usize, 1, 2];
    order.sort_by(|&a, &b| eig.eigenvalues[b].total_cmp(&eig.eigenvalues[a]));
    let (middle, smallest) = (eig.eigenvalues[order[1]], eig.eigenvalues[order[2]]);
    if smallest.is_nan() || smallest <= 0.0 || middle / smallest > max_condition_number {
        return None;
    }
    let v = eig.eigenvectors.column(order[0]);
    // The axis as a motion in (x, y, θ).
    let motion = [v[0], v[1], v[2] / rho];
    let apart = [
        guess.x - result.pose.x,
        guess.y - result.pose.y,
        wrap_angle(guess.theta - result.pose.theta),
    ];
    let along = v[0] * apart[0] + v[1] * apart[1] + v[2] * rho * apart[2];
    let pose = Pose2::new(
        result.pose.x + along * motion[0],
        result.pose.y + along * motion[1],
        wrap_angle(result.pose.theta + along * motion[2]),
    );
    let mut covariance = *cov;
    for (r, row) in covariance.iter_mut().enumerate() {
        for (c, value) in row.iter_mut().enumerate() {
            *value += FREE_VARIANCE * motion[r] * motion[c];
        }
    }
    Some(IcpResult {
        pose,
        covariance,
        ill_conditioned: false,
        free_direction: Some(motion),
        ..result.clone()
    })
}
