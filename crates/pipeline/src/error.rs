//! Why the pipeline could not produce a calibration, in one sentence each.

use crate::rejection::{Rejection, RejectionCounts};
use crate::sync::{DiscardCounts, DiscardReason};
use odocal_log::LogError;
use odocal_solver::SolveError;

/// An error of the pipeline.
#[derive(Debug, thiserror::Error)]
pub enum PipelineError {
    /// The log could not be read or lacks what calibration needs.
    #[error(transparent)]
    Log(#[from] LogError),
    /// Too few scan pairs survived synchronization and matching.
    #[error(
        "only {usable} usable sample(s) out of {pairs} scan pairs (discarded: {}); at least \
         {needed} are needed{}",
        describe_discards(.discarded),
        why_too_few(.discarded, .match_rejections, *.scan_returns)
    )]
    TooFewSamples {
        /// Samples that survived, not counting matches along a corridor (which fix
        /// two directions of ŝ only).
        usable: usize,
        /// Scan pairs considered.
        pairs: usize,
        /// The minimum the pipeline asks for.
        needed: usize,
        /// Discarded pairs per reason.
        discarded: DiscardCounts,
        /// Of the pairs discarded because the matcher refused them, how many per
        /// reason.
        match_rejections: RejectionCounts,
        /// The scans' median returns and rays per scan, when known.
        scan_returns: Option<crate::matching::ScanReturns>,
    },
    /// The solver refused (not excited, too few samples after trimming, …).
    #[error(transparent)]
    Solve(#[from] SolveError),
    /// The solver returned numbers, but some parameters are so poorly determined
    /// (verdict "weak" or "not excited") that they would mislead.
    #[error(
        "the data do not determine {} well enough{}: {sentence}{}{} ({}){}",
        parameters.join(", "),
        because(&diagnosis.causes),
        holds_sentence(&diagnosis.holds),
        caveat_sentence(&diagnosis.caveat),
        way_out(diagnosis.no_hold),
        also_found(&diagnosis.faults)
    )]
    NotDetermined {
        /// The parameters concerned (`r_L`, `r_R`, `b`, `l_x`, `l_y`, `l_theta`).
        parameters: Vec<String>,
        /// The solver's observability sentence: what motion is missing.
        sentence: String,
        /// Its causes, the way out, and what else weakens the verdicts.
        diagnosis: Box<crate::refusal::Diagnosis>,
    },
    /// Calibration failed, and the data-health stage found faults in the log that
    /// explain it: the faults come first, then what failed.
    #[error("the log has data faults: {faults}; as a result, {cause}")]
    DataFault {
        /// The faults found (the warnings' messages, joined).
        faults: String,
        /// What failed, without the generic advice.
        cause: String,
        /// The underlying refusal.
        refusal: Box<PipelineError>,
    },
    /// Too few samples, and the log has data faults that do not take pairs out (a
    /// clock offset, slip): the refusal first, then the faults, not named as its
    /// cause.
    #[error("{refusal}; also found in the log (not the cause): {faults}")]
    AlsoFound {
        /// The refusal.
        refusal: Box<PipelineError>,
        /// The faults found (the warnings' messages, joined).
        faults: String,
    },
    /// A setting is out of range.
    #[error("invalid setting: {0}")]
    InvalidSetting(String),
    /// The log's numbers cannot be those of a real robot (timestamps in the wrong
    /// unit, encoder counts at an impossible rate): calibrating would give wrong
    /// numbers.
    #[error("implausible log: {0}")]
    Implausible(String),
}

