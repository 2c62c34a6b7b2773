//! `odocal match LOG [LOG …] --out FILE`: synchronization and scan matching only;
//! writes the samples (of every log, in the order given) as tuples (one JSON object
//! per line). A bag read for several lasers (`--scan-topic` repeated) writes each
//! laser's samples to its own file: `--out` once per topic, in the same order.

use crate::input::InputArgs;
use crate::nominal::{describe, odometry_only_mode};
use crate::output_paths::check_file_output;
use crate::progress_bar::Bar;
use crate::terminal::errln;
use anyhow::Context;
use odocal_pipeline::{health, synchronize_and_match, write_tuples, Options, Timing};
use odocal_solver::Params;
use std::path::PathBuf;

/// Arguments of `odocal match`.
#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(flatten)]
    pub input: InputArgs,
    /// Where to write the tuples. With several --scan-topic, once per topic in the
    /// same order: each laser's samples go to its own file.
    #[arg(long, value_name = "FILE", required = true)]
    pub out: Vec<PathBuf>,
}

/// Runs `odocal match`.
pub fn run(args: Args) -> anyhow::Result<()> {
    let input = &args.input;
    let pool = input.thread_pool()?;
    let paths = input.paths();
    let topics = &input.read.scan_topic;
    let lasers = topics.len().max(1);
    if args.out.len() != lasers {
        anyhow::bail!(
            "{} --out given for {lasers} laser(s): with several --scan-topic give one \
             --out per topic, in the same order (e.g. `odocal match robot.bag --scan-topic \
             /scan_front --scan-topic /scan_rear --out front.tuple --out rear.tuple`)",
            args.out.len()
        );
    }
    for (i, out) in args.out.iter().enumerate() {
        if args.out[..i].contains(out) {
            anyhow::bail!(
                "--out {} is given twice: each laser needs its own file",
                out.display()
            );
        }
        for log_path in &paths {
            check_file_output(out, log_path)
                .with_context(|| format!("cannot write {}", out.display()))?;
        }
    }
    let inputs = input.read_lasers()?;
    // A log's laser: its scan topic's position among several --scan-topic, else 0.
    let laser_of = |r: &crate::read_args::ReadInput| {
        r.scan_topic
            .as_ref()
            .and_then(|t| topics.iter().position(|g| g == t))
            .filter(|_| lasers > 1)
            .unwrap_or(0)
    };
    // Each laser's nominal pose from its first bag with static transforms; the
    // first laser's is the one `--nominal` with three values completes, the others'
    // replace the laser pose of the nominal parameters for their logs.
    let nominal_of = |k: usize| {
        inputs
            .iter()
            .filter(|(_, r)| laser_of(r) == k)
            .find_map(|(_, r)| r.nominal_laser.clone())
    };
    let initial_params = input.nominal_with_laser(nominal_of(0).as_ref())?;
    let initial_of: Vec<Option<Params>> = (0..lasers)
        .map(|k| match (k, nominal_of(k), initial_params) {
            (0, _, p) => p,
            (_, Some(l), Some(p)) => Some(Params {
                laser: odocal_geom::Pose2::new(l.x, l.y, l.theta),
                ..p
            }),
            _ => None,
        })
        .collect();
    let mut logs: Vec<_> = Vec::with_capacity(inputs.len());
    for (i, r) in inputs {
        let k = laser_of(&r);
        let mut log = r.log;
        if let Some(n) = odometry_only_mode(paths[i], &mut log, initial_params.as_ref())? {
            errln!("{}: {}", paths[i].display(), describe(&n));
        }
        logs.push((i, k, r.scan_topic, log));
    }
    let base = Options {
        ticks_per_revolution: input.read.ticks_per_rev,
        stride: input.stride,
        time_offset: input.time_offset.unwrap_or(0.0),
        ..Options::default()
    };
    let bar = Bar::for_stderr();
    let mut samples = vec![Vec::new(); lasers];
    let named = logs.len() > 1;
    for (i, k, topic, log) in &logs {
        let path = paths[*i];
        let opts = Options {
            // Without a nominal pose of its own, another laser's logs bootstrap
            // their first guesses (as `calibrate` does).
            initial_params: initial_of[*k],
            ..base.clone()
        };
        let mut timing = Timing::default();
        // The data-health stage repairs the log as `calibrate` does, and says what it did.
        let (log, mut findings) = health::check_log(log, &opts);
        let synced = pool
            .install(|| synchronize_and_match(&log, &opts, &bar, &mut timing))
            .with_context(|| format!("{}", path.display()))?;
        findings.extend(health::after_matching(&log, &synced, &opts));
        let name = match topic {
            Some(t) if lasers > 1 => format!("{} {t}: ", path.display()),
            _ if named => format!("{}: ", path.display()),
            _ => String::new(),
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
        samples[*k].extend(synced.samples);
    }
    for (out, samples) in args.out.iter().zip(&samples) {
        write_tuples(out, samples).with_context(|| format!("cannot write {}", out.display()))?;
        errln!("{} samples written to {}", samples.len(), out.display());
    }
    Ok(())
}
