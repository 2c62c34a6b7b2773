//! Everything the pipeline can be told: [`Options`], shared by the per-log stages
//! (synchronization, health, matching, clock offset) and the joint solve.

use crate::sync::SyncLimits;
use odocal_icp::IcpParams;
use odocal_solver::{Params, SolveOptions};

/// Pairs matched without odometry (the motion the pair before measured, or the
/// identity: [`crate::bootstrap_runs`]) to bootstrap the odometry guesses of the
/// others when there are at least twice as many pairs (with fewer, all pairs are
/// matched so first, and the failures again from odometry).
pub const BOOTSTRAP_PAIRS: usize = 300;

/// Consecutive pairs in each run of the bootstrap's subset of a long log: a run of
/// a chain prepares one scan more than it has pairs, and so does each run left
/// between two runs. Taken one pair in every `k` instead, the subset and the pairs
/// left each prepared two scans per pair, about 1.5 preparations per pair over a
/// log instead of one (a 10-minute Khepera log: 2,438 for 1,499 pairs).
pub const BOOTSTRAP_RUN: usize = 8;

/// Fewest samples the pipeline hands to the solver.
pub const MIN_SAMPLES: usize = 20;

/// Everything the pipeline can be told.
#[derive(Debug, Clone)]
pub struct Options {
    /// Encoder ticks per wheel revolution; overrides the log's PARAM when set.
    pub ticks_per_revolution: Option<f64>,
    /// Scan pairs `stride` scans apart; `None` picks intervals of about 0.4 s.
    pub stride: Option<usize>,
    /// Synchronization thresholds; `None` derives them from the streams.
    pub limits: Option<SyncLimits>,
    /// Use the encoder profile (non-constant-speed formulas).
    pub use_profile: bool,
    /// Pass ŝ's covariance from ICP to the solver (weights).
    pub use_icp_covariance: bool,
    /// Solver settings (trimming rule, refinement).
    pub solve: SolveOptions,
    /// Known clock offset (s): laser clock minus encoder clock (subtracted from scan timestamps).
    pub time_offset: f64,
    /// Estimate the offset within ±this many seconds (`None`: keep `time_offset`,
    /// unless [`Options::estimate_found_time_offset`] applies).
    pub estimate_time_offset: Option<f64>,
    /// Without [`Options::estimate_time_offset`]: when the quick check on every run
    /// finds the clocks clearly offset from `time_offset`, estimate the offset anyway
    /// (in a range that holds the quick check's answer) instead of calibrating at
    /// `time_offset` with biased results. Off when the offset is known (the CLI's
    /// `--time-offset`): then the quick check only warns.
    pub estimate_found_time_offset: bool,
    /// Parameters for the first guesses of scan matching (odometry prediction).
    pub initial_params: Option<Params>,
    /// Without `initial_params`: match [`BOOTSTRAP_PAIRS`] evenly spread pairs (all
    /// pairs of a shorter log) without odometry, solve roughly, and guess the
    /// other pairs and the failed ones by odometry with that estimate (fewer ICP
    /// iterations and failures). Off: identity for all.
    pub bootstrap_guesses: bool,
    /// Match again with first guesses predicted from the first estimate.
    pub second_pass: bool,
    /// Scan matcher settings.
    pub icp: IcpParams,
    /// Return numbers even when some parameters are only weakly determined or not
    /// excited (by default that is an error naming them), at every solve: the
    /// first, the second pass, and each solve of the clock-offset search.
    pub accept_weak: bool,
    /// Odometry-only mode: the wheel rotations were recovered from odometry poses with
    /// `initial_params` (the nominal parameters), so the odometry's heading is checked
    /// to come from the wheels (see [`crate::health::gyro_heading`]).
    pub odometry_only: bool,
    /// One σ of the laser's range scale, relative (0.01: 1 %), as stated by the user;
    /// `None`: the data sheet's of the range finder recognised in the log (see
    /// [`crate::range_finder`]), or none when it is not recognised.
    pub laser_range_scale: Option<f64>,
    /// Scan matching uses the readings below this range (m), as stated by the user;
    /// `None`: the range the laser is rated for
    /// ([`crate::LaserSignature::matching_range`]). A scan's own declared maximum
    /// applies either way.
    pub matching_range: Option<f64>,
    /// The scans' frame (a bag's `header.frame_id`), when the input tells it: one more
    /// clue to recognise the range finder by.
    pub laser_frame: Option<String>,
    /// The sideways slide of a skid-steer robot in turns: checked for and estimated
    /// when found (default), always estimated, or neither (see
    /// [`crate::lateral_slip`]).
    pub lateral_slip: crate::lateral_slip::SlideModel,
}

