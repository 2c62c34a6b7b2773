//! Each log of a joint calibration against the joint estimate: the log's own
//! estimate minus the joint one, compared with the covariance of that difference
//! (`C_log − C_joint`: the joint estimate contains the log's samples), by the
//! two-halves check's rules ([`crate::consistency`]); and the share of the
//! information on each parameter that each log brings.

use crate::consistency::{compare, Consistency, HalvesCheck, Z_LIMIT};
use nalgebra::DMatrix;
use odocal_solver::{Calibration, SolveOptions, Verdict, PARAMETER_NAMES};

/// Compares one log's own estimate `log` with the joint estimate `joint`; `name`
/// names the log in the sentence. With `own_covariance` the difference is judged by
/// the log's own covariance (conservative: for a log that is the only one of its
/// laser in a joint solve of several lasers, whose `C_log − C_joint` is nearly
/// singular and no longer the difference's covariance). A log that alone does not determine every free
/// parameter well, or lands on the mirror solution, is not compared (the reason is
/// given): its covariance would describe a linearization that is not valid.
pub fn check_log(
    log: &Calibration,
    joint: &Calibration,
    options: &SolveOptions,
    name: &str,
    own_covariance: bool,
) -> Consistency {
    let weak: Vec<&str> = log
        .observability
        .parameters
        .iter()
        .enumerate()
        .filter(|(i, p)| !options.constraints.is_held(*i) && p.verdict != Verdict::WellDetermined)
        .map(|(_, p)| p.name.as_str())
        .collect();
    if !weak.is_empty() {
        return Consistency::NotAvailable {
            reason: format!(
                "{name} alone does not determine {} well ({} samples), so its own estimate \
                 is not compared with the joint one; its samples count only in the joint fit",
                weak.join(", "),
                log.samples_used
            ),
        };
    }
    let sign = |c: &Calibration| (c.params.r_l.signum(), c.params.r_r.signum());
    if sign(log) != sign(joint) {
        return Consistency::NotAvailable {
            reason: format!(
                "{name} alone lands on the opposite signs of the wheel radii (the mirror \
                 solution): too short to tell them apart, so it is not compared"
            ),
        };
    }
    let what = format!("{name} and the joint estimate");
    let covariance = if own_covariance {
        log.covariance
    } else {
        difference_covariance(log, joint, options)
    };
    let mut check = compare(log, joint, &covariance, options, &what);
    if !check.agree {
        check.sentence = disagreement(&what, &check);
    }
    Consistency::Checked(Box::new(check))
}

/// "LOG and the joint estimate disagree …": the parameters that moved and the causes
/// that fit a whole log (not the two-halves check's causes within one log).
fn disagreement(what: &str, h: &HalvesCheck) -> String {
    let mut moved: Vec<usize> = (0..6).filter(|&i| h.z[i].abs() > Z_LIMIT).collect();
    if moved.is_empty() {
        moved = (0..6).collect();
        moved.sort_by(|&p, &q| h.z[q].abs().total_cmp(&h.z[p].abs()));
        moved.truncate(2);
    }
    let list: Vec<String> = moved
        .iter()
        .map(|&i| format!("{} by {:.1}σ", PARAMETER_NAMES[i], h.z[i].abs()))
        .collect();
    let cause = if moved.iter().all(|&i| i >= 3) {
        "the laser was mounted elsewhere for this log"
    } else {
        "this log was recorded on another robot, another floor or with other tyres or \
         load, or the laser was mounted elsewhere"
    };
    format!(
        "{what} disagree beyond 3σ ({}; χ² {:.1} for {} parameters, 3σ level {:.1}): likely \
         {cause}, or this log has a fault of its own (see its findings)",
        list.join(", "),
        h.chi2,
        h.dof,
        h.chi2_limit
    )
}