impl PipelineError {
    /// Names the data faults found in front of a refusal (not enough samples, not
    /// determined, the solver's refusals) when there are any; other errors unchanged.
    pub fn with_faults(self, findings: &[crate::finding::Finding]) -> Self {
        let refusal = matches!(
            self,
            PipelineError::TooFewSamples { .. }
                | PipelineError::NotDetermined { .. }
                | PipelineError::Solve(_)
                | PipelineError::Log(LogError::MissingData { .. })
        );
        let Some(faults) = crate::finding::explain(findings).filter(|_| refusal) else {
            return self;
        };
        // Too few samples: only faults that take pairs out can be why; the others are
        // named after the refusal.
        if let PipelineError::TooFewSamples { .. } = self {
            let (removing, others): (Vec<_>, Vec<_>) = findings
                .iter()
                .cloned()
                .partition(|f| f.kind.removes_samples());
            let refused = match crate::finding::explain(&others) {
                Some(faults) if removing.is_empty() => {
                    return PipelineError::AlsoFound {
                        refusal: Box::new(self),
                        faults,
                    }
                }
                Some(others) => format!("; also found in the log (not the cause): {others}"),
                None => String::new(),
            };
            let faults = crate::finding::explain(&removing).unwrap_or(faults);
            let cause = format!("{}{refused}", too_few_cause(&self));
            return PipelineError::DataFault {
                faults,
                cause,
                refusal: Box::new(self),
            };
        }
        // The trajectory or the matching explains it: the faults are only also found
        // (those that are not the cause itself).
        let refused = match self {
            PipelineError::NotDetermined {
                parameters,
                sentence,
                mut diagnosis,
            } if !diagnosis.causes.is_empty() => {
                let others: Vec<crate::finding::Finding> = findings
                    .iter()
                    .filter(|f| !diagnosis.causes.contains(&f.message))
                    .cloned()
                    .collect();
                diagnosis.faults = crate::finding::explain(&others);
                return PipelineError::NotDetermined {
                    parameters,
                    sentence,
                    diagnosis,
                };
            }
            // No fault found can be why (a clock offset): they are only also found.
            PipelineError::NotDetermined {
                parameters,
                sentence,
                mut diagnosis,
            } if findings
                .iter()
                .filter(|f| f.severity == crate::finding::Severity::Warning)
                .all(|f| !f.kind.can_leave_parameters_undetermined()) =>
            {
                diagnosis.faults = Some(faults);
                return PipelineError::NotDetermined {
                    parameters,
                    sentence,
                    diagnosis,
                };
            }
            other => other,
        };
        PipelineError::DataFault {
            faults,
            cause: refused.to_string(),
            refusal: Box::new(refused),
        }
    }

    /// The stride the refused calibration paired its scans at (through a data-fault
    /// wrapper; 0 for other errors).
    pub fn stride(&self) -> usize {
        match self {
            PipelineError::NotDetermined { diagnosis, .. } => diagnosis.stride,
            PipelineError::DataFault { refusal, .. } | PipelineError::AlsoFound { refusal, .. } => {
                refusal.stride()
            }
            _ => 0,
        }
    }

    /// The parameters to hold that the refusal proposes (through a data-fault wrapper).
    pub fn holds(&self) -> &[crate::refusal::Hold] {
        match self {
            PipelineError::NotDetermined { diagnosis, .. } => &diagnosis.holds,
            PipelineError::DataFault { refusal, .. } | PipelineError::AlsoFound { refusal, .. } => {
                refusal.holds()
            }
            _ => &[],
        }
    }
}

/// A too-few-samples refusal worded as the result of data faults ("only … remain").
fn too_few_cause(refusal: &PipelineError) -> String {
    match refusal {
        PipelineError::TooFewSamples {
            usable,
            pairs,
            needed,
            discarded,
            match_rejections,
            scan_returns,
        } => format!(
            "only {usable} usable sample(s) remain out of {pairs} scan pairs (discarded: {}; \
             at least {needed} are needed){}",
            describe_discards(discarded),
            why_too_few(discarded, match_rejections, *scan_returns)
        ),
        other => other.to_string(),
    }
}

fn because(causes: &[String]) -> String {
    if causes.is_empty() {
        String::new()
    } else {
        format!(" because {}", causes.join(", and "))
    }
}

/// The generic way out of a refusal for poorly determined parameters: hold the known
/// ones (unless holding cannot help), or see the numbers anyway.
fn way_out(no_hold: bool) -> &'static str {
    if no_hold {
        "pass --accept-weak to see the numbers anyway, all weak"
    } else {
        "if some of them are known, hold them with --fix NAME=VALUE or give a prior with \
         --prior NAME=VALUE±SIGMA, SI units; pass --accept-weak to see the numbers anyway"
    }
}

fn holds_sentence(holds: &[crate::refusal::Hold]) -> String {
    if holds.is_empty() {
        String::new()
    } else {
        format!("; {}", crate::refusal::describe_holds(holds))
    }
}

fn caveat_sentence(caveat: &Option<String>) -> String {
    caveat.as_ref().map_or(String::new(), |c| format!("; {c}"))
}

