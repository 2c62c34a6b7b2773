//! `odocal`: simultaneous calibration of a differential-drive robot's odometry
//! (wheel radii, wheel distance) and of its range finder's pose, from a raw log.
//!
//! This binary is thin: each subcommand lives in its own module and calls the
//! library crates (`odocal-log`, `odocal-icp`, `odocal-solver`, `odocal-sim`,
//! `odocal-pipeline`, `odocal-report`).

use crate::terminal::errln;
use clap::{Parser, Subcommand};
use std::process::ExitCode;

mod calibrate;
mod export;
mod hashing_thread;
mod heading_refusal;
mod info;
mod input;
mod json_error;
mod matching;
mod nominal;
mod open_input;
mod output_paths;
mod partial_args;
mod progress_bar;
mod read_args;
mod simulate;
mod solve;
mod table_i;
mod terminal;

/// Calibrate a differential-drive robot and its laser from nothing but a log.
#[derive(Parser, Debug)]
#[command(name = "odocal", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Raw log in, calibrated robot out: r_L, r_R, b and the laser pose, with uncertainty.
    Calibrate(calibrate::Args),
    /// Scan matching and synchronization only: write the samples (tuples).
    Match(matching::Args),
    /// Solve for the parameters from samples (tuple files).
    Solve(solve::Args),
    /// Describe a log: counts per message, time span, scan geometry, encoder rate.
    Info(info::Args),
    /// Simulate a robot with encoders and a URG-04LX; write a log and its ground truth.
    Simulate(Box<simulate::Args>),
    /// A calibration's results in ROS terms: diff_drive_controller YAML, URDF origin.
    Export(export::Args),
    /// Reproduce the ICRA 2008 Table I in simulation and compare with the published rows.
    TableI(table_i::Args),
}

impl Command {
    /// True when the command was asked for JSON output (`--json`).
    fn wants_json(&self) -> bool {
        match self {
            Command::Calibrate(a) => a.json,
            Command::Solve(a) => a.json,
            Command::Info(a) => a.json,
            _ => false,
        }
    }
}

/// Lets a closed pipe end the process quietly, as it does `cat` or `grep`
/// (`odocal info run.log | head`): Rust ignores SIGPIPE, so without this every
/// `println!` after the reader has gone would panic with "Broken pipe".
fn exit_quietly_on_closed_pipe() {
    #[cfg(unix)]
    // SAFETY: called first thing in `main`, before any other thread exists; SIG_DFL
    // is a valid disposition for SIGPIPE.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}

fn main() -> ExitCode {
    exit_quietly_on_closed_pipe();
    let cli = Cli::parse();
    let json = cli.command.wants_json();
    let result = match cli.command {
        Command::Calibrate(a) => calibrate::run(a),
        Command::Match(a) => matching::run(a),
        Command::Solve(a) => solve::run(a),
        Command::Info(a) => info::run(a),
        Command::Simulate(a) => simulate::run(*a),
        Command::TableI(a) => table_i::run(a),
        Command::Export(a) => export::run(a),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            errln!("error: {e:#}");
            if json {
                let args: Vec<String> = std::env::args().collect();
                let _ =
                    terminal::write_json_stdout(&json_error::error_object(&e, &args).to_string());
            }
            ExitCode::FAILURE
        }
    }
}
