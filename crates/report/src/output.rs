//! Files written by `--out DIR` (results.json, samples.tuple, results.html, the
//! results in ROS terms — diff_drive_controller.yaml and laser_joint.urdf.xml — and,
//! with `--plots`, one SVG per figure) and by `--report FILE.html`.

use crate::export::{diff_drive_controller_yaml, laser_joints_urdf, DIFF_DRIVE_FILE, URDF_FILE};
use crate::figures::{figures, Figure};
use crate::html::page;
use crate::report::Report;
use odocal_pipeline::{
    write_bytes_atomically, write_dir_atomically, write_tuples, Options, Outcome,
};
use std::fs;
use std::io;
use std::path::Path;

/// The figures of `outcome`, or an I/O error naming the drawing failure.
fn drawn(opts: &Options, outcome: &Outcome, report: &Report) -> io::Result<Vec<Figure>> {
    figures(opts, outcome, report)
        .map_err(|e| io::Error::other(format!("cannot draw the figures: {e}")))
}

/// The report page as one self-contained HTML document.
pub fn html_report(opts: &Options, outcome: &Outcome, report: &Report) -> io::Result<String> {
    Ok(page(report, &drawn(opts, outcome, report)?))
}

/// Writes the report page to `path`, creating its directory when missing (as
/// `--out DIR` does).
pub fn write_html(
    path: &Path,
    opts: &Options,
    outcome: &Outcome,
    report: &Report,
) -> io::Result<()> {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        fs::create_dir_all(dir)?;
    }
    write_bytes_atomically(path, html_report(opts, outcome, report)?.as_bytes())
}

/// True for the names of the files [`write_outputs`] writes, so an old `--out`
/// directory holding nothing else may be replaced.
pub fn is_output_name(name: &str) -> bool {
    matches!(
        name,
        "results.json" | "samples.tuple" | "results.html" | DIFF_DRIVE_FILE | URDF_FILE
    ) || name.ends_with(".svg")
}

/// Writes `results.json`, `samples.tuple`, `results.html`, the ROS files of
/// [`write_ros_files`](crate::export::write_ros_files) and, with `plots`, the
/// figures as `NAME.svg` as the directory `dir`, all files or none: they are written
/// into a fresh directory that then replaces `dir` (see
/// [`odocal_pipeline::atomic_dir`]); a `dir` holding other files is refused.
/// Parameters that cannot be a robot's (a negative radius) have no ROS files: the
/// others are written and the error says why.
pub fn write_outputs(
    dir: &Path,
    opts: &Options,
    outcome: &Outcome,
    report: &Report,
    plots: bool,
) -> io::Result<()> {
    // The figures are drawn while results.json is written out.
    let (json, figs) = rayon::join(
        || serde_json::to_string_pretty(report).map_err(io::Error::other),
        || drawn(opts, outcome, report),
    );
    let (json, figs) = (json?, figs?);
    let ros_yaml = diff_drive_controller_yaml(&report.params);
    let ros_urdf = laser_joints_urdf(&report.params, &report.laser_poses());
    write_dir_atomically(dir, &is_output_name, |fresh| {
        write_bytes_atomically(&fresh.join("results.json"), (json + "\n").as_bytes())?;
        write_tuples(&fresh.join("samples.tuple"), &outcome.synced.samples)?;
        write_bytes_atomically(&fresh.join("results.html"), page(report, &figs).as_bytes())?;
        if plots {
            for f in &figs {
                write_bytes_atomically(&fresh.join(format!("{}.svg", f.name)), f.svg.as_bytes())?;
            }
        }
        if let (Ok(yaml), Ok(urdf)) = (&ros_yaml, &ros_urdf) {
            write_bytes_atomically(&fresh.join(DIFF_DRIVE_FILE), yaml.as_bytes())?;
            write_bytes_atomically(&fresh.join(URDF_FILE), urdf.as_bytes())?;
        }
        Ok(())
    })?;
    ros_yaml.and(ros_urdf).map(|_| ()).map_err(io::Error::other)
}
