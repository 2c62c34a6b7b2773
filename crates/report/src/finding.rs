//! One thing the report wants a reader to notice: a data-health finding (clock jump,
//! wheel slip, …) or the verdict of a consistency check (the two halves of the log).
//! Every producer fills this one type, so the summary, `results.json` and the page
//! show all of them the same way.

use serde::Serialize;
use std::fmt;

/// How much a finding matters.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Severity {
    /// Noted; the results are not affected.
    Info,
    /// Data were changed or left out, or the results may be affected.
    Warning,
    /// The results should not be trusted.
    Error,
}

impl Severity {
    /// The word the summary and the page use.
    pub fn as_str(self) -> &'static str {
        match self {
            Severity::Info => "note",
            Severity::Warning => "warning",
            Severity::Error => "error",
        }
    }
}

/// One finding: what kind, how much it matters, how often, where, and in words what
/// was found, what was done and what the user can do.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Finding {
    /// Short snake_case name of the kind (`clock_jump`, `slip`, `two_halves`, …).
    pub kind: String,
    /// How much it matters.
    pub severity: Severity,
    /// How many records, samples or episodes it concerns.
    pub count: u64,
    /// 1-based line of the first occurrence in the log, when known.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub first_line: Option<u64>,
    /// Timestamp (s, laser clock) of the first occurrence, when known.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub time: Option<f64>,
    /// Time spans `[start, end]` (s, laser clock) it covers, e.g. slip episodes: the
    /// figures over time shade them.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub spans: Vec<[f64; 2]>,
    /// What was found, what was done, what the user can do.
    pub message: String,
}

impl fmt::Display for Finding {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} [{}]: {}",
            self.severity.as_str(),
            self.kind,
            self.message
        )
    }
}
