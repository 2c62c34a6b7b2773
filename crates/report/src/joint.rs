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

/// One log given in phases (`--all-pairs`): how much its phases share their errors.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PhaseCorrelationRow {
    /// The log as given.
    pub log: String,
    /// The correlation and the factor on the σ.
    #[serde(flatten)]
    pub correlation: odocal_pipeline::phase_correlation::PhaseCorrelation,
}

/// One laser of a robot with several: its pose with the shared wheels, and its pose
/// in the first laser's frame.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LaserRow {
    /// The bag's scan topic, when the laser's logs are bags.
    pub topic: Option<String>,
    /// The logs (names as in `logs`) whose samples are this laser's.
    pub logs: Vec<String>,
    /// ℓx (m).
    pub l_x: f64,
    /// ℓy (m).
    pub l_y: f64,
    /// ℓθ (rad).
    pub l_theta: f64,
    /// σ of (ℓx, ℓy, ℓθ).
    pub sigma: [f64; 3],
    /// Covariance of (ℓx, ℓy, ℓθ) from the joint covariance.
    pub covariance: [[f64; 3]; 3],
    /// Samples of this laser handed to the solve.
    pub samples: usize,
    /// Of them, the samples the joint estimate used.
    pub samples_used: usize,
    /// The laser's range scale (stated, or its recognised range finder's data sheet),
    /// from its first log: its ℓx, ℓy scale with it.
    pub range_scale: odocal_pipeline::RangeScale,
    /// σ of (ℓx, ℓy, ℓθ) with the laser's range scale: `hypot(σ, σ_s·ℓ)` for ℓx, ℓy.
    pub sigma_total: [f64; 3],
    /// The laser's pose in the first laser's frame, `ℓ₁⁻¹ ⊕ ℓ_k`, with its covariance
    /// (from the joint covariance of ℓ₁ and ℓ_k, cross terms included); identity with
    /// zero covariance for the first laser.
    pub from_first: Between,
    /// The laser's nominal pose from its bag (`/tf_static` or the URDF for its scan
    /// topic's frame), when the bag has one: scan matching's first guess with
    /// `--nominal` (see docs/frames.md).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub nominal: Option<crate::report::NominalLaserPose>,
}

impl Report {
    /// Every laser's pose for export (empty with one laser).
    pub fn laser_poses(&self) -> Vec<crate::export::LaserPose> {
        self.lasers
            .iter()
            .map(|l| crate::export::LaserPose {
                topic: l.topic.clone(),
                l_x: l.l_x,
                l_y: l.l_y,
                l_theta: l.l_theta,
            })
            .collect()
    }
}

/// A pose relative to the first laser, with its covariance.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Between {
    /// x (m) in the first laser's frame.
    pub x: f64,
    /// y (m).
    pub y: f64,
    /// Heading (rad).
    pub theta: f64,
    /// σ of (x, y, θ).
    pub sigma: [f64; 3],
    /// Covariance of (x, y, θ).
    pub covariance: [[f64; 3]; 3],
}

