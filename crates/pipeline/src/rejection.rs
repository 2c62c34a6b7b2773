//! Why the scan matcher refused a pair, by reason, with what to do about each.

use odocal_icp::IcpError;
use serde::Serialize;
use std::collections::BTreeMap;
use std::fmt;

/// The reason a pair's match was refused.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Rejection {
    /// The result matched too small a share of the current scan.
    Overlap,
    /// The residuals were far above the scans' own range noise (a wrong alignment).
    Residuals,
    /// The result was too far from the first guess.
    Correction,
    /// Too few points found a reference segment.
    Correspondences,
    /// The scans do not constrain some direction of the displacement.
    Conditioning,
    /// Two distinct, equally consistent alignments.
    Ambiguity,
    /// The iterations did not settle.
    Convergence,
    /// A scan of the pair was unusable (too few valid readings, bad geometry).
    Scan,
    /// Anything else (numerical failure, no encoder coverage of the sweep, …).
    Other,
}

impl Rejection {
    /// Every reason, in report order.
    pub const ALL: [Rejection; 9] = [
        Rejection::Overlap,
        Rejection::Residuals,
        Rejection::Correction,
        Rejection::Correspondences,
        Rejection::Conditioning,
        Rejection::Ambiguity,
        Rejection::Convergence,
        Rejection::Scan,
        Rejection::Other,
    ];

    /// The snake_case key used in reports and JSON.
    pub fn key(self) -> &'static str {
        match self {
            Rejection::Overlap => "overlap",
            Rejection::Residuals => "residuals",
            Rejection::Correction => "correction",
            Rejection::Correspondences => "correspondences",
            Rejection::Conditioning => "conditioning",
            Rejection::Ambiguity => "ambiguity",
            Rejection::Convergence => "convergence",
            Rejection::Scan => "scan",
            Rejection::Other => "other",
        }
    }

    /// What a user can do when this reason is common.
    pub fn advice(self) -> &'static str {
        match self {
            Rejection::Overlap => {
                "the scans of a pair see too little of the same scene: pair closer scans \
                 (--stride 1 or 2), or drive slower"
            }
            Rejection::Residuals => {
                "the matches leave residuals far above the laser's noise (wrong alignments, \
                 or moving people and clutter): pair closer scans (--stride 1 or 2)"
            }
            Rejection::Correction => {
                "the matches end far from their first guesses: give the nominal parameters \
                 (--nominal r_L,r_R,b) so that odometry guesses the motion; matched again \
                 from the first estimate, a match farther from odometry than the log's \
                 other pairs allow is a wrong alignment or a slip of the wheels (drive \
                 slower, on a floor that grips)"
            }
            Rejection::Correspondences => {
                "the scans have too few returns in common (open space, dark or glass \
                 surfaces): drive closer to walls, or pair closer scans"
            }
            Rejection::Conditioning => {
                "the scene does not fix some direction (a corridor, one wall): drive where \
                 walls in two directions are in view"
            }
            Rejection::Ambiguity => {
                "the scene repeats itself (equal rooms, pillars): pair closer scans, or \
                 give --nominal for better first guesses"
            }
            Rejection::Convergence => "the matches did not settle: pair closer scans",
            Rejection::Scan => "scans with too few valid readings: check the laser",
            Rejection::Other => "see the log's health findings",
        }
    }

    /// The reason of a matcher error.
    pub fn of(error: &IcpError) -> Self {
        match error {
            IcpError::SmallOverlap { .. } => Rejection::Overlap,
            IcpError::ResidualAboveNoise { .. } => Rejection::Residuals,
            IcpError::CorrectionTooLarge { .. } => Rejection::Correction,
            IcpError::TooFewCorrespondences { .. } => Rejection::Correspondences,
            IcpError::Ambiguous { .. } => Rejection::Ambiguity,
            IcpError::FailedToConverge { .. } => Rejection::Convergence,
            IcpError::TooFewValidPoints { .. } | IcpError::InvalidScan(_) => Rejection::Scan,
            IcpError::InvalidParams(_)
            | IcpError::NonFiniteGuess(_)
            | IcpError::Numerical { .. } => Rejection::Other,
        }
    }
}

/// A pair the matcher refused: the reason and the matcher's message.
#[derive(Debug, Clone, PartialEq)]
pub struct MatchFailure {
    /// The reason.
    pub reason: Rejection,
    /// What the matcher said.
    pub message: String,
}

impl MatchFailure {
    /// A failure for `reason` with `message`.
    pub fn new(reason: Rejection, message: impl Into<String>) -> Self {
        MatchFailure {
            reason,
            message: message.into(),
        }
    }
}

impl fmt::Display for MatchFailure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

/// How many pairs the matcher refused, per reason (every reason present, possibly 0).
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
#[serde(transparent)]
pub struct RejectionCounts(pub BTreeMap<&'static str, usize>);

impl Default for RejectionCounts {
    fn default() -> Self {
        RejectionCounts(Rejection::ALL.iter().map(|r| (r.key(), 0)).collect())
    }
}

impl RejectionCounts {
    /// Counts one refused pair.
    pub fn add(&mut self, reason: Rejection) {
        *self.0.entry(reason.key()).or_insert(0) += 1;
    }

    /// Refused pairs for `reason`.
    pub fn get(&self, reason: Rejection) -> usize {
        self.0.get(reason.key()).copied().unwrap_or(0)
    }

    /// Refused pairs in all.
    pub fn total(&self) -> usize {
        self.0.values().sum()
    }

    /// The most common reason, when any pair was refused.
    pub fn most_common(&self) -> Option<(Rejection, usize)> {
        Rejection::ALL
            .iter()
            .map(|&r| (r, self.get(r)))
            .filter(|&(_, n)| n > 0)
            .max_by_key(|&(r, n)| (n, std::cmp::Reverse(r)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_matcher_error_has_its_reason() {
        let overlap = IcpError::SmallOverlap {
            share_percent: 50.0,
            min_percent: 70.0,
        };
        assert_eq!(Rejection::of(&overlap), Rejection::Overlap);
        let few = IcpError::TooFewCorrespondences {
            found: 3,
            needed: 20,
            iteration: 1,
        };
        assert_eq!(Rejection::of(&few), Rejection::Correspondences);
        let mut counts = RejectionCounts::default();
        assert_eq!(counts.most_common(), None);
        counts.add(Rejection::of(&overlap));
        counts.add(Rejection::of(&few));
        counts.add(Rejection::of(&few));
        assert_eq!(counts.total(), 3);
        assert_eq!(counts.most_common(), Some((Rejection::Correspondences, 2)));
        assert_eq!(counts.0.len(), Rejection::ALL.len());
    }
}
