//! From a raw log to calibrated parameters: synchronization of the encoder and scan
//! streams, parallel scan matching, (clock-offset estimation,) solving, and the report.
//!
//! ```no_run
//! use odocal_pipeline::{build_report, calibrate_log, NoProgress, Options};
//! # fn demo() -> Result<(), Box<dyn std::error::Error>> {
//! let path = std::path::Path::new("robot.log");
//! let log = odocal_log::read_log(path, &odocal_log::ReadOptions::default())?;
//! let outcome = calibrate_log(&log, &Options::default(), &NoProgress)?;
//! println!("{}", build_report(path, &log, &Options::default(), &outcome));
//! # Ok(()) }
//! ```
//!
//! Stages, one module each: [`sync`] (encoder interpolation at the scan timestamps,
//! encoder profile, discards by reason), [`matching`] (ICP over the pairs, in parallel
//! with [`parallel`]), [`time_offset`] (optional clock-offset search), [`run`] (the
//! whole, with timing), [`report`] and [`output`] (results.json, tuples, figures).

#![deny(missing_docs)]

mod error;
pub mod health;
pub mod matching;
pub mod output;
pub mod parallel;
mod progress;
pub mod report;
pub mod run;
pub mod samples;
pub mod svg;
pub mod sync;
/// Regression against published calibration results (ICRA 2008 Table I, T-RO 2013).
pub mod table_i;
pub mod time_offset;

pub use error::PipelineError;
pub use health::{FaultKind, Finding, Severity};
pub use odocal_solver::Trim;
pub use output::{write_outputs, write_tuples};
pub use progress::{NoProgress, Progress};
pub use report::{build_report, Report};
pub use run::{calibrate_log, synchronize_and_match, Options, Outcome, Synchronized, Timing};
