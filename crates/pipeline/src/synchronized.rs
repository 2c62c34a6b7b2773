//! The per-log data between synchronization and the solve: [`Synchronized`] (samples
//! ready for the solver and what was thrown away), read by the health checks and the
//! clock-offset search.

use crate::rejection::RejectionCounts;
use crate::samples::PairSample;
use crate::self_check::MatchSelfCheck;
use crate::sync::{DiscardCounts, SyncLimits};

/// Samples ready for the solver, and what was thrown away.
#[derive(Debug, Clone)]
pub struct Synchronized {
    /// Scans between the two of a pair.
    pub stride: usize,
    /// The thresholds used.
    pub limits: SyncLimits,
    /// Ticks per revolution used.
    pub ticks_per_revolution: f64,
    /// Scan pairs considered.
    pub pairs: usize,
    /// Pairs that became samples, in time order.
    pub samples: Vec<PairSample>,
    /// Pairs discarded, per reason.
    pub discarded: DiscardCounts,
    /// The pairs counted in `discarded` as `match_failed`, by the matcher's reason.
    pub match_rejections: RejectionCounts,
    /// The matcher's own error per pair, from the closure of scan triples (see
    /// [`crate::self_check`]); `None` when too few triples close.
    pub match_self_check: Option<MatchSelfCheck>,
    /// Clock offset used (s): laser clock minus encoder clock.
    pub time_offset: f64,
    /// The scans were swept and the samples were matched after moving every ray to
    /// the sensor frame at its scan's reference time (see [`crate::sweep`]).
    pub sweep_compensated: bool,
    /// Standard deviation (s) of the read-time error left in the wheel counts after
    /// smoothing, when they were read at jittery times (see
    /// [`crate::health::read_jitter`]); the solver's covariance accounts for it.
    pub read_time_sigma: Option<f64>,
    /// A timing fault nothing repairs (see [`crate::health::scan_jitter`]), in words:
    /// while it is set no parameter is judged well determined.
    pub unrepaired_timing: Option<String>,
    /// In odometry-only mode, an odometry heading that does not come from the wheels
    /// (see [`crate::health::gyro_heading`]), in words: while it is set no parameter is
    /// judged well determined.
    pub heading_not_from_wheels: Option<String>,
    /// A sideways slide in turns that the model solved cannot hold (several lasers
    /// solved together, one of whose logs slides; see [`crate::lateral_slip`]), in
    /// words: while it is set no parameter is judged well determined.
    pub unmodelled_slide: Option<String>,
    /// The estimate that places the neighbouring scans of the pairs matched with them
    /// did not settle (see [`crate::placement_rounds`]), in words: while it is set no
    /// parameter is judged well determined.
    pub unsettled_placement: Option<String>,
    /// The scans' returns: the median count of readings within the laser's range
    /// per scan and the rays per scan (of the first log, with several), when any
    /// scan was read; a refusal for too few matches names it.
    pub scan_returns: Option<crate::matching::ScanReturns>,
    /// The factor on the σ for the phases of a log sharing their errors
    /// ([`crate::phase_correlation`]; 1: none, or one log alone). The parameters to
    /// hold that a refusal proposes are judged with it.
    pub shared_error_factor: f64,
}

impl Synchronized {
    /// The refusal for `usable` samples, fewer than [`crate::options::MIN_SAMPLES`],
    /// with these pairs' discards, match rejections and scan returns as its evidence.
    pub(crate) fn too_few_samples(&self, usable: usize) -> crate::PipelineError {
        crate::PipelineError::TooFewSamples {
            usable,
            pairs: self.pairs,
            needed: crate::options::MIN_SAMPLES,
            discarded: self.discarded.clone(),
            match_rejections: self.match_rejections.clone(),
            scan_returns: self.scan_returns,
        }
    }

    /// What keeps every verdict from "well determined" (unrepaired timing, a heading
    /// not from the wheels, a slide not modelled, a placement that did not settle), in
    /// words; `None` when nothing does.
    pub fn unjudgeable(&self) -> Option<String> {
        let causes: Vec<&str> = [
            &self.unrepaired_timing,
            &self.heading_not_from_wheels,
            &self.unmodelled_slide,
            &self.unsettled_placement,
        ]
        .into_iter()
        .filter_map(|c| c.as_deref())
        .collect();
        (!causes.is_empty()).then(|| causes.join("; "))
    }
}
