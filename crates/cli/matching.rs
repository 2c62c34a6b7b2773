//! `odocal match LOG --out FILE`: synchronization and scan matching only; writes the
//! samples as tuples (one JSON object per line).

use crate::input::InputArgs;
use crate::nominal::{describe, odometry_only_mode};
use crate::progress_bar::Bar;
use anyhow::Context;
use odocal_pipeline::{health, synchronize_and_match, write_tuples, Options, Timing};
use std::path::PathBuf;

/// Arguments of `odocal match`.
#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(flatten)]
    pub input: InputArgs,
    /// Where to write the tuples.
    #[arg(long, value_name = "FILE")]
    pub out: PathBuf,
}

/// Runs `odocal match`.
pub fn run(args: Args) -> anyhow::Result<()> {
    let input = &args.input;
    let pool = input.thread_pool()?;
    let (mut log, laser) = input.read.read_log_and_laser()?;
    let initial_params = input.nominal_with_laser(laser.as_ref())?;
    if let Some(n) = odometry_only_mode(&input.read.log, &mut log, initial_params.as_ref())? {
        eprintln!("{}", describe(&n));
    }
    let opts = Options {
        initial_params,
        ticks_per_revolution: input.read.ticks_per_rev,
        stride: input.stride,
        time_offset: input.time_offset.unwrap_or(0.0),
        ..Options::default()
    };
    let bar = Bar::for_stderr();
    let mut timing = Timing::default();
    // The data-health stage repairs the log as `calibrate` does, and says what it did.
    let (log, mut findings) = health::check_log(&log, &opts);
    let synced = pool.install(|| synchronize_and_match(&log, &opts, &bar, &mut timing))?;
    findings.extend(health::after_matching(&log, &synced, &opts));
    for f in &findings {
        eprintln!("{f}");
    }
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
