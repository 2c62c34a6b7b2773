//! Each log's clock-offset uncertainty carried into the joint estimate.
//!
//! A log whose clock offset was estimated carries, in its own σ, how far its estimate
//! moves when the offset moves by its σ ([`crate::time_offset::OffsetEstimate::parameter_shift`]).
//! The joint estimate weighs each log by its information, so to first order it moves
//! by `C_joint · C_log⁻¹ · shift` when that log's offset moves by its σ; the logs'
//! offsets are estimated separately, so their moves add to the joint covariance one
//! by one (`Σ_i Δ_i Δ_iᵀ`).
//!
//! With several lasers the joint estimate is `3 + 3K` long
//! ([`odocal_solver::LasersCalibration`]) and a log's six parameters are the shared
//! wheels and its own laser's ℓ ([`odocal_solver::LasersCalibration::indices`]): its
//! move is `C_joint[:, idx] · C_log⁻¹ · shift` ([`joint_move`]), which reaches every
//! parameter the log's are correlated with in the joint covariance (the other lasers'
//! ℓ through the shared wheels). [`widen_by_offsets`] adds every log's move to the
//! joint covariance and to the first laser's view of it alike.

use nalgebra::{Matrix6, RowVector6, Vector6};
use odocal_solver::{Calibration, LasersCalibration};

/// Singular values of a log's covariance below this fraction of its largest are
/// taken as zero when it is inverted (a held parameter's zero variance: the log
/// brings no information on it to weigh).
const SINGULAR_FRACTION: f64 = 1e-12;

/// How far a joint estimate of `n` parameters (covariance `joint`, `n` rows of `n`)
/// moves when one log's estimate (covariance `log`) moves by `shift`:
/// `joint[:, indices] · log⁻¹ · shift`, the log's covariance pseudo-inverted (a held
/// parameter's zero variance takes no move), `indices` being where the log's six
/// parameters (r_L, r_R, b, ℓx, ℓy, ℓθ) sit in the joint vector
/// ([`LasersCalibration::indices`] of the log's laser). `None` when the log's
/// covariance cannot be inverted, an index is outside a row, or the result is not
/// finite.
pub fn joint_move(
    joint: &[Vec<f64>],
    indices: &[usize; 6],
    log: &[[f64; 6]; 6],
    shift: &[f64; 6],
) -> Option<Vec<f64>> {
    let log = Matrix6::from_fn(|i, j| log[i][j]);
    let largest = log.abs().max();
    if !(largest.is_finite() && largest > 0.0) {
        return None;
    }
    let information = log.pseudo_inverse(SINGULAR_FRACTION * largest).ok()?;
    let shift = Vector6::from_column_slice(shift);
    let moved = joint
        .iter()
        .map(|row| {
            let at: Option<Vec<f64>> = indices.iter().map(|&i| row.get(i).copied()).collect();
            // Row by row: the same products, in the same order, as the 6×6 matrices of
            // the single-laser case.
            Some((RowVector6::from_row_slice(&at?) * information * shift)[0])
        })
        .collect::<Option<Vec<f64>>>()?;
    moved.iter().all(|v| v.is_finite()).then_some(moved)
}

/// One log's part in [`widen_by_offsets`].
#[derive(Debug, Clone, Copy)]
pub struct LogOffset<'a> {
    /// The log's laser (0: the first).
    pub laser: usize,
    /// The log's own covariance (r_L, r_R, b, ℓx, ℓy, ℓθ).
    pub covariance: &'a [[f64; 6]; 6],
    /// How far the log's own estimate moves when its clock offset moves by its σ.
    pub shift: [f64; 6],
}

