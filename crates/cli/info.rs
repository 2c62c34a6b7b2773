//! `odocal info LOG`: describe a log — counts per message kind, time span, scan
//! geometry, encoder rate, where ticks per revolution came from, unknown and skipped
//! lines, and the data-health findings that need no scan matching. `--json` prints the
//! same as one JSON object (findings under `health`). For a ROS bag: every topic (type,
//! count, rate, span), the laser geometry, the joint names, and which topics `calibrate`
//! would use and why.

use crate::read_args::ReadArgs;
use crate::terminal::{out, outln, write_json_stdout};
use anyhow::Context;
use odocal_bag::inspect_bag;
use odocal_log::{sensor_value, LogSummary};
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
    let range_scale = opts.range_scale(&log);
    if args.json {
        let mut value = serde_json::to_value(&summary).context("serializing the summary")?;
        if let Some(map) = value.as_object_mut() {
            map.insert(
                "health".into(),
                serde_json::to_value(&findings).context("serializing the findings")?,
            );
            map.insert("range_scale".into(), serde_json::to_value(&range_scale)?);
        }
        let text = serde_json::to_string_pretty(&value).context("serializing the summary")?;
        write_json_stdout(&text)?;
    } else {
        out!("{summary}")?;
        outln!("laser range scale: {}", range_scale.sentence())?;
        print_findings(&findings)?;
    }
    Ok(())
}

/// `odocal info BAG`.
fn bag_info(args: &Args) -> anyhow::Result<()> {
    let info = inspect_bag(&args.read.log, &args.read.bag_options()?)
        .map_err(|e| anyhow::anyhow!("{e}"))?;
    let (choice, summary, findings) = match &info.calibration {
        Ok((sel, log)) => (
            Ok(sel),
            Some(LogSummary::of(log)),
            health::check_log(log, &Options::default()).1,
        ),
        Err(e) => (Err(e.to_string()), None, Vec::new()),
    };
    // The range finder `calibrate` would recognise in the chosen scans.
    let range_scale = info.calibration.as_ref().ok().map(|(_, log)| {
        Options {
            laser_frame: info.nominal_laser.as_ref().map(|l| l.laser_frame.clone()),
            ..Options::default()
        }
        .range_scale(log)
    });
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
            o.insert("health".into(), serde_json::to_value(&findings)?);
            if let Some(l) = &info.nominal_laser {
                o.insert("nominal_laser".into(), serde_json::to_value(l)?);
            }
            if let Some(r) = &range_scale {
                o.insert("range_scale".into(), serde_json::to_value(r)?);
            }
        }
        write_json_stdout(&serde_json::to_string_pretty(&obj)?)?;
        return Ok(());
    }
    outln!(
        "{} ({:?}, {:.1} MB)",
        args.read.log.display(),
        info.format,
        info.bytes_read as f64 / 1e6
    )?;
    outln!("topics:")?;
    for t in &info.topics {
        let rate = t.rate_hz().map_or("-".into(), |r| format!("{r:.1} Hz"));
        outln!(
            "  {}  {}  {} messages  {rate}  {:.1} s",
            t.name,
            t.type_name,
            t.count,
            t.span_s()
        )?;
    }
    for l in &info.lasers {
        let f = &l.fields;
        outln!(
            "laser {}: {} rays, angle {:.4} to {:.4} rad step {:.6} rad, range {} to {} m, \
             time_increment {} s, scan_time {} s",
            l.topic,
            l.rays,
            f.angle_min,
            f.angle_max,
            f.angle_increment,
            sensor_value(f.range_min),
            sensor_value(f.range_max),
            sensor_value(f.time_increment),
            sensor_value(f.scan_time)
        )?;
    }
    for (t, names) in &info.joints {
        outln!("joints of {t}: {}", names.join(", "))?;
    }
    if let Some(l) = &info.nominal_laser {
        outln!(
            "nominal laser pose ({} {} -> {}): l_x = {:.4} m, l_y = {:.4} m, \
             l_theta = {:.4} rad ({:.2}°), height {:.3} m",
            l.source,
            l.base_frame,
            l.laser_frame,
            l.x,
            l.y,
            l.theta,
            l.theta.to_degrees(),
            l.z
        )?;
        if l.tilt > 1f64.to_radians() {
            outln!(
                "note: the laser is tilted {:.1}° from level; the planar calibration assumes it level",
                l.tilt.to_degrees()
            )?;
        }
    }
    for w in &info.warnings {
        outln!("note: {w}")?;
    }
    match choice {
        Ok(sel) => {
            outln!("calibrate would use:")?;
            for r in &sel.reasons {
                outln!("  {r}")?;
            }
        }
        Err(e) => outln!("calibrate cannot choose: {e}")?,
    }
    if let Some(s) = summary {
        print_bag_summary(&s)?;
    }
    if let Some(r) = &range_scale {
        outln!("laser range scale: {}", r.sentence())?;
    }
    print_findings(&findings)?;
    Ok(())
}

/// The data-health findings, under a heading when there are any.
fn print_findings(findings: &[odocal_pipeline::Finding]) -> anyhow::Result<()> {
    if !findings.is_empty() {
        outln!("data health (what calibrate and match do about it):")?;
    }
    for f in findings {
        outln!("  {f}")?;
    }
    Ok(())
}

/// What calibrate would read from a bag, in a bag's terms (messages and stamps; a bag
/// has no lines, comments or encoder ticks).
fn print_bag_summary(s: &LogSummary) -> anyhow::Result<()> {
    let wheels = if s.encoder_records > 0 {
        format!("{} wheel joint-state messages", s.encoder_records)
    } else {
        format!("{} odometry messages", s.odom_records)
    };
    outln!("calibrate reads:  {} scans, {wheels}", s.scans)?;
    match (s.start_time, s.end_time) {
        (Some(a), Some(b)) => outln!(
            "stamps:           {a:.3} … {b:.3} s ({:.3} s)",
            s.duration_s
        ),
        _ => outln!("stamps:           none"),
    }?;
    for g in &s.geometries {
        outln!("scan geometry:    {}: {} scans", g.rays_text(), g.scans)?;
    }
    let hz = |r: Option<f64>| r.map_or("n/a".to_string(), |r| format!("{r:.2} Hz"));
    outln!("scan rate:        {}", hz(s.scan_rate_hz))?;
    if s.encoder_records > 0 {
        outln!("joint-state rate: {}", hz(s.encoder_rate_hz))?;
    } else if s.odom_records > 0 {
        outln!("odometry rate:    {}", hz(s.odom_rate_hz))?;
    }
    outln!(
        "invalid ranges:   {} ({:.2}%)",
        s.invalid_readings,
        100.0 * s.invalid_fraction
    )?;
    for (stream, n) in &s.out_of_order {
        outln!("out of order:     {n} {stream} messages by stamp (sorted)")?;
    }
    for w in &s.warnings {
        outln!("warning:          {w}")?;
    }
    Ok(())
}
