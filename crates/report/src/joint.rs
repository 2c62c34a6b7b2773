//! The report of a joint calibration of several logs: the joint result as for one
//! log, plus a row per log (its clock offset, samples, share of the information, its
//! own estimate and whether it agrees with the joint one) and each log's agreement
//! as a consistency finding.

use crate::report::{build_report, Report};
use odocal_geom::FlatParams;
use odocal_log::Log;
use odocal_pipeline::consistency::Consistency;
use odocal_pipeline::{Estimate, Finding, FindingKind, JointOutcome, Options};
use serde::Serialize;
use std::fmt;
use std::path::Path;

/// One log of a joint calibration.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LogRow {
    /// The log as given.
    pub path: String,
    /// SHA-256 of the log's file, when the caller gives it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sha256: Option<String>,
    /// Clock offset used for this log (s, laser clock minus encoder clock): given,
    /// or estimated on this log alone.
    pub time_offset_s: f64,
    /// Samples the log handed to the joint solve.
    pub samples: usize,
    /// Of them, samples the joint estimate used (after trimming).
    pub samples_used: usize,
    /// Share of the information on r_L, r_R, b, ℓx, ℓy, ℓθ (1/σ² of the log's own
    /// estimate over the sum of the logs').
    pub information_share: [f64; 6],
    /// The log's own estimate: fields `r_l`, `r_r`, `b`, `l_x`, `l_y`, `l_theta`.
    pub own: FlatParams,
    /// σ of the log's own estimate, order r_L, r_R, b, ℓx, ℓy, ℓθ.
    pub own_sigma: [f64; 6],
    /// χ² of the log's own estimate against the joint one, when compared.
    pub chi2: Option<f64>,
    /// Its degrees of freedom, when compared.
    pub dof: Option<usize>,
    /// Whether the log agrees with the joint estimate, when compared.
    pub agree: Option<bool>,
    /// Parameters that moved beyond 3σ.
    pub disagreeing: Vec<String>,
}

/// The report of `joint`, the joint calibration of `logs` read from `paths`.
pub fn build_joint_report(
    paths: &[&Path],
    logs: &[&Log],
    opts: &Options,
    joint: &JointOutcome,
) -> Report {
    let mut report = build_report(paths[0], logs[0], opts, &joint.joint);
    report.log = paths
        .iter()
        .map(|p| p.display().to_string())
        .collect::<Vec<_>>()
        .join(" + ");
    let c = &mut report.log_contents;
    for log in &logs[1..] {
        c.scans += log.scans.len();
        c.encoder_records += log.encoders.len();
        c.skipped_lines += log.stats.skipped_lines;
        c.unknown_messages += log.stats.unknown.values().sum::<u64>();
    }
    report.checks = joint
        .contributions
        .iter()
        .zip(paths)
        .map(|(c, path)| agreement_finding(&c.agreement, path))
        .collect();
    report.logs = joint
        .contributions
        .iter()
        .zip(&joint.logs)
        .zip(paths)
        .map(|((c, o), path)| {
            let own = Estimate::of(o);
            let checked = match &c.agreement {
                Consistency::Checked(h) => Some(h),
                Consistency::NotAvailable { .. } => None,
            };
            LogRow {
                path: path.display().to_string(),
                sha256: None,
                time_offset_s: o.synced.time_offset,
                samples: c.samples,
                samples_used: c.samples_used,
                information_share: c.information_share,
                own: FlatParams::from_array(own.params),
                own_sigma: own.sigma,
                chi2: checked.map(|h| h.chi2),
                dof: checked.map(|h| h.dof),
                agree: checked.map(|h| h.agree),
                disagreeing: checked.map(|h| h.disagreeing.clone()).unwrap_or_default(),
            }
        })
        .collect();
    report
}

/// One log's agreement as a finding: a warning, with what to do, when it disagrees.
fn agreement_finding(agreement: &Consistency, path: &Path) -> Finding {
    match agreement {
        Consistency::Checked(h) if h.agree => {
            Finding::note(FindingKind::LogAgreement, h.sentence.clone())
        }
        Consistency::Checked(h) => Finding::warning(
            FindingKind::LogAgreement,
            format!(
                "{}; if {} was recorded with the laser mounted elsewhere, on another floor or \
                 on another robot, calibrate without it, or on its own (`odocal calibrate {}`)",
                h.sentence,
                path.display(),
                path.display()
            ),
        ),
        Consistency::NotAvailable { reason } => {
            Finding::note(FindingKind::LogAgreement, reason.clone())
        }
    }
}

/// The per-log table of the human summary.
pub(crate) fn write_log_table(f: &mut fmt::Formatter<'_>, rows: &[LogRow]) -> fmt::Result {
    writeln!(
        f,
        "  per log (own estimate; share of the information on b and ℓθ):"
    )?;
    for r in rows {
        let agreement = match (r.agree, r.chi2, r.dof) {
            (Some(true), Some(c), Some(n)) => format!("agrees (χ² {c:.1}, {n} dof)"),
            (Some(false), Some(c), Some(n)) if r.disagreeing.is_empty() => {
                format!("DISAGREES (χ² {c:.1}, {n} dof, no single parameter beyond 3σ)")
            }
            (Some(false), Some(c), Some(n)) => format!(
                "DISAGREES (χ² {c:.1}, {n} dof: {} beyond 3σ)",
                r.disagreeing.join(", ")
            ),
            _ => "not compared".to_string(),
        };
        let o = r.own.to_array();
        writeln!(
            f,
            "    {}: {} samples ({} used), clock offset {:+.4} s, b {:.4} ± {:.4} mm, ℓθ \
             {:+.3}° ± {:.3}°, share b {:.0} %, ℓθ {:.0} %; {}",
            r.path,
            r.samples,
            r.samples_used,
            r.time_offset_s,
            o[2] * 1e3,
            r.own_sigma[2] * 1e3,
            o[5].to_degrees(),
            r.own_sigma[5].to_degrees(),
            100.0 * r.information_share[2],
            100.0 * r.information_share[5],
            agreement
        )?;
    }
    Ok(())
}
