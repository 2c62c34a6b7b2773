//! `odocal export results.json [--out DIR] [--format ros2-control|urdf]`: a
//! calibration's results in ROS terms — the ros2_control `diff_drive_controller`
//! parameters and the laser joint's URDF `<origin>` — from its `results.json`, the
//! same files `calibrate --out DIR` writes beside it. With several lasers
//! (results.json `lasers`), the URDF file has one joint origin per laser.

use crate::terminal::{out, outln};
use anyhow::Context;
use odocal_geom::FlatParams;
use odocal_pipeline::write_bytes_atomically;
use odocal_report::export::{DIFF_DRIVE_FILE, URDF_FILE};
use odocal_report::{diff_drive_controller_yaml, laser_joints_urdf, LaserPose};
use std::path::PathBuf;

/// Which file to export.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// ros2_control diff_drive_controller parameters (YAML).
    Ros2Control,
    /// The laser joint's URDF `<origin xyz rpy>`.
    Urdf,
}

/// Arguments of `odocal export`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// A calibration's results.json (`calibrate --out DIR` or `calibrate --json`).
    pub results: PathBuf,
    /// Write the files into DIR (diff_drive_controller.yaml, laser_joint.urdf.xml)
    /// instead of printing them.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Only this one (default: both).
    #[arg(long, value_enum)]
    pub format: Option<Format>,
}

/// Runs `odocal export`.
pub fn run(args: Args) -> anyhow::Result<()> {
    let path = &args.results;
    let text =
        std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))?;
    let params: FlatParams = serde_json::from_str(&text).with_context(|| {
        format!(
            "{}: not a calibration's results.json (expected a JSON object with r_l, r_r, b, \
             l_x, l_y, l_theta in metres and radians)",
            path.display()
        )
    })?;
    // Several lasers: results.json's `lasers`, one URDF joint origin each.
    let lasers: Vec<LaserPose> = match serde_json::from_str::<serde_json::Value>(&text)
        .ok()
        .and_then(|v| v.get("lasers").cloned())
    {
        Some(v) => serde_json::from_value(v).with_context(|| {
            format!(
                "{}: `lasers` is not a list of objects with l_x, l_y, l_theta (m, rad)",
                path.display()
            )
        })?,
        None => Vec::new(),
    };
    let mut files = Vec::new();
    if args.format != Some(Format::Urdf) {
        files.push((DIFF_DRIVE_FILE, diff_drive_controller_yaml(&params)?));
    }
    if args.format != Some(Format::Ros2Control) {
        files.push((URDF_FILE, laser_joints_urdf(&params, &lasers)?));
    }
    match &args.out {
        Some(dir) => {
            std::fs::create_dir_all(dir)
                .with_context(|| format!("cannot create {}", dir.display()))?;
            for (name, body) in &files {
                let file = dir.join(name);
                write_bytes_atomically(&file, body.as_bytes())
                    .with_context(|| format!("cannot write {}", file.display()))?;
                outln!("written {}", file.display())?;
            }
        }
        None => {
            for (name, body) in &files {
                if files.len() > 1 {
                    outln!("# {name}")?;
                }
                out!("{body}")?;
            }
        }
    }
    Ok(())
}