/// Widens the joint estimate by each log's clock-offset uncertainty: every log's
/// [`joint_move`], computed from the joint covariance before any is added, adds
/// `Δ Δᵀ` to `lasers`' joint covariance (with several lasers) and its part at the
/// first laser's indices to `first` (the first laser's view, or with one laser the
/// joint estimate itself), whose verdicts are judged again
/// ([`odocal_solver::widen_along`]); `first`'s covariance thus stays the first
/// laser's block of the joint one. A log whose move cannot be computed adds nothing.
pub fn widen_by_offsets(
    first: &mut Calibration,
    mut lasers: Option<&mut LasersCalibration>,
    logs: &[LogOffset],
) {
    let joint: Vec<Vec<f64>> = match &lasers {
        Some(l) => l.covariance.clone(),
        None => first.covariance.iter().map(|r| r.to_vec()).collect(),
    };
    let moves: Vec<Vec<f64>> = logs
        .iter()
        .filter_map(|o| {
            joint_move(
                &joint,
                &LasersCalibration::indices(o.laser),
                o.covariance,
                &o.shift,
            )
        })
        .collect();
    for moved in &moves {
        if let Some(l) = lasers.as_deref_mut() {
            odocal_solver::widen_lasers_along(l, moved);
        }
        let of_first = LasersCalibration::indices(0).map(|i| moved.get(i).copied().unwrap_or(0.0));
        odocal_solver::widen_along(first, &of_first);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// [`joint_move`] of a joint estimate of the six parameters themselves (one laser:
    /// `joint · log⁻¹ · shift`).
    fn joint_shift(
        joint: &[[f64; 6]; 6],
        log: &[[f64; 6]; 6],
        shift: &[f64; 6],
    ) -> Option<[f64; 6]> {
        let rows: Vec<Vec<f64>> = joint.iter().map(|r| r.to_vec()).collect();
        joint_move(&rows, &LasersCalibration::indices(0), log, shift)?
            .try_into()
            .ok()
    }

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

    /// The covariance of two lasers' joint estimate (9×9) with `wheels`, `first` and
    /// `second` on its diagonal blocks and nothing between them.
    fn block_diagonal(
        wheels: [[f64; 3]; 3],
        first: [[f64; 3]; 3],
        second: [[f64; 3]; 3],
    ) -> Vec<Vec<f64>> {
        let mut c = vec![vec![0.0; 9]; 9];
        for (at, block) in [(0, wheels), (3, first), (6, second)] {
            for i in 0..3 {
                for j in 0..3 {
                    c[at + i][at + j] = block[i][j];
                }
            }
        }
        c
    }

    /// A 6×6 covariance with `wheels` and `laser` on its diagonal blocks.
    fn log_blocks(wheels: [[f64; 3]; 3], laser: [[f64; 3]; 3]) -> [[f64; 6]; 6] {
        std::array::from_fn(|i| {
            std::array::from_fn(|j| match (i < 3, j < 3) {
                (true, true) => wheels[i][j],
                (false, false) => laser[i - 3][j - 3],
                _ => 0.0,
            })
        })
    }

    fn close(got: f64, want: f64) -> bool {
        (got - want).abs() <= 1e-12 * want.abs().max(1e-30)
    }

    const WHEELS: [[f64; 3]; 3] = [[1e-6, 2e-7, 0.0], [2e-7, 1e-6, -3e-7], [0.0, -3e-7, 4e-6]];
    const LASER: [[f64; 3]; 3] = [[1e-4, 2e-5, 0.0], [2e-5, 1e-4, 1e-6], [0.0, 1e-6, 1e-5]];

    #[test]
    fn a_second_lasers_log_moves_its_laser_and_the_wheels_not_the_first_lasers() {
        // The joint holds a third of the log's wheel variance (two other logs as
        // good) and, on laser 2's ℓ, half of it; nothing between the blocks.
        let third = WHEELS.map(|r| r.map(|v| v / 3.0));
        let half = LASER.map(|r| r.map(|v| v / 2.0));
        let joint = block_diagonal(
            third,
            [[7e-5, 0.0, 0.0], [0.0, 7e-5, 0.0], [0.0, 0.0, 3e-6]],
            half,
        );
        let log = log_blocks(WHEELS, LASER);
        let shift = [1e-4, -2e-4, 3e-4, 1e-3, -1e-3, 2e-3];
        let moved = joint_move(&joint, &LasersCalibration::indices(1), &log, &shift).unwrap();
        assert_eq!(moved.len(), 9);
        // Laser 1's ℓ: nothing in the joint covariance ties it to the log's.
        assert_eq!(&moved[3..6], &[0.0; 3]);
        // Each block: C_joint_block · C_log_block⁻¹ · shift, here a third and a half.
        for i in 0..3 {
            assert!(close(moved[i], shift[i] / 3.0), "{i}: {}", moved[i]);
            assert!(
                close(moved[6 + i], shift[3 + i] / 2.0),
                "ℓ {i}: {}",
                moved[6 + i]
            );
        }
        // A joint block not proportional to the log's: C_joint_block · C_log_block⁻¹ ·
        // shift by the 3×3 inverse.
        let other = [[5e-5, 0.0, 1e-6], [0.0, 2e-5, 0.0], [1e-6, 0.0, 8e-6]];
        let joint = block_diagonal(third, LASER, other);
        let moved = joint_move(&joint, &LasersCalibration::indices(1), &log, &shift).unwrap();
        let want = nalgebra::Matrix3::from_fn(|i, j| other[i][j])
            * nalgebra::Matrix3::from_fn(|i, j| LASER[i][j])
                .try_inverse()
                .unwrap()
            * nalgebra::Vector3::new(shift[3], shift[4], shift[5]);
        for i in 0..3 {
            assert!(
                (moved[6 + i] - want[i]).abs() <= 1e-9 * want.abs().max(),
                "ℓ {i}: {} against {}",
                moved[6 + i],
                want[i]
            );
        }
        assert_eq!(&moved[3..6], &[0.0; 3]);
    }

    #[test]
    fn a_joint_covariance_equal_to_the_logs_on_its_indices_passes_the_whole_move() {
        let log = log_blocks(WHEELS, LASER);
        let mut joint = block_diagonal(
            WHEELS,
            [[3e-5, 0.0, 0.0], [0.0, 3e-5, 0.0], [0.0, 0.0, 1e-6]],
            LASER,
        );
        // Laser 1's ℓ tied to the wheels: it moves along, the log's own do not change.
        joint[3][2] = 1e-6;
        joint[2][3] = 1e-6;
        let shift = [1e-4, -2e-4, 3e-4, 1e-3, -1e-3, 2e-3];
        let moved = joint_move(&joint, &LasersCalibration::indices(1), &log, &shift).unwrap();
        for (a, &i) in LasersCalibration::indices(1).iter().enumerate() {
            assert!(
                (moved[i] - shift[a]).abs() <= 1e-12,
                "{i}: {} against {}",
                moved[i],
                shift[a]
            );
        }
        assert!(moved[3] != 0.0);
    }

    #[test]
    fn the_first_lasers_pose_moves_through_its_covariance_with_the_wheels() {
        // Laser 2's log moves b only (diagonal covariances); laser 1's ℓx shares
        // 2·10⁻⁶ m² with b in the joint covariance, so it moves by
        // 2·10⁻⁶ / 4·10⁻⁶ · 10⁻³ = 5·10⁻⁴ m; b by 2·10⁻⁶ / 4·10⁻⁶ · 10⁻³ = 5·10⁻⁴ m too
        // (its joint variance half the log's), nothing else.
        let mut joint = block_diagonal(
            [[5e-7, 0.0, 0.0], [0.0, 5e-7, 0.0], [0.0, 0.0, 2e-6]],
            [[5e-5, 0.0, 0.0], [0.0, 5e-5, 0.0], [0.0, 0.0, 5e-6]],
            [[1e-4, 0.0, 0.0], [0.0, 1e-4, 0.0], [0.0, 0.0, 1e-5]],
        );
        joint[2][3] = 2e-6;
        joint[3][2] = 2e-6;
        let log = diagonal([1e-6, 1e-6, 4e-6, 1e-4, 1e-4, 1e-5]);
        let moved = joint_move(
            &joint,
            &LasersCalibration::indices(1),
            &log,
            &[0.0, 0.0, 1e-3, 0.0, 0.0, 0.0],
        )
        .unwrap();
        let want = [0.0, 0.0, 5e-4, 5e-4, 0.0, 0.0, 0.0, 0.0, 0.0];
        for (i, (m, w)) in moved.iter().zip(want).enumerate() {
            assert!((m - w).abs() <= 1e-15, "{i}: {m} against {w}");
        }
    }

    #[test]
    fn the_first_lasers_indices_give_the_six_parameter_move() {
        // Rows and columns of the first laser's six in a 9×9 joint covariance: the
        // joint move there is the 6×6 one of that block (the second laser's ℓ is a
        // parameter the log says nothing of).
        let mut joint = block_diagonal(
            WHEELS,
            LASER,
            [[2e-4, 0.0, 0.0], [0.0, 2e-4, 0.0], [0.0, 0.0, 2e-5]],
        );
        for (i, j, v) in [(2, 3, 1e-6), (0, 5, -2e-7), (3, 6, 5e-6), (2, 8, 3e-7)] {
            joint[i][j] = v;
            joint[j][i] = v;
        }
        let mut log = log_blocks(
            WHEELS.map(|r| r.map(|v| 2.0 * v)),
            LASER.map(|r| r.map(|v| 1.5 * v)),
        );
        log[1][4] = 3e-7;
        log[4][1] = 3e-7;
        let shift = [1e-4, -2e-4, 3e-4, 1e-3, -1e-3, 2e-3];
        let ix = LasersCalibration::indices(0);
        let moved = joint_move(&joint, &ix, &log, &shift).unwrap();
        let block: [[f64; 6]; 6] =
            std::array::from_fn(|i| std::array::from_fn(|j| joint[ix[i]][ix[j]]));
        let six = joint_shift(&block, &log, &shift).unwrap();
        for (a, &i) in ix.iter().enumerate() {
            assert_eq!(moved[i], six[a], "{i}");
        }
        // The second laser's ℓx and ℓθ move through their covariance with ℓx and b.
        assert!(
            moved[6] != 0.0 && moved[8] != 0.0 && moved[7] == 0.0,
            "{moved:?}"
        );
    }

    #[test]
    fn bad_covariances_or_indices_give_none() {
        let joint = block_diagonal(WHEELS, LASER, LASER);
        let log = log_blocks(WHEELS, LASER);
        let shift = [1e-4; 6];
        let at = LasersCalibration::indices(1);
        assert!(joint_move(&joint, &at, &log, &shift).is_some());
        assert_eq!(joint_move(&joint, &at, &[[0.0; 6]; 6], &shift), None);
        assert_eq!(
            joint_move(&joint, &at, &diagonal([f64::INFINITY; 6]), &shift),
            None
        );
        // A laser the joint estimate does not have.
        assert_eq!(
            joint_move(&joint, &LasersCalibration::indices(2), &log, &shift),
            None
        );
        // Not finite: a joint entry, or the shift.
        let mut nan = joint.clone();
        nan[7][7] = f64::NAN;
        assert_eq!(joint_move(&nan, &at, &log, &shift), None);
        assert_eq!(joint_move(&joint, &at, &log, &[f64::NAN; 6]), None);
    }

    /// Two lasers' joint estimate of a robot driven in spins, arcs and straight
    /// runs, each laser's `ŝ` with a small deterministic error.
    fn two_lasers_solved() -> LasersCalibration {
        use odocal_geom::Pose2;
        use odocal_solver::{calibrate_lasers, Params, Sample, SolveOptions};
        let front = Params {
            r_l: 0.0305,
            r_r: 0.0298,
            b: 0.32,
            laser: Pose2::new(0.08, -0.03, 0.6),
        };
        let rear = Params {
            laser: Pose2::new(-0.12, 0.02, 3.0),
            ..front
        };
        let (mut samples, mut laser_of) = (Vec::new(), Vec::new());
        for (k, p) in [front, rear].iter().enumerate() {
            for i in 0..120 {
                let u = (i as f64 * 0.7 + k as f64).sin();
                let (d, w) = [(0.2 * u, 0.0), (0.0, 0.6 * u), (0.15 * u, -0.4 * u)][i % 3];
                let a_l = (d - 0.5 * w * p.b) / p.r_l;
                let a_r = (d + 0.5 * w * p.b) / p.r_r;
                let s = Sample::from_rotations(0.2, a_l, a_r, Pose2::IDENTITY);
                let e = |j: f64| 2e-3 * (i as f64 * 1.3 + j + 5.0 * k as f64).sin();
                let sm = odocal_solver::predict(p, &s);
                samples.push(Sample {
                    sm: Pose2::new(sm.x + e(0.0), sm.y + e(1.0), sm.theta + e(2.0)),
                    ..s
                });
                laser_of.push(k);
            }
        }
        calibrate_lasers(&samples, &laser_of, &SolveOptions::default()).expect("solves")
    }

    #[test]
    fn with_several_lasers_every_laser_and_the_first_view_widen_alike() {
        let solved = two_lasers_solved();
        let shift = [1e-4, -1e-4, 2e-3, 1e-3, -1e-3, 2e-3];
        // A log of the second laser whose own covariance is its laser's.
        let logs = [LogOffset {
            laser: 1,
            covariance: &solved.own[1].covariance,
            shift,
        }];
        let (mut lasers, mut first) = (solved.clone(), solved.first.clone());
        widen_by_offsets(&mut first, Some(&mut lasers), &logs);
        let moved = joint_move(
            &solved.covariance,
            &LasersCalibration::indices(1),
            &solved.own[1].covariance,
            &shift,
        )
        .unwrap();
        for i in 0..9 {
            for j in 0..9 {
                let want = solved.covariance[i][j] + moved[i] * moved[j];
                assert!(close(lasers.covariance[i][j], want), "({i}, {j})");
            }
        }
        // The first laser's view is the first laser's block of the widened joint
        // covariance, its σ and verdicts judged from it.
        assert_eq!(first.covariance, lasers.covariance_of(0));
        assert_eq!(
            first.observability.parameters,
            lasers.view(0).observability.parameters
        );
        // Every laser's σ grew: the wheels', the second laser's ℓ, and the first
        // laser's ℓ through its covariance with the wheels.
        for (k, i) in [(0, 2), (0, 3), (1, 3), (1, 4), (1, 5)] {
            let (before, after) = (solved.covariance_of(k)[i][i], lasers.covariance_of(k)[i][i]);
            assert!(after > before, "laser {k}, {i}: {before} -> {after}");
        }
        let (_, before) = solved.from_first(1);
        let (_, after) = lasers.from_first(1);
        assert!(after[0][0] > before[0][0], "{before:?} -> {after:?}");
        // No move, nothing widened.
        let (mut same, mut same_first) = (solved.clone(), solved.first.clone());
        widen_by_offsets(
            &mut same_first,
            Some(&mut same),
            &[LogOffset {
                shift: [0.0; 6],
                ..logs[0]
            }],
        );
        assert_eq!(same, solved);
        assert_eq!(same_first, solved.first);
    }

    #[test]
    fn with_one_laser_the_joint_estimate_widens_by_the_six_parameter_move() {
        let solved = two_lasers_solved();
        let (joint, log) = (&solved.own[0], &solved.own[1]);
        let shift = [1e-4, -1e-4, 2e-3, 1e-3, -1e-3, 2e-3];
        let mut widened = joint.clone();
        widen_by_offsets(
            &mut widened,
            None,
            &[LogOffset {
                laser: 0,
                covariance: &log.covariance,
                shift,
            }],
        );
        let mut want = joint.clone();
        let moved = joint_shift(&joint.covariance, &log.covariance, &shift).unwrap();
        odocal_solver::widen_along(&mut want, &moved);
        assert_eq!(widened, want);
        assert_ne!(widened, *joint);
    }
}
