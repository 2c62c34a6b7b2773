//! `odocal match LOG [LOG …] --out FILE`: synchronization and scan matching only;
//! writes the samples (of every log, in the order given) as tuples (one JSON object
//! per line).

use crate::input::InputArgs;
use crate::nominal::{describe, odometry_only_mode};
use crate::output_paths::check_file_output;
use crate::progress_bar::Bar;
use crate::terminal::errln;
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
    let paths = input.paths();
    for log_path in &paths {
        check_file_output(&args.out, log_path)
            .with_context(|| format!("cannot write {}", args.out.display()))?;
    }
    let inputs = input.read_logs()?;
    // The laser's nominal pose from the first bag with static transforms.
    let laser = inputs.iter().find_map(|r| r.nominal_laser.clone());
    let initial_params = input.nominal_with_laser(laser.as_ref())?;
    let mut logs: Vec<_> = inputs.into_iter().map(|r| r.log).collect();
    for (path, log) in paths.iter().zip(logs.iter_mut()) {
        if let Some(n) = odometry_only_mode(path, log, initial_params.as_ref())? {
            errln!("{}: {}", path.display(), describe(&n));
        }
    }
    let opts = Options {
        initial_params,
        ticks_per_revolution: input.read.ticks_per_rev,
        stride: input.stride,
        time_offset: input.time_offset.unwrap_or(0.0),
        ..Options::default()
    };
    let bar = Bar::for_stderr();
    let mut samples = Vec::new();
    for (path, log) in paths.iter().zip(&logs) {
        let mut timing = Timing::default();
        // The data-health stage repairs the log as `calibrate` does, and says what it did.
        let (log, mut findings) = health::check_log(log, &opts);
        let synced = pool
            .install(|| synchronize_and_match(&log, &opts, &bar, &mut timing))
            .with_context(|| format!("{}", path.display()))?;
        findings.extend(health::after_matching(&log, &synced, &opts));
        let name = if paths.len() > 1 {
            format!("{}: ", path.display())
        } else {
            String::new()
        };
        for f in &findings {
            errln!("{name}{f}");
        }
        let discarded: Vec<String> = synced
            .discarded
            .0
            .iter()
            .map(|(k, n)| format!("{k} {n}"))
            .collect();
        errln!(
            "{name}{} samples ({} scan pairs, stride {}; discarded: {}); matching took {:.2} s",
            synced.samples.len(),
            synced.pairs,
            synced.stride,
            discarded.join(", "),
            timing.r#match
        );
        samples.extend(synced.samples);
    }
    write_tuples(&args.out, &samples)
        .with_context(|| format!("cannot write {}", args.out.display()))?;
    errln!(
        "{} samples written to {}",
        samples.len(),
        args.out.display()
    );
    Ok(())
}
