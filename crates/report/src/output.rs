//! Files written by `--out DIR` (results.json, samples.tuple, results.html, the
//! results in ROS terms — diff_drive_controller.yaml and laser_joint.urdf.xml — and,
//! with `--plots`, one SVG per figure) and by `--report FILE.html`.

use crate::figures::{figures, Figure};
use crate::html::page;
use crate::report::Report;
use odocal_pipeline::{write_bytes_atomically, write_tuples, Options, Outcome};
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

/// Writes `results.json`, `samples.tuple`, `results.html`, the ROS files of
/// [`write_ros_files`](crate::export::write_ros_files) and, with `plots`, the
/// figures as `NAME.svg` into `dir` (created if needed); each file atomically (a
/// temporary file renamed).
pub fn write_outputs(
    dir: &Path,
    opts: &Options,
    outcome: &Outcome,
    report: &Report,
    plots: bool,
) -> io::Result<()> {
    fs::create_dir_all(dir)?;
    let json = serde_json::to_string_pretty(report).map_err(io::Error::other)?;
    write_bytes_atomically(&dir.join("results.json"), (json + "\n").as_bytes())?;
    write_tuples(&dir.join("samples.tuple"), &outcome.synced.samples)?;
    let figs = drawn(opts, outcome, report)?;
    write_bytes_atomically(&dir.join("results.html"), page(report, &figs).as_bytes())?;
    if plots {
        for f in &figs {
            write_bytes_atomically(&dir.join(format!("{}.svg", f.name)), f.svg.as_bytes())?;
        }
    }
    // Last: parameters that cannot be a robot's (a negative radius) are refused here,
    // after everything else was written.
    crate::export::write_ros_files(dir, &report.params)
}
