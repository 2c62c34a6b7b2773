//! From a raw log to calibrated parameters: synchronization of the encoder and scan
//! streams, parallel scan matching, (clock-offset estimation,) solving. The report
//! (summary, results.json, figures) is the `odocal-report` crate's.
//!
//! ```no_run
//! use odocal_pipeline::{calibrate_log, Estimate, NoProgress, Options};
//! # fn demo() -> Result<(), Box<dyn std::error::Error>> {
//! let path = std::path::Path::new("robot.log");
//! let log = odocal_log::read_log(path, &odocal_log::ReadOptions::default())?;
//! let outcome = calibrate_log(&log, &Options::default(), &NoProgress)?;
//! println!("{:?}", Estimate::of(&outcome).values());
//! # Ok(()) }
//! ```
//!
//! Stages, one module each: [`sync`] (encoder interpolation at the scan timestamps,
//! encoder profile, discards by reason), [`sweep`] (rays of a sweeping laser moved to
//! the sensor frame at the scan's reference time), [`matching`] (ICP over the pairs, in
//! parallel with [`parallel`]; refusals counted by reason in [`rejection`]; the matcher's own error by closure of scan
//! triples in [`self_check`]), [`health`] (data faults found, repaired and named,
//! before and after matching, as [`finding`]s: what the results want a reader to
//! notice), [`time_offset`] (optional clock-offset search), [`options`] (what the pipeline can be told),
//! [`synchronized`] (the per-log samples between synchronization and the solve),
//! [`run`] (the
//! whole, with timing), [`joint`] (several logs of one robot, one calibration), [`lasers`]
//! (several lasers on it: the wheels shared, one ℓ per laser) and
//! [`log_agreement`] (each of them against the joint estimate), [`lateral_slip`] (a
//! skid-steer robot's sideways slide in turns: checked, and estimated when found),
//! [`samples`] (the samples and their tuples), [`estimate`] (the core numbers of a
//! result), [`range_finder`] (common range finders recognised from their scans) and
//! [`range_scale`] (the laser's range-scale σ that every calibrated distance carries).

#![deny(missing_docs)]

pub mod atomic_dir;
pub mod atomic_file;
pub mod bootstrap_runs;
pub mod chained;
pub mod consistency;
mod error;
pub mod estimate;
pub mod finding;
pub mod guess_window;
pub mod health;
pub mod input_files;
pub mod joint;
pub mod joint_offsets;
pub mod lasers;
pub mod lateral_slip;
pub mod local_map;
pub mod log_agreement;
pub mod match_quality;
pub mod matcher_bias;
pub mod matching;
pub mod options;
pub mod parallel;
pub mod phase_correlation;
pub mod phases;
pub mod placement_rounds;
mod progress;
pub mod range_finder;
pub mod range_scale;
pub mod refusal;
pub mod rejection;
pub mod run;
pub mod samples;
pub mod self_check;
pub mod sweep;
pub mod sync;
pub mod synchronized;
pub mod time_offset;

pub use atomic_dir::{check_replaceable_dir, write_dir_atomically};
pub use atomic_file::{check_replaceable_file, write_atomically, write_bytes_atomically};
pub use error::PipelineError;
pub use estimate::Estimate;
pub use finding::{Finding, FindingKind, Severity};
pub use input_files::InputFiles;
pub use joint::{
    calibrate_log_phases, calibrate_logs, calibrate_logs_with_lasers, Contribution, JointError,
    JointOutcome, LogPhases, PhaseGroupCheck,
};
pub use lasers::{laser_indices, LaserSetup};
pub use lateral_slip::SlideModel;
pub use odocal_solver::Trim;
pub use options::{Options, BOOTSTRAP_PAIRS, BOOTSTRAP_RUN, MIN_SAMPLES};
pub use progress::{NoProgress, Progress};
pub use range_finder::{recognise, LaserSignature, RangeFinder, RANGE_FINDERS};
pub use range_scale::{RangeScale, RangeScaleSource};
pub use rejection::{MatchFailure, Rejection, RejectionCounts};
pub use run::{calibrate_log, synchronize_and_match, Outcome, Timing};
pub use samples::write_tuples;
pub use synchronized::Synchronized;
