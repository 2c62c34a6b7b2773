//! One thing a reader of the results should notice: a data-health finding (clock jump,
//! wheel slip, …) or the verdict of a consistency check (the two halves of the log).
//! Every producer fills this one type, so the summary, `results.json` and the page
//! show all of them the same way.

use serde::Serialize;
use std::fmt;

/// What a finding is about: a data fault or a check of the result.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FindingKind {
    /// Encoder counters wrapping with no modulus given.
    EncoderWrap,
    /// Wheel angles in radians wrapped to one turn (ROS continuous joints).
    WheelAngleWrap,
    /// A stream's clock jumping backwards.
    ClockJump,
    /// Records slightly out of timestamp order (sorted by the reader).
    OutOfOrder,
    /// Records repeated exactly.
    Duplicate,
    /// Different records with the same timestamp (rounded timestamps).
    TimestampCollision,
    /// The laser repeating one scan.
    FrozenScan,
    /// Encoder counts jumping at a physically impossible wheel speed.
    EncoderSpike,
    /// A stream with a hole.
    Gap,
    /// A large offset between the laser clock and the encoder clock.
    ClockOffset,
    /// Scan matching and odometry disagreeing in rotation (wheel slip).
    Slip,
    /// The two halves of the samples calibrated separately and compared.
    TwoHalves,
    /// Wheel counts read at times that vary around their timestamps.
    ReadJitter,
    /// One log of a joint calibration against the joint estimate.
    LogAgreement,
    /// The phases of one log (`--all-pairs`) sharing part of their errors.
    PhaseCorrelation,
    /// Odometry-only mode on odometry whose heading is not integrated from the wheels
    /// (a gyro's or a filter's).
    GyroHeading,
    /// A skid-steer robot sliding sideways in its turns (`v_y = −k·v·ω`).
    LateralSlip,
    /// A phase of a log (`--all-pairs`) matched from first guesses by another phase's
    /// estimate: too few of its pairs matched from its own.
    PhaseGuesses,
}

impl FindingKind {
    /// Whether a fault of this kind takes records or scan pairs out of the data
    /// (repaired or left out: holes, jumps, repeats, frozen scans, impossible counts),
    /// so that it can be why too few samples remain. The others (a clock offset, slip,
    /// jitter, the checks of the result) leave every pair in.
    pub fn removes_samples(self) -> bool {
        matches!(
            self,
            FindingKind::EncoderWrap
                | FindingKind::WheelAngleWrap
                | FindingKind::ClockJump
                | FindingKind::OutOfOrder
                | FindingKind::Duplicate
                | FindingKind::TimestampCollision
                | FindingKind::FrozenScan
                | FindingKind::EncoderSpike
                | FindingKind::Gap
        )
    }

    /// Whether a fault of this kind can be why the data leave parameters undetermined.
    /// Not a clock offset: one found is estimated and applied before the verdicts (or,
    /// known, only reported), and the motion is what it is at either offset. Nor exact
    /// repeats: the record repeated is kept, so no motion is lost with the repeat.
    pub fn can_leave_parameters_undetermined(self) -> bool {
        !matches!(self, FindingKind::ClockOffset | FindingKind::Duplicate)
    }

    /// The snake_case name used in the JSON.
    pub fn name(self) -> &'static str {
        match self {
            FindingKind::EncoderWrap => "encoder_wrap",
            FindingKind::WheelAngleWrap => "wheel_angle_wrap",
            FindingKind::ClockJump => "clock_jump",
            FindingKind::OutOfOrder => "out_of_order",
            FindingKind::Duplicate => "duplicate",
            FindingKind::TimestampCollision => "timestamp_collision",
            FindingKind::FrozenScan => "frozen_scan",
            FindingKind::EncoderSpike => "encoder_spike",
            FindingKind::Gap => "gap",
            FindingKind::ClockOffset => "clock_offset",
            FindingKind::Slip => "slip",
            FindingKind::TwoHalves => "two_halves",
            FindingKind::ReadJitter => "read_jitter",
            FindingKind::LogAgreement => "log_agreement",
            FindingKind::PhaseCorrelation => "phase_correlation",
            FindingKind::GyroHeading => "gyro_heading",
            FindingKind::LateralSlip => "lateral_slip",
            FindingKind::PhaseGuesses => "phase_guesses",
        }
    }
}

/// How much a finding matters.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Severity {
    /// Noted; the results are not affected.
    Info,
    /// Data were changed or left out, or the results may be affected.
    Warning,
}

impl Severity {
    /// The word the summary and the page use.
    pub fn as_str(self) -> &'static str {
        match self {
            Severity::Info => "note",
            Severity::Warning => "warning",
        }
    }
}

/// One finding: what kind, how much it matters, how often, where, and in words what
/// was found, what was done and what the user can do.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Finding {
    /// The kind.
    pub kind: FindingKind,
    /// How much it matters.
    pub severity: Severity,
    /// How many records, samples or episodes it concerns.
    pub count: u64,
    /// 1-based line of the first occurrence in the log, when known.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub first_line: Option<u64>,
    /// Timestamp (s, the stream's own clock) of the first occurrence, when known.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub time: Option<f64>,
    /// Time spans `[start, end]` (s, laser clock) it covers, e.g. slip episodes: the
    /// figures over time shade them.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub spans: Vec<[f64; 2]>,
    /// What was found, what was done, what the user can do.
    pub message: String,
}

impl Finding {
    /// A finding of `kind` and `severity` concerning one thing, with no place given;
    /// [`Finding::count`] and [`Finding::at`] add those.
    pub fn new(kind: FindingKind, severity: Severity, message: impl Into<String>) -> Self {
        Finding {
            kind,
            severity,
            count: 1,
            first_line: None,
            time: None,
            spans: Vec::new(),
            message: message.into(),
        }
    }

    /// A warning: data were changed or left out, or the results may be affected.
    pub fn warning(kind: FindingKind, message: impl Into<String>) -> Self {
        Finding::new(kind, Severity::Warning, message)
    }

    /// A note: the results are not affected.
    pub fn note(kind: FindingKind, message: impl Into<String>) -> Self {
        Finding::new(kind, Severity::Info, message)
    }

    /// The same finding concerning `count` records, samples or episodes.
    pub fn count(self, count: u64) -> Self {
        Finding { count, ..self }
    }

    /// The same finding with its first occurrence at `line` (1-based, when known) and
    /// time `t` (s).
    pub fn at(self, line: impl Into<Option<u64>>, t: f64) -> Self {
        Finding {
            first_line: line.into(),
            time: Some(t),
            ..self
        }
    }

    /// The same finding covering the time spans `spans` (s, laser clock).
    pub fn spans(self, spans: Vec<[f64; 2]>) -> Self {
        Finding { spans, ..self }
    }
}

impl fmt::Display for Finding {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} [{}]: {}",
            self.severity.as_str(),
            self.kind.name(),
            self.message
        )
    }
}

/// The findings that can explain a refusal (warnings), joined into one sentence.
pub fn explain(findings: &[Finding]) -> Option<String> {
    let w: Vec<&str> = findings
        .iter()
        .filter(|f| f.severity == Severity::Warning)
        .map(|f| f.message.as_str())
        .collect();
    (!w.is_empty()).then(|| w.join("; "))
}
