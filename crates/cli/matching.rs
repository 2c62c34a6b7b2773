//! `odocal match LOG --out FILE`: synchronization and scan matching only; writes the
//! samples as tuples (one JSON object per line).

use crate::calibrate::{read_input_log, thread_pool, Bar};
use anyhow::Context;
use odocal_pipeline::{synchronize_and_match, write_tuples, Options, Timing};
use std::path::PathBuf;

/// Arguments of `odocal match`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// The log (Carmen-style text with ENCODER lines, or the original package's JSON log).
    pub log: PathBuf,
    /// Where to write the tuples.
    #[arg(long, value_name = "FILE")]
    pub out: PathBuf,
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

/// Runs `odocal match`.
pub fn run(args: Args) -> anyhow::Result<()> {
    let pool = thread_pool(args.threads)?;
    let log = read_input_log(&args.log, args.lenient, args.ticks_per_rev)?;
    let opts = Options {
        ticks_per_revolution: args.ticks_per_rev,
        stride: args.stride,
        time_offset: args.time_offset,
        ..Options::default()
    };
    let bar = Bar::for_stderr();
    let mut timing = Timing::default();
    let synced = pool.install(|| synchronize_and_match(&log, &opts, &bar, &mut timing))?;
    write_tuples(&args.out, &synced.samples)
        .with_context(|| format!("cannot write {}", args.out.display()))?;
    let discarded: Vec<String> = synced
        .discarded
        .0
        .iter()
        .map(|(k, n)| format!("{k} {n}"))
        .collect();
    eprintln!(
        "{} samples written to {} ({} scan pairs, stride {}; discarded: {}); matching took {:.2} s",
        synced.samples.len(),
        args.out.display(),
        synced.pairs,
        synced.stride,
        discarded.join(", "),
        timing.r#match
    );
    Ok(())
}
