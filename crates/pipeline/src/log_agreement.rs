//! Each log of a joint calibration against the others: the log's own estimate minus
//! the other logs' own estimates combined (weighted by their information), compared
//! with the covariance of that difference (`C_log + C_others`: the logs are
//! independent), by the two-halves check's rules ([`crate::consistency`]); and the
//! share of the information on each parameter that each log brings.
//!
//! The joint estimate is not the comparison's other side: its covariance is not the
//! combination of the logs' own (one noise level and shape blend for all logs, the
//! slide and the shared-scan model fitted on all of them), so `C_log − C_joint`, the
//! difference's covariance were it the combination, was too small in some direction
//! for one log of a pair and too large for the other: on 12 pairs of 60 s simulated
//! Khepera logs given in phases, one log of a pair at χ² 25.1 for 6 against the joint
//! estimate while the two logs' own estimates differed by χ² 1.9 (mean χ²/dof 1.28
//! against the joint, 0.87 between the logs).

use crate::consistency::{
    compare, leaving_out, left_out, names_of, Consistency, HalvesCheck, Z_LIMIT,
};
use nalgebra::{DMatrix, DVector};
use odocal_solver::{Calibration, Params, SolveOptions, Verdict, PARAMETER_NAMES};

/// Compares one log's own estimate `log` with the other logs' (`others`), or with the
/// joint estimate `joint`; `name` names the log in the sentence. With
/// `own_covariance` the difference with the joint estimate is judged by the log's own
/// covariance (conservative: for a log that is the only one of its laser in a joint
/// solve of several lasers, whose `C_log − C_joint` is nearly singular and no longer
/// the difference's covariance).
///
/// A log that alone leaves a free parameter weak is compared on the parameters it
/// determines well (their marginal covariance), the weak ones named and left out:
/// two real logs of one rover without spins in place, whose ℓx is weak in each,
/// differ in b by 2–3σ, which no comparison showed when a weak ℓx left the whole log
/// out. A log that does not excite a parameter at all, determines none well, or
/// lands on the mirror solution is not compared (the reason is given): its
/// covariance would describe a linearization that is not valid.
///
/// `others` are the other logs' names and own estimates (their σ as the logs report
/// them): the log is compared with their combination by their information when they
/// give one on the parameters compared, else with the joint estimate by
/// `C_log − C_joint` (several lasers, or `own_covariance`).
pub fn check_log(
    log: &Calibration,
    others: &[(&str, &Calibration)],
    joint: &Calibration,
    options: &SolveOptions,
    name: &str,
    own_covariance: bool,
) -> Consistency {
    check_with_cause(log, others, joint, options, name, own_covariance, None)
}

/// [`check_log`], a disagreement giving `cause` when there is one (else the causes
/// that fit a whole log).
fn check_with_cause(
    log: &Calibration,
    others: &[(&str, &Calibration)],
    joint: &Calibration,
    options: &SolveOptions,
    name: &str,
    own_covariance: bool,
    cause: Option<&str>,
) -> Consistency {
    let weak = match left_out(log, options) {
        Ok(weak) => weak,
        Err(missing) => {
            return Consistency::NotAvailable {
                reason: format!(
                    "{name} alone does not determine {} well ({} samples), so its own \
                     estimate is not compared with the joint one; its samples count only in \
                     the joint fit",
                    names_of(log, &missing),
                    log.samples_used
                ),
            }
        }
    };
    let sign = |c: &Calibration| (c.params.r_l.signum(), c.params.r_r.signum());
    if sign(log) != sign(joint) {
        return Consistency::NotAvailable {
            reason: format!(
                "{name} alone lands on the opposite signs of the wheel radii (the mirror \
                 solution): too short to tell them apart, so it is not compared"
            ),
        };
    }
    // The weak parameters are left out: the comparison is over the others' marginal.
    let compared = leaving_out(options, &weak, joint);
    let usable: Vec<(&str, &Calibration)> = others
        .iter()
        .copied()
        .filter(|(_, c)| sign(c) == sign(joint))
        .collect();
    let estimates: Vec<&Calibration> = usable.iter().map(|(_, c)| *c).collect();
    let rest = (!own_covariance)
        .then(|| combined(log, &estimates, joint, &compared))
        .flatten();
    // The other side, and whom a disagreement's causes are said of.
    let (other_side, which) = match (&rest, usable.as_slice()) {
        (Some(_), [(other, _)]) => (other.to_string(), "one of the two logs"),
        (Some(_), _) => ("the other logs together".to_string(), "this log"),
        (None, _) => ("the joint estimate".to_string(), "this log"),
    };
    let what = if weak.is_empty() {
        format!("{name} and {other_side}")
    } else {
        format!(
            "{name} and {other_side}, on the parameters the log alone determines \
             well (not {}: weak in it),",
            names_of(log, &weak)
        )
    };
    let mut check = match &rest {
        Some((rest, covariance)) => compare(log, rest, covariance, &compared, &what),
        None => {
            let covariance = if own_covariance {
                log.covariance
            } else {
                difference_covariance(log, joint, &compared)
            };
            compare(log, joint, &covariance, &compared, &what)
        }
    };
    if !check.agree {
        check.sentence = disagreement(&what, &check, cause, which);
    }
    Consistency::Checked(Box::new(check))
}

