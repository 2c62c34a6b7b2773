//! The arguments of every command that reads a log: the file and how to read it.
//! `calibrate`, `match` and `info` flatten this one struct, so each reading option
//! exists on every such command.

use odocal_log::{read_log, Log, Mode, ReadOptions};
use std::path::PathBuf;

/// The input log and the options of reading it.
#[derive(clap::Args, Debug)]
pub struct ReadArgs {
    /// The log (Carmen-style text with ENCODER lines, or the original package's JSON log).
    pub log: PathBuf,
    /// Encoder ticks per wheel revolution (overrides the log's PARAM).
    #[arg(long, value_name = "X")]
    pub ticks_per_rev: Option<f64>,
    /// Encoder counter modulus, e.g. 65536 (overrides the log's PARAM).
    #[arg(long, value_name = "M")]
    pub encoder_modulus: Option<f64>,
    /// Minimum valid range in metres (overrides the log's PARAM).
    #[arg(long, value_name = "METRES")]
    pub min_range: Option<f64>,
    /// Seconds between two consecutive rays of a scan, the sweep (overrides the log's
    /// PARAM laser_front_laser_time_increment); ray 0 is taken at the scan's timestamp.
    #[arg(long, value_name = "S", allow_negative_numbers = true)]
    pub time_increment: Option<f64>,
    /// Skip malformed lines (counted and reported) instead of stopping at the first.
    #[arg(long)]
    pub lenient: bool,
}

impl ReadArgs {
    /// The reader options these arguments ask for.
    pub fn read_options(&self) -> ReadOptions {
        ReadOptions {
            mode: if self.lenient {
                Mode::Lenient
            } else {
                Mode::Strict
            },
            ticks_per_revolution: self.ticks_per_rev,
            encoder_modulus: self.encoder_modulus,
            min_range: self.min_range,
            time_increment: self.time_increment,
        }
    }

    /// Reads the log, strict unless `--lenient`, with the command-line overrides.
    pub fn read_log(&self) -> anyhow::Result<Log> {
        // The reader's message already says everything (file, line, cause).
        read_log(&self.log, &self.read_options()).map_err(|e| anyhow::anyhow!("{e}"))
    }
}
