//! Why scan pairs fail on a log: matches every pair `stride` scans apart, from
//! odometry guesses with given parameters (sweep compensated), and tallies the errors.
//!
//! `cargo run --release -p odocal-pipeline --example match_diagnosis -- LOG STRIDE OFFSET r_l r_r b l_x l_y l_theta`
//!
//! Environment: `NOISE` prints the scans' own range noise; `DUMP` every pair's guess
//! and result or error; `RATIO`, `SHARE` and `MAXR` override
//! `max_residual_to_noise`, `min_matched_share` and `max_reading`.

use odocal_icp::IcpParams;
use odocal_pipeline::matching::match_pairs;
use odocal_pipeline::sweep::compensated_pairs;
use odocal_pipeline::sync::{EncoderTrack, SyncLimits};
use std::collections::BTreeMap;

mod common;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let a: Vec<String> = std::env::args().collect();
    let setup = common::Setup::from_args(&a)?;
    let (log, stride, offset, params) = (&setup.log, setup.stride, setup.offset, &setup.params);
    let track = EncoderTrack::new(&log.encoders, setup.ticks);
    let limits = SyncLimits::from_streams(&setup.encoder_times(), &setup.times, stride);
    let mut pairs = Vec::new();
    let mut guesses = Vec::new();
    for i in 0..log.scans.len().saturating_sub(stride) {
        let Some(g) = setup.guess(&track, i, i + stride) else {
            continue;
        };
        guesses.push(g);
        pairs.push((i, i + stride));
    }
    if std::env::var("NOISE").is_ok() {
        let mut n: Vec<f64> = (0..log.scans.len())
            .filter_map(|i| {
                let s = log.scans.get(i)?;
                let p = odocal_icp::PreparedScan::new(
                    s.ranges,
                    &s.geometry.angles,
                    s.geometry.min_range,
                    s.geometry.max_range,
                    &IcpParams::default(),
                )
                .ok()?;
                Some(p.noise_sigma()? * 1e3)
            })
            .collect();
        if n.is_empty() {
            return Err("no scan shows its noise".into());
        }
        n.sort_by(f64::total_cmp);
        println!(
            "scan noise mm: min {:.2} p10 {:.2} median {:.2} p90 {:.2} max {:.2}",
            n[0],
            n[n.len() / 10],
            n[n.len() / 2],
            n[n.len() * 9 / 10],
            n[n.len() - 1]
        );
    }
    let (store, _) = compensated_pairs(&log.scans, &pairs, &track, &limits, params, offset);
    let mut icp = IcpParams::default();
    if let Ok(v) = std::env::var("RATIO") {
        icp.max_residual_to_noise = v.parse()?;
    }
    if let Ok(v) = std::env::var("SHARE") {
        icp.min_matched_share = v.parse()?;
    }
    if let Ok(v) = std::env::var("MAXR") {
        icp.max_reading = v.parse()?;
    }
    let results = match_pairs(&store, &pairs, &guesses, &icp, || {});
    let mut tally: BTreeMap<String, usize> = BTreeMap::new();
    let mut ok = 0;
    for r in &results {
        match r {
            Ok(_) => ok += 1,
            Err(e) => {
                let key = e.reason.key().to_string();
                *tally.entry(key).or_default() += 1;
            }
        }
    }
    println!(
        "{} pairs, {} matched ({:.0} %)",
        results.len(),
        ok,
        100.0 * ok as f64 / results.len() as f64
    );
    for (k, n) in tally {
        println!("  {n:5}  {k}");
    }
    if std::env::var("DUMP").is_ok() {
        for ((p, g), r) in pairs.iter().zip(&guesses).zip(&results) {
            match r {
                Ok(m) => println!(
                    "{:4} {:4} guess {:.3} {:.3} {:.2}° ok {:.3} {:.3} {:.2}° res {:.1} mm",
                    p.0,
                    p.1,
                    g.x,
                    g.y,
                    g.theta.to_degrees(),
                    m.pose.x,
                    m.pose.y,
                    m.pose.theta.to_degrees(),
                    m.mean_residual * 1e3
                ),
                Err(e) => println!(
                    "{:4} {:4} guess {:.3} {:.3} {:.2}° ERR {e}",
                    p.0,
                    p.1,
                    g.x,
                    g.y,
                    g.theta.to_degrees()
                ),
            }
        }
    }
    Ok(())
}