/// Compares one phase of a log given in phases (`--all-pairs`, one log), `alike` as
/// [`as_exchangeable_phase`] makes it, with the log's joint estimate `joint` (before
/// any widening for the phases' shared errors); a disagreement names the causes a
/// phase can have.
pub fn check_phase(
    alike: &Calibration,
    joint: &Calibration,
    options: &SolveOptions,
    name: &str,
) -> Consistency {
    check_with_cause(alike, &[], joint, options, name, false, Some(PHASE_CAUSE))
}

/// Why one phase of a log disagrees with the others: not another robot or mounting.
const PHASE_CAUSE: &str = "this phase pairs other scans of the same driving, so it holds \
    matches or wheel motions the other phases do not (a slip, a wrong match: see its \
    findings)";

/// One phase of a log given in phases (`--all-pairs`), as its comparison with the
/// joint estimate sees it: its own estimate, with the covariance the joint estimate
/// `joint` (before any widening for the phases' shared errors) gives its share of the
/// samples, `C_joint · N / n`. The phases of one log are alike (the same driving, the
/// same scans' kind, interleaved in time), so they differ in precision only by their
/// sample counts; their own covariances differ far more, by the noise of each one's
/// noise estimate: on 30 simulated logs each of three presets, a phase's own σ was
/// 0.5–0.6 of `σ_joint·√(N/n)` for one phase in ten and 1.2–1.5 for another, and
/// judged by them 5–13 % of the phases disagreed with their own log's joint estimate
/// (by χ² 25–430 for 6, no single parameter beyond 3σ in half of them). The
/// difference's covariance is then `(N/n − 1)·C_joint`, that of independent phases:
/// phases that share errors differ less, so the check errs on the side of agreement.
pub fn as_exchangeable_phase(phase: &Calibration, joint: &Calibration) -> Calibration {
    let share = joint.samples_used as f64 / phase.samples_used.max(1) as f64;
    let mut alike = phase.clone();
    alike.covariance = joint.covariance.map(|row| row.map(|v| v * share));
    alike
}

/// "LOG and … disagree …": the parameters that moved and the causes that fit a whole
/// log (not the two-halves check's causes within one log), said of `which` log ("this
/// log", or "one of the two logs" when the log is compared with one other), or `cause`
/// when given.
fn disagreement(what: &str, h: &HalvesCheck, cause: Option<&str>, which: &str) -> String {
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
    let cause = match cause {
        Some(cause) => cause.to_string(),
        None if moved.iter().all(|&i| i >= 3) => format!(
            "likely the laser was mounted elsewhere for {which}, or {which} has a fault of its \
             own (see its findings)"
        ),
        None => format!(
            "likely {which} was recorded on another robot, another floor or with other tyres \
             or load, or the laser was mounted elsewhere, or {which} has a fault of its own \
             (see its findings)"
        ),
    };
    format!(
        "{what} disagree beyond 3σ ({}; χ² {:.1} for {} parameters, 3σ level {:.1}): {cause}",
        list.join(", "),
        h.chi2,
        h.dof,
        h.chi2_limit
    )
}