/// The per-laser rows of a joint estimate with several lasers; `names` are the logs'
/// names and `topics` their bag scan topics, in the order of `joint.laser_of_log`.
pub fn laser_rows(
    joint: &JointOutcome,
    names: &[String],
    topics: &[Option<String>],
) -> Vec<LaserRow> {
    let Some(lasers) = &joint.lasers else {
        return Vec::new();
    };
    (0..lasers.lasers())
        .map(|k| {
            let mine: Vec<usize> = (0..joint.laser_of_log.len())
                .filter(|&i| joint.laser_of_log[i] == k)
                .collect();
            let p = lasers.params_of(k).laser;
            let c6 = lasers.covariance_of(k);
            let covariance: [[f64; 3]; 3] =
                std::array::from_fn(|i| std::array::from_fn(|j| c6[3 + i][3 + j]));
            let (t, tc) = lasers.from_first(k);
            let sigma = |c: &[[f64; 3]; 3]| std::array::from_fn(|i| c[i][i].max(0.0).sqrt());
            let range_scale = mine
                .first()
                .and_then(|&i| joint.logs.get(i))
                .map_or_else(odocal_pipeline::RangeScale::unknown, |o| {
                    o.range_scale.clone()
                });
            let data: [f64; 3] = sigma(&covariance);
            let s = range_scale.sigma;
            let sigma_total = [data[0].hypot(s * p.x), data[1].hypot(s * p.y), data[2]];
            LaserRow {
                range_scale,
                sigma_total,
                topic: mine.iter().find_map(|&i| topics.get(i).cloned().flatten()),
                logs: mine.iter().filter_map(|&i| names.get(i).cloned()).collect(),
                l_x: p.x,
                l_y: p.y,
                l_theta: p.theta,
                sigma: sigma(&covariance),
                covariance,
                samples: mine.iter().map(|&i| joint.contributions[i].samples).sum(),
                samples_used: mine
                    .iter()
                    .map(|&i| joint.contributions[i].samples_used)
                    .sum(),
                from_first: Between {
                    x: t.x,
                    y: t.y,
                    theta: t.theta,
                    sigma: sigma(&tc),
                    covariance: tc,
                },
                nominal: None,
            }
        })
        .collect()
}

/// The per-laser lines of the human summary.
pub(crate) fn write_laser_table(f: &mut fmt::Formatter<'_>, rows: &[LaserRow]) -> fmt::Result {
    writeln!(
        f,
        "  per laser (wheels shared; ℓ ± σ, and the pose in laser 1's frame):"
    )?;
    for (k, r) in rows.iter().enumerate() {
        let name = r.topic.clone().unwrap_or_else(|| r.logs.join(", "));
        // A held parameter (zero variance) says so instead of "± 0".
        let pm = |sigma: f64, scale: f64, digits: usize, unit: &str| {
            if sigma == 0.0 {
                " held".to_string()
            } else {
                format!(" ± {:.*}{unit}", digits, sigma * scale)
            }
        };
        write!(
            f,
            "    laser {} {}: ℓx {:+.2}{} mm, ℓy {:+.2}{} mm, ℓθ {:+.3}°{} ({} samples, {} used)",
            k + 1,
            name,
            r.l_x * 1e3,
            pm(r.sigma[0], 1e3, 2, ""),
            r.l_y * 1e3,
            pm(r.sigma[1], 1e3, 2, ""),
            r.l_theta.to_degrees(),
            pm(r.sigma[2], 180.0 / std::f64::consts::PI, 3, "°"),
            r.samples,
            r.samples_used
        )?;
        let b = &r.from_first;
        if k > 0 {
            write!(
                f,
                "; from laser 1: x {:+.2} ± {:.2} mm, y {:+.2} ± {:.2} mm, θ {:+.3}° ± {:.3}°",
                b.x * 1e3,
                b.sigma[0] * 1e3,
                b.y * 1e3,
                b.sigma[1] * 1e3,
                b.theta.to_degrees(),
                b.sigma[2].to_degrees()
            )?;
        }
        let scale = &r.range_scale;
        match &scale.sensor {
            Some(sensor) if scale.applies() => write!(
                f,
                "; {sensor}, {}: ℓx ± {:.2} mm, ℓy ± {:.2} mm with it",
                scale.label(),
                r.sigma_total[0] * 1e3,
                r.sigma_total[1] * 1e3
            )?,
            Some(sensor) => write!(f, "; {sensor}, no range-scale figure")?,
            None if scale.applies() => write!(f, "; {}", scale.label())?,
            None => write!(f, "; laser not recognised")?,
        }
        if let Some(n) = &r.nominal {
            write!(
                f,
                "; nominal from {} ({} -> {}): ℓx {:+.1} mm, ℓy {:+.1} mm, ℓθ {:+.2}°",
                n.source,
                n.base_frame,
                n.laser_frame,
                n.l_x * 1e3,
                n.l_y * 1e3,
                n.l_theta.to_degrees()
            )?;
        }
        writeln!(f)?;
    }
    Ok(())
}