/// `C_log − C_joint` over the free parameters when it is positive definite (the
/// joint estimate contains the log, so the difference has that covariance); else the
/// log's own covariance (larger, so the check errs on the side of agreement), as
/// when the noise levels estimated from the joint and the single log differ.
fn difference_covariance(
    log: &Calibration,
    joint: &Calibration,
    options: &SolveOptions,
) -> [[f64; 6]; 6] {
    let diff: [[f64; 6]; 6] = std::array::from_fn(|i| {
        std::array::from_fn(|j| log.covariance[i][j] - joint.covariance[i][j])
    });
    let free: Vec<usize> = (0..6)
        .filter(|&i| !options.constraints.is_held(i))
        .collect();
    let n = free.len();
    let own = DMatrix::from_fn(n, n, |p, q| log.covariance[free[p]][free[q]]);
    let m = DMatrix::from_fn(n, n, |p, q| diff[free[p]][free[q]]);
    if keeps_share_of_own(&own, &m, MIN_DIFFERENCE_SHARE) {
        diff
    } else {
        log.covariance
    }
}

/// The least share of the log's own variance the difference's must keep in every
/// direction. Below it the other logs would add almost nothing there, which a log
/// that is not alone only shows when the joint solve's noise levels differ from its
/// own (a 47-sample bag beside a 149-sample log: 0.09 % in one direction, χ² 350 for
/// estimates 0.3σ apart by its own covariance).
const MIN_DIFFERENCE_SHARE: f64 = 0.01;

/// Does `diff` keep at least `share` of `own` in every direction: `uᵀ·diff·u ≥
/// share · uᵀ·own·u` for every `u` (the smallest eigenvalue of `L⁻¹·diff·L⁻ᵀ`,
/// `own = L·Lᵀ`)? False when `own` is not positive definite.
fn keeps_share_of_own(own: &DMatrix<f64>, diff: &DMatrix<f64>, share: f64) -> bool {
    let Some(l) = own.clone().cholesky().map(|c| c.l()) else {
        return false;
    };
    let Some(l_inv) = l.try_inverse() else {
        return false;
    };
    let whitened = &l_inv * diff * l_inv.transpose();
    let whitened = (&whitened + whitened.transpose()) * 0.5;
    whitened.symmetric_eigenvalues().iter().all(|&e| e >= share)
}

/// Per log, per parameter (r_L, r_R, b, ℓx, ℓy, ℓθ): the log's information on the
/// parameter (1/σ² of its own estimate) over the sum of all logs'. A parameter no log
/// determines (every σ infinite or zero) gets equal shares.
pub fn information_shares(logs: &[&Calibration]) -> Vec<[f64; 6]> {
    let info = |c: &Calibration, i: usize| {
        let v = c.covariance[i][i];
        if v.is_finite() && v > 0.0 {
            1.0 / v
        } else {
            0.0
        }
    };
    let totals: [f64; 6] = std::array::from_fn(|i| logs.iter().map(|c| info(c, i)).sum());
    logs.iter()
        .map(|c| {
            std::array::from_fn(|i| {
                if totals[i] > 0.0 {
                    info(c, i) / totals[i]
                } else {
                    1.0 / logs.len() as f64
                }
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_difference_nearly_singular_in_one_direction_is_not_kept() {
        let own = DMatrix::from_row_slice(2, 2, &[4.0, 1.0, 1.0, 2.0]);
        // The joint holding a tenth of the log's variance: 90 % kept everywhere.
        assert!(keeps_share_of_own(&own, &(&own * 0.9), 0.01));
        // Diagonals well kept (a quarter, a half), positive definite, but along
        // (1, −1) only 0.05 % of the log's own.
        let joint = DMatrix::from_row_slice(2, 2, &[3.0, 0.001, 0.001, 1.0]);
        let u = nalgebra::DVector::from_row_slice(&[1.0, -1.0]);
        let diff = &own - &joint;
        let along = (u.transpose() * &diff * &u)[0] / (u.transpose() * &own * &u)[0];
        assert!(diff[(0, 0)] > 0.2 * own[(0, 0)] && diff[(1, 1)] > 0.2 * own[(1, 1)]);
        assert!(along < 0.01, "{along}");
        assert!(!keeps_share_of_own(&own, &diff, 0.01));
        // Not positive definite, or an own covariance that is not: not kept.
        assert!(!keeps_share_of_own(&own, &(&own * -0.1), 0.01));
        assert!(!keeps_share_of_own(&(&own * 0.0), &own, 0.01));
    }
}