/// The estimates `others` combined on the parameters `options` leaves free, by their
/// information: `θ = C·Σ C_j⁻¹ θ_j`, `C = (Σ C_j⁻¹)⁻¹` over the free block (each
/// log's marginal there), with `log`'s estimate minus it and `C_log + C`, the
/// covariance of that difference (the logs independent). The held parameters keep
/// `at`'s values (they are not compared). `None` when no other is given or some
/// covariance over the free block is not positive definite.
fn combined(
    log: &Calibration,
    others: &[&Calibration],
    at: &Calibration,
    options: &SolveOptions,
) -> Option<(Calibration, [[f64; 6]; 6])> {
    let free: Vec<usize> = (0..6)
        .filter(|&i| !options.constraints.is_held(i))
        .collect();
    let estimates: Vec<(&Params, &[[f64; 6]; 6])> =
        others.iter().map(|c| (&c.params, &c.covariance)).collect();
    let (shift, c_rest) = combine_on(&log.params, &estimates, &free)?;
    let own = log.params.to_vector();
    let mut v = at.params.to_vector();
    for (p, &i) in free.iter().enumerate() {
        v[i] = own[i] + shift[p];
    }
    let mut rest = at.clone();
    rest.params = Params::from_vector(v);
    rest.covariance = [[0.0; 6]; 6];
    for (p, &i) in free.iter().enumerate() {
        for (q, &j) in free.iter().enumerate() {
            rest.covariance[i][j] = c_rest[(p, q)];
        }
    }
    let sum = std::array::from_fn(|i| {
        std::array::from_fn(|j| log.covariance[i][j] + rest.covariance[i][j])
    });
    sum.iter()
        .flatten()
        .all(|v: &f64| v.is_finite())
        .then_some((rest, sum))
}

