//! The report of a calibration: the human summary and `results.json` ([`report`]),
//! the joint report of several logs ([`joint`]), where the run came from
//! ([`provenance`]), the laser's range scale in σ ([`range_scale`]), the figures ([`figures`], drawn with `plotters`), the one-page
//! `results.html` ([`html`]), the results in ROS terms ([`export`]) and the files
//! `--out DIR` writes ([`output`]).
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

mod data_section;
pub mod export;
pub mod figures;
pub mod html;
pub mod joint;
pub mod output;
pub mod provenance;
pub mod range_scale;
pub mod report;

pub use export::{
    diff_drive_controller_yaml, laser_joint_urdf, laser_joints_urdf, write_ros_files, LaserPose,
};
pub use joint::{build_joint_report, laser_rows, Between, LaserRow, LogRow};
pub use odocal_pipeline::{Finding, FindingKind, Severity};
pub use output::{html_report, is_output_name, write_html, write_outputs};
pub use provenance::{sha256_of_input, Provenance};
pub use range_scale::RangeScaleReport;
pub use report::{build_report, NominalLaserPose, Report};