/// The report of `joint`, the joint calibration of `logs` read from `paths` and named
/// `names` in the messages and rows (a bag read for several lasers is one name per
/// scan topic); `topics` are the logs' bag scan topics (`None` for text logs).
pub fn build_joint_report(
    paths: &[&Path],
    names: &[String],
    topics: &[Option<String>],
    logs: &[&Log],
    opts: &Options,
    joint: &JointOutcome,
) -> Report {
    let mut report = build_report(paths[0], logs[0], opts, &joint.joint);
    let mut distinct: Vec<String> = Vec::new();
    for p in paths {
        let p = p.display().to_string();
        if !distinct.contains(&p) {
            distinct.push(p);
        }
    }
    report.log = distinct.join(" + ");
    report.lasers = laser_rows(joint, names, topics);
    let c = &mut report.log_contents;
    for (i, log) in logs.iter().enumerate().skip(1) {
        c.scans += log.scans.len();
        // A bag read once per laser holds its wheel data once.
        if paths[..i].contains(&paths[i]) {
            continue;
        }
        c.encoder_records += log.encoders.len();
        c.skipped_lines += log.stats.skipped_lines;
        c.unknown_messages += log.stats.unknown.values().sum::<u64>();
    }
    let files = Files::new(paths, names, topics);
    // A log given in phases is compared as a whole: its phases get no finding.
    let in_phases = |i: usize| joint.phase_groups.iter().any(|g| g.logs.contains(&i));
    report.checks = joint
        .contributions
        .iter()
        .enumerate()
        .filter(|(i, _)| !in_phases(*i))
        .map(|(i, c)| agreement_finding(&c.agreement, i, names, &files, joint))
        .collect();
    report.logs = joint
        .contributions
        .iter()
        .zip(&joint.logs)
        .zip(names)
        .map(|((c, o), name)| {
            let own = Estimate::of(o);
            let checked = match &c.agreement {
                Consistency::Checked(h) => Some(h),
                Consistency::NotAvailable { .. } => None,
            };
            LogRow {
                path: name.clone(),
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
    report.logs_given = phase_group_rows(joint);
    report.phase_correlation = joint
        .phase_correlations
        .iter()
        .map(|(log, correlation)| PhaseCorrelationRow {
            log: log.clone(),
            correlation: *correlation,
        })
        .collect();
    report
        .checks
        .extend(joint.phase_groups.iter().map(phase_group_finding));
    report
}

/// With the phases of several logs: one row per log given, its phases together (its
/// clock offset: its first phase's).
fn phase_group_rows(joint: &JointOutcome) -> Vec<LogRow> {
    let own: Vec<&odocal_solver::Calibration> =
        joint.phase_groups.iter().map(|g| &g.calibration).collect();
    let shares = odocal_pipeline::log_agreement::information_shares(&own);
    joint
        .phase_groups
        .iter()
        .zip(shares)
        .map(|(g, information_share)| {
            let members = || g.logs.iter().filter_map(|&i| joint.contributions.get(i));
            let checked = match &g.agreement {
                Consistency::Checked(h) => Some(h),
                Consistency::NotAvailable { .. } => None,
            };
            let c = &g.calibration;
            LogRow {
                path: g.name.clone(),
                sha256: None,
                time_offset_s: g
                    .logs
                    .first()
                    .and_then(|&i| joint.logs.get(i))
                    .map_or(f64::NAN, |o| o.synced.time_offset),
                samples: members().map(|m| m.samples).sum(),
                samples_used: c.samples_used,
                information_share,
                own: FlatParams::from_array(c.params.to_vector()),
                own_sigma: std::array::from_fn(|i| c.covariance[i][i].max(0.0).sqrt()),
                chi2: checked.map(|h| h.chi2),
                dof: checked.map(|h| h.dof),
                agree: checked.map(|h| h.agree),
                disagreeing: checked.map(|h| h.disagreeing.clone()).unwrap_or_default(),
            }
        })
        .collect()
}

/// A log given, its phases together, against the joint estimate as a finding: a
/// warning, with what to do, when it disagrees.
fn phase_group_finding(group: &odocal_pipeline::PhaseGroupCheck) -> Finding {
    as_finding(&group.agreement, || {
        other_robot_advice(&format!("{} --all-pairs", group.name))
    })
}

/// One log's agreement as a finding: a warning, with what to do, when it disagrees:
/// log `index` of `names` (`files` are the log files given, `file_of[i]` the file of
/// log `i`; `joint` says which logs share a laser).
fn agreement_finding(
    agreement: &Consistency,
    index: usize,
    names: &[String],
    files: &Files,
    joint: &JointOutcome,
) -> Finding {
    // A phase of the log: its sentence says what a phase's disagreement means, and
    // the calibration is the log's.
    if joint.phases_of_one_log {
        return as_finding(agreement, String::new);
    }
    as_finding(agreement, || {
        let name = &names[index];
        let laser = joint.laser_of_log.get(index).copied().unwrap_or(0);
        let shares_laser = joint
            .laser_of_log
            .iter()
            .enumerate()
            .any(|(i, &k)| k == laser && files.file_of[i] != files.file_of[index]);
        let own = if shares_laser {
            format!(
                "; if {name}'s laser was mounted elsewhere, give it its own ℓ (`{}`, with \
                 the other options you gave)",
                files.own_laser_command(files.file_of[index])
            )
        } else {
            String::new()
        };
        format!(
            "{own}{}",
            other_robot_advice(&files.files[files.file_of[index]])
        )
    })
}

/// An agreement as a finding: a note when it agrees or was not compared; a warning
/// when it disagrees, its sentence followed by `advice()`.
fn as_finding(agreement: &Consistency, advice: impl FnOnce() -> String) -> Finding {
    match agreement {
        Consistency::Checked(h) if h.agree => {
            Finding::note(FindingKind::LogAgreement, h.sentence.clone())
        }
        Consistency::Checked(h) => Finding::warning(
            FindingKind::LogAgreement,
            format!("{}{}", h.sentence, advice()),
        ),
        Consistency::NotAvailable { reason } => {
            Finding::note(FindingKind::LogAgreement, reason.clone())
        }
    }
}

/// "; if it was recorded on another floor …": what to do with a log (calibrated on
/// its own by `odocal calibrate ARGS`) that disagrees with the others.
fn other_robot_advice(args: &str) -> String {
    format!(
        "; if it was recorded on another floor or on another robot, calibrate without it, \
         or on its own (`odocal calibrate {args}`)"
    )
}

/// The log files of a joint calibration and the scan topics read from them.
struct Files {
    /// Each file once, in the order given.
    files: Vec<String>,
    /// Per log: its file's index in `files`.
    file_of: Vec<usize>,
    /// The scan topics when a bag was read for several (each once).
    topics: Vec<String>,
}

impl Files {
    fn new(paths: &[&Path], names: &[String], topics: &[Option<String>]) -> Files {
        let mut files: Vec<String> = Vec::new();
        let file_of = paths
            .iter()
            .map(|p| {
                let p = p.display().to_string();
                match files.iter().position(|f| *f == p) {
                    Some(i) => i,
                    None => {
                        files.push(p);
                        files.len() - 1
                    }
                }
            })
            .collect();
        let several = names.len() > files.len();
        let mut listed: Vec<String> = Vec::new();
        for t in topics.iter().flatten() {
            if several && !listed.contains(t) {
                listed.push(t.clone());
            }
        }
        Files {
            files,
            file_of,
            topics: listed,
        }
    }

    /// `odocal calibrate FILES… [--scan-topic T…] --own-laser N` for file `file`.
    fn own_laser_command(&self, file: usize) -> String {
        let mut cmd = format!("odocal calibrate {}", self.files.join(" "));
        for t in &self.topics {
            cmd.push_str(&format!(" --scan-topic {t}"));
        }
        cmd.push_str(&format!(" --own-laser {}", file + 1));
        cmd
    }
}

/// A per-log table of the human summary, under `heading`.
pub(crate) fn write_log_table(
    f: &mut fmt::Formatter<'_>,
    heading: &str,
    rows: &[LogRow],
) -> fmt::Result {
    writeln!(f, "  {heading}")?;
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
