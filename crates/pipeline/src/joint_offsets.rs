//! Each log's clock-offset uncertainty carried into the joint estimate.
//!
//! A log whose clock offset was estimated carries, in its own σ, how far its estimate
//! moves when the offset moves by its σ ([`crate::time_offset::OffsetEstimate::parameter_shift`]).
//! The joint estimate weighs each log by its information, so to first order it moves
//! by `C_joint · C_log⁻¹ · shift` when that log's offset moves by its σ; the logs'
//! offsets are estimated separately, so their moves add to the joint covariance one
//! by one (`Σ_i Δ_i Δ_iᵀ`).

use nalgebra::{Matrix6, Vector6};

/// Singular values of a log's covariance below this fraction of its largest are
/// taken as zero when it is inverted (a held parameter's zero variance: the log
/// brings no information on it to weigh).
const SINGULAR_FRACTION: f64 = 1e-12;

/// How far the joint estimate (covariance `joint`) moves when one log's estimate
/// (covariance `log`) moves by `shift`: `joint · log⁻¹ · shift`, the log's
/// covariance pseudo-inverted. `None` when it cannot be inverted or the result is
/// not finite.
pub fn joint_shift(
    joint: &[[f64; 6]; 6],
    log: &[[f64; 6]; 6],
    shift: &[f64; 6],
) -> Option<[f64; 6]> {
    let joint = Matrix6::from_fn(|i, j| joint[i][j]);
    let log = Matrix6::from_fn(|i, j| log[i][j]);
    let largest = log.abs().max();
    if !(largest.is_finite() && largest > 0.0) {
        return None;
    }
    let information = log.pseudo_inverse(SINGULAR_FRACTION * largest).ok()?;
    let moved = joint * information * Vector6::from_column_slice(shift);
    let moved: [f64; 6] = std::array::from_fn(|i| moved[i]);
    moved.iter().all(|v| v.is_finite()).then_some(moved)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn diagonal(d: [f64; 6]) -> [[f64; 6]; 6] {
        std::array::from_fn(|i| std::array::from_fn(|j| if i == j { d[i] } else { 0.0 }))
    }

    #[test]
    fn two_equal_logs_pass_half_of_one_logs_move_to_the_joint_estimate() {
        let log = diagonal([1e-6, 1e-6, 4e-6, 1e-4, 1e-4, 1e-5]);
        let joint = diagonal([5e-7, 5e-7, 2e-6, 5e-5, 5e-5, 5e-6]);
        let shift = [1e-4, -2e-4, 3e-4, 1e-3, -1e-3, 2e-3];
        let moved = joint_shift(&joint, &log, &shift).unwrap();
        for (m, s) in moved.iter().zip(shift) {
            assert!((m - 0.5 * s).abs() <= 1e-12 * s.abs(), "{m} against {s}");
        }
    }

    #[test]
    fn a_log_far_more_precise_than_the_others_passes_its_whole_move() {
        // Correlated parameters: the joint covariance is the log's, nearly (the
        // others bring little), so the joint estimate moves as the log does.
        let mut log = diagonal([1e-6, 1e-6, 4e-6, 1e-4, 1e-4, 1e-5]);
        log[2][3] = 1e-5;
        log[3][2] = 1e-5;
        let shift = [0.0, 0.0, 1e-3, -2e-3, 0.0, 0.0];
        let moved = joint_shift(&log, &log, &shift).unwrap();
        for (m, s) in moved.iter().zip(shift) {
            assert!((m - s).abs() <= 1e-9, "{m} against {s}");
        }
    }

    #[test]
    fn a_held_parameter_takes_no_move_and_bad_covariances_give_none() {
        let log = diagonal([1e-6, 1e-6, 4e-6, 1e-4, 0.0, 1e-5]);
        let joint = diagonal([5e-7, 5e-7, 2e-6, 5e-5, 0.0, 5e-6]);
        let moved = joint_shift(&joint, &log, &[1e-4, 1e-4, 1e-4, 1e-4, 1e-4, 1e-4]).unwrap();
        assert_eq!(moved[4], 0.0);
        assert!((moved[3] - 5e-5).abs() < 1e-15);
        assert_eq!(joint_shift(&joint, &[[0.0; 6]; 6], &[1.0; 6]), None);
        assert_eq!(
            joint_shift(&joint, &diagonal([f64::NAN; 6]), &[1.0; 6]),
            None
        );
    }
}
