//! `odocal info LOG`: describe a log — counts per message kind, time span, scan
//! geometry, encoder rate, where ticks per revolution came from, unknown and skipped
//! lines. `--json` prints the same as one JSON object.

use crate::read_args::ReadArgs;
use anyhow::Context;
use odocal_log::LogSummary;

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
    if args.json {
        let text = serde_json::to_string_pretty(&summary).context("serializing the summary")?;
        println!("{text}");
    } else {
        print!("{summary}");
    }
    Ok(())
}
