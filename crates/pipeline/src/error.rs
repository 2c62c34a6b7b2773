//! Why the pipeline could not produce a calibration, in one sentence each.

use crate::sync::DiscardCounts;
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
         {needed} are needed — drive longer, or check the encoder stream and the scans",
        describe_discards(.discarded)
    )]
    TooFewSamples {
        /// Samples that survived.
        usable: usize,
        /// Scan pairs considered.
        pairs: usize,
        /// The minimum the pipeline asks for.
        needed: usize,
        /// Discarded pairs per reason.
        discarded: DiscardCounts,
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
            other => other,
        };
        let cause = match &refused {
            PipelineError::TooFewSamples {
                usable,
                pairs,
                needed,
                discarded,
            } => format!(
                "only {usable} usable sample(s) remain out of {pairs} scan pairs (discarded: \
                 {}; at least {needed} are needed)",
                describe_discards(discarded)
            ),
            other => other.to_string(),
        };
        PipelineError::DataFault {
            faults,
            cause,
            refusal: Box::new(refused),
        }
    }

    /// The parameters to hold that the refusal proposes (through a data-fault wrapper).
    pub fn holds(&self) -> &[crate::refusal::Hold] {
        match self {
            PipelineError::NotDetermined { diagnosis, .. } => &diagnosis.holds,
            PipelineError::DataFault { refusal, .. } => refusal.holds(),
            _ => &[],
        }
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
