//! The report of a calibration: the human summary and `results.json` ([`report`]),
//! the files `--out DIR` writes ([`output`]) and the figures ([`svg`]).
//!
//! ```no_run
//! use odocal_pipeline::{calibrate_log, NoProgress, Options};
//! use odocal_report::build_report;
//! # fn demo() -> Result<(), Box<dyn std::error::Error>> {
//! let path = std::path::Path::new("robot.log");
//! let log = odocal_log::read_log(path, &odocal_log::ReadOptions::default())?;
//! let outcome = calibrate_log(&log, &Options::default(), &NoProgress)?;
//! println!("{}", build_report(path, &log, &Options::default(), &outcome));
//! # Ok(()) }
//! ```

#![deny(missing_docs)]

pub mod output;
pub mod report;
pub mod svg;

pub use output::write_outputs;
pub use report::{build_report, Report};
