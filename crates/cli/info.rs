//! `odocal info LOG`: describe a log — counts per message kind, time span, scan
//! geometry, encoder rate, where ticks per revolution came from, unknown and skipped
//! lines, and the data-health findings that need no scan matching. `--json` prints the
//! same as one JSON object (findings under `health`).

use crate::read_args::ReadArgs;
use anyhow::Context;
use odocal_log::LogSummary;
use odocal_pipeline::{health, Options};

/// Arguments of `odocal info`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// The log and how to read it.
    #[command(flatten)]
    pub read: ReadArgs,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
}

/// Runs `odocal info`.
pub fn run(args: Args) -> anyhow::Result<()> {
    let log = args.read.read_log()?;
    let summary = LogSummary::of(&log);
    // The data-health checks that need no scan matching (clock jumps, duplicates,
    // frozen scans, wraps, spikes, gaps), as `calibrate` would report them.
    let opts = Options {
        ticks_per_revolution: args.read.ticks_per_rev,
        ..Options::default()
    };
    let (_, findings) = health::check_log(&log, &opts);
    if args.json {
        let mut value = serde_json::to_value(&summary).context("serializing the summary")?;
        if let Some(map) = value.as_object_mut() {
            map.insert(
                "health".into(),
                serde_json::to_value(&findings).context("serializing the findings")?,
            );
        }
        let text = serde_json::to_string_pretty(&value).context("serializing the summary")?;
        println!("{text}");
    } else {
        print!("{summary}");
        if !findings.is_empty() {
            println!("data health (what calibrate and match do about it):");
        }
        for f in &findings {
            println!("  {f}");
        }
    }
    Ok(())
}
