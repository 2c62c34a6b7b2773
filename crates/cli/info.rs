//! `odocal info LOG`: describe a log — counts per message kind, time span, scan
//! geometry, encoder rate, where ticks per revolution came from, unknown and skipped
//! lines, and the data-health findings that need no scan matching. `--json` prints the
//! same as one JSON object (findings under `health`). For a ROS bag: every topic (type,
//! count, rate, span), the laser geometry, the joint names, and which topics `calibrate`
//! would use and why.

use crate::read_args::ReadArgs;
use anyhow::Context;
use odocal_bag::inspect_bag;
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
    if args.read.is_bag()? {
        return bag_info(&args);
    }
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

/// `odocal info BAG`.
fn bag_info(args: &Args) -> anyhow::Result<()> {
    let info = inspect_bag(&args.read.log, &args.read.bag_options()?)
        .map_err(|e| anyhow::anyhow!("{e}"))?;
    let (choice, summary) = match &info.calibration {
        Ok((sel, log)) => (Ok(sel), Some(LogSummary::of(log))),
        Err(e) => (Err(e.to_string()), None),
    };
    if args.json {
        let mut obj = match &summary {
            Some(s) => serde_json::to_value(s)?,
            None => serde_json::json!({}),
        };
        let topics: serde_json::Map<String, serde_json::Value> = info
            .topics
            .iter()
            .map(|t| {
                (
                    t.name.clone(),
                    serde_json::json!({
                        "type": t.type_name, "count": t.count, "rate_hz": t.rate_hz(),
                        "span_s": t.span_s(), "encoding": t.encoding,
                    }),
                )
            })
            .collect();
        if let Some(o) = obj.as_object_mut() {
            o.insert("format".into(), serde_json::to_value(info.format)?);
            o.insert("topics".into(), topics.into());
            o.insert("lasers".into(), serde_json::to_value(&info.lasers)?);
            let joints: serde_json::Map<_, _> = info
                .joints
                .iter()
                .map(|(t, n)| (t.clone(), serde_json::json!(n)))
                .collect();
            o.insert("joint_names".into(), joints.into());
            match &choice {
                Ok(sel) => o.insert("calibration_uses".into(), serde_json::to_value(sel)?),
                Err(e) => o.insert("calibration_error".into(), e.clone().into()),
            };
            o.insert("warnings_bag".into(), serde_json::json!(info.warnings));
        }
        println!("{}", serde_json::to_string_pretty(&obj)?);
        return Ok(());
    }
    println!(
        "{} ({:?}, {:.1} MB)",
        args.read.log.display(),
        info.format,
        info.bytes_read as f64 / 1e6
    );
    println!("topics:");
    for t in &info.topics {
        let rate = t.rate_hz().map_or("-".into(), |r| format!("{r:.1} Hz"));
        println!(
            "  {}  {}  {} messages  {rate}  {:.1} s",
            t.name,
            t.type_name,
            t.count,
            t.span_s()
        );
    }
    for l in &info.lasers {
        let f = &l.fields;
        println!(
            "laser {}: {} rays, angle {:.4} to {:.4} rad step {:.6} rad, range {} to {} m, \
             time_increment {} s, scan_time {} s",
            l.topic,
            l.rays,
            f.angle_min,
            f.angle_max,
            f.angle_increment,
            f.range_min,
            f.range_max,
            f.time_increment,
            f.scan_time
        );
    }
    for (t, names) in &info.joints {
        println!("joints of {t}: {}", names.join(", "));
    }
    for w in &info.warnings {
        println!("note: {w}");
    }
    match choice {
        Ok(sel) => {
            println!("calibrate would use:");
            for r in &sel.reasons {
                println!("  {r}");
            }
        }
        Err(e) => println!("calibrate cannot choose: {e}"),
    }
    if let Some(s) = summary {
        print!("{s}");
    }
    Ok(())
}