fn also_found(faults: &Option<String>) -> String {
    faults.as_ref().map_or(String::new(), |f| {
        format!("; also found in the log (not the cause): {f}")
    })
}

/// Why so few pairs remain, and what to do: the matcher's refusals by reason with the
/// advice for the most common one when matching lost most pairs; else what the
/// largest discard says about the recording.
fn why_too_few(
    d: &DiscardCounts,
    rejections: &RejectionCounts,
    scan_returns: Option<crate::matching::ScanReturns>,
) -> String {
    let largest = [
        DiscardReason::MatchFailed,
        DiscardReason::RobotStill,
        DiscardReason::EncoderGap,
        DiscardReason::IntervalTooLong,
    ]
    .into_iter()
    .map(|r| (r, d.get(r)))
    .filter(|&(_, n)| n > 0)
    .max_by_key(|&(_, n)| n);
    match largest {
        Some((DiscardReason::MatchFailed, failed)) => {
            let Some((reason, n)) = rejections.most_common() else {
                return format!(
                    ": the scan matcher refused {failed} pairs; check the scans (`odocal info \
                     LOG`)"
                );
            };
            let by_reason: Vec<String> = rejections
                .0
                .iter()
                .filter(|(_, n)| **n > 0)
                .map(|(k, n)| format!("{k} {n}"))
                .collect();
            // Sparse scans explain refusals for too few correspondences, an unfixed
            // direction or unusable scans: the numbers say so.
            let sparse = match (reason, scan_returns) {
                (
                    Rejection::Correspondences | Rejection::Conditioning | Rejection::Scan,
                    Some(crate::matching::ScanReturns { median, rays }),
                ) if rays > 0 && 2 * median < rays => format!(
                    " (this log's scans have a median of {median} returns of {rays} rays: \
                     a sparse laser sees little of the scene, so drive near walls and \
                     furniture in every direction)"
                ),
                _ => String::new(),
            };
            format!(
                ": the scan matcher refused {failed} pairs ({}); most often {} ({n}): {}{sparse}",
                by_reason.join(", "),
                reason.key(),
                reason.advice()
            )
        }
        Some((DiscardReason::RobotStill, _)) => {
            ": the robot stood still through most of the log; record it driving (straights, \
             arcs and spins in place)"
                .into()
        }
        Some((DiscardReason::EncoderGap, _)) => {
            ": the wheel counts do not cover most scan pairs; check the encoder stream (its \
             rate and gaps: `odocal info LOG`)"
                .into()
        }
        Some((DiscardReason::IntervalTooLong, _)) => {
            ": most scan pairs lie further apart in time than their stride allows (scans \
             missing from the log); check the laser's rate and driver (`odocal info LOG`)"
                .into()
        }
        _ => " — drive longer, or check the encoder stream and the scans".into(),
    }
}