/// The estimates `others` (parameters and covariance) combined by their information
/// over the parameters `free` (each one's marginal there): the combination minus
/// `log` (headings unwrapped by taking each one's difference from `log`) and its
/// covariance, `(Σ C_j⁻¹)⁻¹`. `None` when no other is given or a covariance is not
/// positive definite over `free`.
fn combine_on(
    log: &Params,
    others: &[(&Params, &[[f64; 6]; 6])],
    free: &[usize],
) -> Option<(DVector<f64>, DMatrix<f64>)> {
    if others.is_empty() || free.is_empty() {
        return None;
    }
    let n = free.len();
    let mut information = DMatrix::zeros(n, n);
    let mut pulled = DVector::zeros(n);
    for (params, covariance) in others {
        let c_j = DMatrix::from_fn(n, n, |p, q| covariance[free[p]][free[q]]).cholesky()?;
        let d = params.difference(log);
        pulled += c_j.solve(&DVector::from_fn(n, |p, _| d[free[p]]));
        information += c_j.inverse();
    }
    let information = (&information + information.transpose()) * 0.5;
    let c_rest = information.cholesky()?.inverse();
    let shift = &c_rest * pulled;
    (shift.iter().chain(c_rest.iter()).all(|v| v.is_finite())).then_some((shift, c_rest))
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

/// The joint estimate's σ widened where the logs disagree. For each parameter that
/// some log's comparison found beyond 3σ, the `K` logs that determine it well give
/// the external error of their weighted mean around the joint value θ: `σ_ext =
/// √(χ²/(K − 1)) / √(Σ 1/σₖ²)`, `χ² = Σ (θₖ − θ)²/σₖ²` (the weighted mean's σ scaled
/// by the Birge ratio); when `σ_ext` is above the joint σ, the parameter's row and
/// column of the covariance are scaled up to it (correlations kept) and the verdicts
/// judged again. Logs that disagree beyond their σ say that their σ leave an error
/// out (or that they are not one robot, which their warnings say); the joint σ would
/// then claim a precision that no log shows: two real logs of one rover whose b
/// differ by 4.7σ (297.5 ± 1.4 and 308.7 ± 1.9 mm with every scan pair) gave a joint
/// b of 302.2 ± 1.2 mm. The joint σ is the reference, not the product: its noise
/// level, estimated on the logs together, may already have grown with their
/// disagreement.
///
/// `logs` pairs each log's own estimate with its comparison; `what` names them in the
/// sentence ("logs", or "phases" for the phases of one log). Returns the widened
/// parameters' sentence, `None` when nothing was widened.
pub fn widen_to_spread(
    joint: &mut Calibration,
    logs: &[(&Calibration, &Consistency)],
    what: &str,
) -> Option<String> {
    let disagreeing: Vec<usize> = (0..6)
        .filter(|&p| {
            logs.iter().any(|(_, a)| match a {
                Consistency::Checked(h) => !h.agree && h.z[p].abs() > Z_LIMIT,
                Consistency::NotAvailable { .. } => false,
            })
        })
        .collect();
    let joint_values = joint.params.to_vector();
    let mut ratios = [1.0; 6];
    let mut said = Vec::new();
    for &p in &disagreeing {
        // The logs that determine p well (their comparison included it).
        let own: Vec<(f64, f64)> = logs
            .iter()
            .filter(|(c, a)| {
                matches!(a, Consistency::Checked(h) if h.sigma[p] > 0.0)
                    && c.observability.parameters[p].verdict == Verdict::WellDetermined
            })
            .map(|(c, _)| (c.params.to_vector()[p], c.covariance[p][p]))
            .filter(|(_, v)| v.is_finite() && *v > 0.0)
            .collect();
        if own.len() < 2 {
            continue;
        }
        let chi2: f64 = own
            .iter()
            .map(|(v, var)| (v - joint_values[p]).powi(2) / var)
            .sum();
        let weight: f64 = own.iter().map(|(_, var)| 1.0 / var).sum();
        let external = (chi2 / (own.len() - 1) as f64 / weight).sqrt();
        let sigma = joint.covariance[p][p].max(0.0).sqrt();
        let ratio = external / sigma;
        if ratio > 1.0 && ratio.is_finite() {
            ratios[p] = ratio;
            let scale = if p == 5 { 1.0 } else { 1e3 };
            let unit = if p == 5 { "rad" } else { "mm" };
            let values: Vec<String> = own
                .iter()
                .map(|(v, var)| format!("{:.4} ± {:.4}", v * scale, var.sqrt() * scale))
                .collect();
            said.push(format!(
                "{} ±{:.4} → ±{:.4} {unit} (×{ratio:.1}; the {what}' own {}: χ² {chi2:.1} for \
                 {} degree(s) of freedom around the joint {:.4})",
                PARAMETER_NAMES[p],
                sigma * scale,
                external * scale,
                values.join(", "),
                own.len() - 1,
                joint_values[p] * scale
            ));
        }
    }
    if said.is_empty() {
        return None;
    }
    odocal_solver::inflate_sigma_per_parameter(joint, ratios);
    Some(format!(
        "the {what} disagree beyond their σ, so the joint σ are widened to the {what}' \
         spread (the external error of their weighted mean): {}; the joint σ would otherwise \
         claim a precision that none of them shows",
        said.join("; ")
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use odocal_geom::Pose2;

    fn params(b: f64, theta: f64) -> Params {
        Params {
            r_l: 0.03,
            r_r: 0.03,
            b,
            laser: Pose2::new(0.1, 0.0, theta),
        }
    }

    fn diagonal(v: [f64; 6]) -> [[f64; 6]; 6] {
        std::array::from_fn(|i| std::array::from_fn(|j| if i == j { v[i] } else { 0.0 }))
    }

    #[test]
    fn the_other_logs_combine_by_their_information() {
        let log = params(0.300, 0.0);
        let all: Vec<usize> = (0..6).collect();
        // One other: its difference from the log and its own covariance.
        let one = params(0.306, 0.0);
        let c1 = diagonal([1e-8, 1e-8, 4e-6, 1e-4, 1e-4, 1e-4]);
        let (shift, c) = combine_on(&log, &[(&one, &c1)], &all).expect("combined");
        assert!((shift[2] - 0.006).abs() < 1e-12, "{shift}");
        assert!((c[(2, 2)] - 4e-6).abs() < 1e-18);
        // Two: b at 0.306 (σ² 4e-6) and 0.303 (σ² 1e-6): the weighted mean 0.3036, its
        // variance 0.8e-6.
        let two = params(0.303, 0.0);
        let c2 = diagonal([1e-8, 1e-8, 1e-6, 1e-4, 1e-4, 1e-4]);
        let (shift, c) = combine_on(&log, &[(&one, &c1), (&two, &c2)], &all).expect("combined");
        assert!((shift[2] - 0.0036).abs() < 1e-12, "{shift}");
        assert!((c[(2, 2)] - 0.8e-6).abs() < 1e-15);
        // Headings either side of ±π combine unwrapped.
        let log = params(0.300, std::f64::consts::PI - 0.01);
        let across = params(0.300, -std::f64::consts::PI + 0.01);
        let (shift, _) = combine_on(&log, &[(&across, &c1)], &all).expect("combined");
        assert!((shift[5] - 0.02).abs() < 1e-12, "{shift}");
        // Over the free parameters only: b held, its zero variance not inverted.
        let mut held = c1;
        held[2][2] = 0.0;
        assert!(combine_on(&log, &[(&one, &held)], &all).is_none());
        let free = [0, 1, 3, 4, 5];
        let (shift, c) = combine_on(&log, &[(&one, &held)], &free).expect("combined");
        assert_eq!((shift.len(), c.nrows()), (5, 5));
        // Nothing to combine, or a covariance that is not finite.
        assert!(combine_on(&log, &[], &all).is_none());
        let mut bad = c1;
        bad[3][3] = f64::NAN;
        assert!(combine_on(&log, &[(&one, &bad)], &all).is_none());
    }

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