impl Options {
    /// The range-scale σ of a run on `log`: [`Options::laser_range_scale`] when
    /// stated, else the data sheet's of the range finder recognised in it.
    pub fn range_scale(&self, log: &odocal_log::Log) -> crate::RangeScale {
        let signature = crate::LaserSignature::of_log(log, self.laser_frame.as_deref());
        crate::RangeScale::resolve(self.laser_range_scale, signature.as_ref())
    }

    /// The scan matcher's settings for `log`: [`Options::icp`] with its readings
    /// limited to [`Options::matching_range`] when stated, else to the range the log's
    /// laser is rated for ([`crate::LaserSignature::matching_range`]).
    pub fn icp_for(&self, log: &odocal_log::Log) -> IcpParams {
        let signature = crate::LaserSignature::of_log(log, self.laser_frame.as_deref());
        IcpParams {
            max_reading: self.reading_limit(signature.as_ref()),
            ..self.icp.clone()
        }
    }

    /// The range (m) below which scan matching uses the readings of the laser of
    /// `signature`: [`Options::matching_range`] when stated, else its rated range;
    /// within [`Options::icp`]'s own `max_reading`.
    fn reading_limit(&self, signature: Option<&crate::LaserSignature>) -> f64 {
        let range = self.matching_range.unwrap_or_else(|| {
            signature.map_or(crate::range_finder::UNDECLARED_MATCHING_RANGE, |s| {
                s.matching_range()
            })
        });
        self.icp.max_reading.min(range)
    }

    /// In words, when scan matching leaves out readings the scans of `log` declare
    /// valid: "readings up to 4 m of the 5.6 m the scans declare (the Hokuyo
    /// URG-04LX's rated range; …)"; `None` when it uses their whole range.
    pub fn matching_range_statement(&self, log: &odocal_log::Log) -> Option<String> {
        let signature = crate::LaserSignature::of_log(log, self.laser_frame.as_deref())?;
        let used = self.reading_limit(Some(&signature));
        let declared = signature.max_range;
        if used >= declared {
            return None;
        }
        let why = match (self.matching_range, crate::recognise(&signature)) {
            (Some(_), _) => "as stated by --matching-range".to_string(),
            (None, Some(r)) => format!(
                "the {}'s rated range; --matching-range METRES to use more",
                r.finder.name
            ),
            (None, None) => {
                "the scans declare no maximum range; --matching-range METRES states the laser's"
                    .to_string()
            }
        };
        let of = if declared.is_finite() {
            format!(
                " of the {} m the scans declare",
                crate::range_finder::metres(declared)
            )
        } else {
            String::new()
        };
        Some(format!(
            "readings up to {} m{of} ({why})",
            crate::range_finder::metres(used)
        ))
    }

    /// The solver's settings with [`Options::accept_weak`] passed on.
    pub fn solve_options(&self) -> SolveOptions {
        SolveOptions {
            accept_weak: self.accept_weak || self.solve.accept_weak,
            ..self.solve
        }
    }
}

impl Default for Options {
    fn default() -> Self {
        Options {
            ticks_per_revolution: None,
            stride: None,
            limits: None,
            use_profile: true,
            use_icp_covariance: false,
            solve: SolveOptions::default(),
            time_offset: 0.0,
            estimate_time_offset: None,
            estimate_found_time_offset: true,
            initial_params: None,
            bootstrap_guesses: true,
            second_pass: false,
            icp: IcpParams::default(),
            accept_weak: false,
            odometry_only: false,
            laser_range_scale: None,
            matching_range: None,
            laser_frame: None,
            lateral_slip: Default::default(),
        }
    }
}