fn describe_discards(d: &DiscardCounts) -> String {
    let parts: Vec<String> =
        d.0.iter()
            .filter(|(_, n)| **n > 0)
            .map(|(k, n)| format!("{n} {}", k.replace('_', " ")))
            .collect();
    if parts.is_empty() {
        "none".into()
    } else {
        parts.join(", ")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Too few samples with a fault that takes pairs out, and one that does not: only
    /// the first is named as the cause; without it, the refusal is the matcher's and
    /// the other is named after it as not the cause.
    #[test]
    fn too_few_samples_blame_only_faults_that_take_pairs_out() {
        use crate::finding::{Finding, FindingKind};
        let refusal = || {
            let mut discarded = DiscardCounts::default();
            let mut match_rejections = RejectionCounts::default();
            for _ in 0..161 {
                discarded.add(DiscardReason::MatchFailed);
                match_rejections.add(Rejection::Correspondences);
            }
            PipelineError::TooFewSamples {
                usable: 19,
                pairs: 188,
                needed: 20,
                discarded,
                match_rejections,
                scan_returns: None,
            }
        };
        let offset = Finding::warning(
            FindingKind::ClockOffset,
            "the laser clock looks offset from the encoder clock by about +0.17 s",
        );
        let gap = Finding::warning(FindingKind::Gap, "the encoder stream has a 12 s hole");
        let alone = refusal().with_faults(std::slice::from_ref(&offset));
        assert!(matches!(alone, PipelineError::AlsoFound { .. }));
        let said = alone.to_string();
        assert!(said.starts_with("only 19 usable sample(s)"), "{said}");
        assert!(!said.contains("data faults"), "{said}");
        assert!(
            said.ends_with(
                "; also found in the log (not the cause): the laser clock looks offset from \
                 the encoder clock by about +0.17 s"
            ),
            "{said}"
        );
        let both = refusal().with_faults(&[offset, gap]);
        assert!(matches!(both, PipelineError::DataFault { .. }));
        let said = both.to_string();
        assert!(
            said.starts_with(
                "the log has data faults: the encoder stream has a 12 s hole; as a result, \
                 only 19 usable sample(s) remain"
            ),
            "{said}"
        );
        assert!(
            said.ends_with(
                "; also found in the log (not the cause): the laser clock looks offset from \
                 the encoder clock by about +0.17 s"
            ),
            "{said}"
        );
    }

    #[test]
    fn a_clock_offset_is_not_why_the_motion_leaves_parameters_weak() {
        use crate::finding::{Finding, FindingKind};
        let refusal = || PipelineError::NotDetermined {
            parameters: vec!["b".into(), "l_x".into(), "l_y".into()],
            sentence: "the motion does not excite them (0 spins in place, 46 straight)".into(),
            diagnosis: Box::default(),
        };
        let offset = Finding::warning(
            FindingKind::ClockOffset,
            "the laser clock looks offset from the encoder clock by about +0.19 s",
        );
        let said = refusal()
            .with_faults(std::slice::from_ref(&offset))
            .to_string();
        assert!(
            said.starts_with("the data do not determine b, l_x, l_y"),
            "{said}"
        );
        assert!(!said.contains("as a result"), "{said}");
        assert!(
            said.ends_with(
                "; also found in the log (not the cause): the laser clock looks offset from \
                 the encoder clock by about +0.19 s"
            ),
            "{said}"
        );
        // A fault that takes samples out may be the cause: named first, as before.
        let gap = Finding::warning(FindingKind::Gap, "the encoder stream has a 12 s hole");
        let said = refusal().with_faults(&[offset, gap]).to_string();
        assert!(said.starts_with("the log has data faults:"), "{said}");
    }

    fn too_few(discards: &[(DiscardReason, usize)], refused: &[(Rejection, usize)]) -> String {
        let mut discarded = DiscardCounts::default();
        for &(r, n) in discards {
            for _ in 0..n {
                discarded.add(r);
            }
        }
        let mut match_rejections = RejectionCounts::default();
        for &(r, n) in refused {
            for _ in 0..n {
                match_rejections.add(r);
            }
        }
        PipelineError::TooFewSamples {
            usable: 3,
            pairs: 299,
            needed: 20,
            discarded,
            match_rejections,
            scan_returns: Some(crate::matching::ScanReturns {
                median: 69,
                rays: 361,
            }),
        }
        .to_string()
    }

    #[test]
    fn too_few_samples_names_what_lost_the_pairs_and_what_to_do() {
        // A sparse laser's log (the simulated Neato, seed 101): matching lost them.
        let said = too_few(
            &[(DiscardReason::MatchFailed, 296)],
            &[
                (Rejection::Conditioning, 132),
                (Rejection::Correspondences, 103),
                (Rejection::Overlap, 31),
            ],
        );
        assert!(
            said.contains("the scan matcher refused 296 pairs (conditioning 132, correspondences 103, overlap 31); most often conditioning (132)"),
            "{said}"
        );
        assert!(said.contains(Rejection::Conditioning.advice()), "{said}");
        assert!(
            said.contains("a median of 69 returns of 361 rays"),
            "{said}"
        );
        // A robot that hardly moved.
        let said = too_few(
            &[
                (DiscardReason::RobotStill, 250),
                (DiscardReason::MatchFailed, 40),
            ],
            &[(Rejection::Overlap, 40)],
        );
        assert!(said.contains("stood still"), "{said}");
        assert!(!said.contains("median of"), "{said}");
        assert!(!said.contains("most often"), "{said}");
        // Wheel counts missing, scans missing.
        let said = too_few(&[(DiscardReason::EncoderGap, 280)], &[]);
        assert!(said.contains("check the encoder stream"), "{said}");
        let said = too_few(&[(DiscardReason::IntervalTooLong, 280)], &[]);
        assert!(said.contains("scans missing"), "{said}");
        // Nothing discarded: the log is short.
        assert!(too_few(&[], &[]).contains("drive longer"));
    }
}
