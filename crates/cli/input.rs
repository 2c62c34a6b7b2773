//! The arguments `calibrate` and `match` share: the log and how to read it, how to
//! pair its scans, and how many threads match them.

use anyhow::Context;
use odocal_log::{read_log, Log, Mode, ReadOptions};
use std::path::PathBuf;

/// The input log and the options of reading, pairing and matching it.
#[derive(clap::Args, Debug)]
pub struct InputArgs {
    /// The log (Carmen-style text with ENCODER lines, or the original package's JSON log).
    pub log: PathBuf,
    /// Encoder ticks per wheel revolution (overrides the log's PARAM).
    #[arg(long, value_name = "X")]
    pub ticks_per_rev: Option<f64>,
    /// Pair scans K apart (default: about 0.4 s apart at the log's scan rate).
    #[arg(long, value_name = "K")]
    pub stride: Option<usize>,
    /// Known clock offset (s): laser clock minus encoder clock.
    #[arg(
        long,
        value_name = "S",
        default_value_t = 0.0,
        allow_negative_numbers = true
    )]
    pub time_offset: f64,
    /// Threads for scan matching (default: all cores).
    #[arg(long, value_name = "N")]
    pub threads: Option<usize>,
    /// Skip malformed lines (counted and reported) instead of stopping at the first.
    #[arg(long)]
    pub lenient: bool,
}

impl InputArgs {
    /// A rayon pool with `--threads` threads (all cores when not given).
    pub fn thread_pool(&self) -> anyhow::Result<rayon::ThreadPool> {
        thread_pool(self.threads)
    }

    /// Reads the log, strict unless `--lenient`, with the `--ticks-per-rev` override.
    pub fn read_log(&self) -> anyhow::Result<Log> {
        let opts = ReadOptions {
            mode: if self.lenient {
                Mode::Lenient
            } else {
                Mode::Strict
            },
            ticks_per_revolution: self.ticks_per_rev,
            ..ReadOptions::default()
        };
        // The reader's message already says everything (file, line, cause).
        read_log(&self.log, &opts).map_err(|e| anyhow::anyhow!("{e}"))
    }
}

/// A rayon pool with `threads` threads (all cores when `None`); 0 is an error.
pub fn thread_pool(threads: Option<usize>) -> anyhow::Result<rayon::ThreadPool> {
    if threads == Some(0) {
        anyhow::bail!("--threads must be at least 1");
    }
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads.unwrap_or(0))
        .build()
        .context("cannot start the scan-matching threads")
}
