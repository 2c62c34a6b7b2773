//! The one error type of this crate: what went wrong, where (file, 1-based line), and
//! what was expected.

use std::fmt;

/// An error while reading (or writing) a log or a tuple file.
#[derive(Debug, thiserror::Error)]
pub enum LogError {
    /// A malformed line of a known message (or a malformed JSON object).
    #[error("{file}:{line}: {message}: {expected}")]
    Parse {
        /// The file (or stream name) being read.
        file: String,
        /// 1-based line number.
        line: u64,
        /// The message name (`ENCODER`, `RAWLASER1`, … or `JSON` / `tuple`).
        message: String,
        /// What was expected and what was found.
        expected: String,
    },
    /// The input is not a text log (NUL bytes: a binary file, `/dev/zero`, …).
    #[error("{file}:{line}: not a text log: {detail}")]
    NotText {
        /// The file (or stream name).
        file: String,
        /// 1-based line where the binary data were found.
        line: u64,
        /// What was found (e.g. a NUL byte at a column).
        detail: String,
    },
    /// Reading or writing failed at the operating-system level.
    ///
    /// The OS error is part of the message (not a separate `source`), so that error
    /// chains printed with `{:#}` do not repeat it.
    #[error("{file}: {error}")]
    Io {
        /// The file (or stream name).
        file: String,
        /// The underlying error.
        error: std::io::Error,
    },
    /// A reader option (usually from the command line) has an impossible value.
    #[error("invalid {option}: expected {expected}")]
    InvalidOption {
        /// Which option.
        option: &'static str,
        /// What was expected.
        expected: &'static str,
    },
    /// The log parsed but lacks something needed for calibration.
    #[error("{file}: {what}")]
    MissingData {
        /// The file (or stream name).
        file: String,
        /// What is missing, with a sentence saying how to supply it.
        what: MissingData,
    },
}

/// Data a log must hold before it can be used for calibration.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MissingData {
    /// No `ENCODER` record at all.
    NoEncoderRecords,
    /// Fewer than two scans (`RAWLASER1`, `ROBOTLASER1` or `FLASER`).
    TooFewScans {
        /// How many scans the log holds.
        found: usize,
    },
    /// No encoder ticks per wheel revolution from the log or the command line.
    NoTicksPerRevolution,
}

impl fmt::Display for MissingData {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            MissingData::NoEncoderRecords => write!(
                f,
                "the log has no ENCODER records; calibration needs the cumulative wheel \
                 encoder counts as `ENCODER left_ticks right_ticks timestamp hostname \
                 logger_timestamp` lines"
            ),
            MissingData::TooFewScans { found } => write!(
                f,
                "the log has {found} laser scan(s) but calibration needs at least two; \
                 log the range finder as RAWLASER1, ROBOTLASER1 or FLASER lines"
            ),
            MissingData::NoTicksPerRevolution => write!(
                f,
                "encoder ticks per wheel revolution are unknown; pass `--ticks-per-rev X` \
                 on the command line or add a line `PARAM robot_wheel_ticks_per_revolution X` \
                 to the log"
            ),
        }
    }
}

impl LogError {
    /// A parse error at `file:line` in message `message`.
    pub fn parse(
        file: impl Into<String>,
        line: u64,
        message: impl Into<String>,
        expected: impl Into<String>,
    ) -> Self {
        LogError::Parse {
            file: file.into(),
            line,
            message: message.into(),
            expected: expected.into(),
        }
    }

    /// An I/O error on `file`.
    pub fn io(file: impl Into<String>, source: std::io::Error) -> Self {
        LogError::Io {
            file: file.into(),
            error: source,
        }
    }

    /// The 1-based line number, for parse errors.
    pub fn line(&self) -> Option<u64> {
        match self {
            LogError::Parse { line, .. } | LogError::NotText { line, .. } => Some(*line),
            _ => None,
        }
    }
}
