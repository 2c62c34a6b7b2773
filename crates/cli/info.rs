//! `odocal info LOG`: describe a log — counts per message kind, time span, scan
//! geometry, encoder rate, where ticks per revolution came from, unknown and skipped
//! lines. `--json` prints the same as one JSON object.

use anyhow::Context;
use odocal_log::{read_log, LogSummary, Mode, ReadOptions};
use std::path::PathBuf;

/// Arguments of `odocal info`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// The log: Carmen-style text, or the original package's JSON log.
    pub log: PathBuf,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
    /// Skip malformed lines (counted and reported) instead of stopping at the first.
    #[arg(long)]
    pub lenient: bool,
    /// Encoder ticks per wheel revolution (overrides the log's PARAM).
    #[arg(long, value_name = "X")]
    pub ticks_per_rev: Option<f64>,
    /// Encoder counter modulus, e.g. 65536 (overrides the log's PARAM).
    #[arg(long, value_name = "M")]
    pub encoder_modulus: Option<f64>,
    /// Minimum valid range in metres (overrides the log's PARAM).
    #[arg(long, value_name = "METRES")]
    pub min_range: Option<f64>,
}

/// Runs `odocal info`.
pub fn run(args: Args) -> anyhow::Result<()> {
    let opts = ReadOptions {
        mode: if args.lenient {
            Mode::Lenient
        } else {
            Mode::Strict
        },
        ticks_per_revolution: args.ticks_per_rev,
        encoder_modulus: args.encoder_modulus,
        min_range: args.min_range,
    };
    let log = read_log(&args.log, &opts)?;
    let summary = LogSummary::of(&log);
    if args.json {
        let text = serde_json::to_string_pretty(&summary).context("serializing the summary")?;
        println!("{text}");
    } else {
        print!("{summary}");
    }
    Ok(())
}
