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
    /// A setting is out of range.
    #[error("invalid setting: {0}")]
    InvalidSetting(String),
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
