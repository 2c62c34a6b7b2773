//! Why scan pairs fail on a log: matches every pair `stride` scans apart, from
//! odometry guesses with given parameters (sweep compensated), and tallies the errors.
//!
//! `cargo run --release -p odocal-pipeline --example match_diagnosis -- LOG STRIDE OFFSET r_l r_r b l_x l_y l_theta`
//!
//! Environment: `NOISE` prints the scans' own range noise; `DUMP` every pair's guess
//! and result or error; `RATIO`, `SHARE` and `MAXR` override
//! `max_residual_to_noise`, `min_matched_share` and `max_reading`.

use odocal_geom::Pose2;
use odocal_icp::IcpParams;
use odocal_pipeline::matching::match_pairs;
use odocal_pipeline::sweep::{compensated_pairs, reference_time};
use odocal_pipeline::sync::{EncoderTrack, SyncLimits};
use odocal_solver::Params;
use std::collections::BTreeMap;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let a: Vec<String> = std::env::args().collect();
    if a.len() < 10 {
        return Err("usage: LOG STRIDE OFFSET r_l r_r b l_x l_y l_theta".into());
    }
    let log = odocal_log::read_log(std::path::Path::new(&a[1]), &Default::default())?;
    let stride: usize = a[2].parse()?;
    let offset: f64 = a[3].parse()?;
    let v: Vec<f64> = a[4..10]
        .iter()
        .map(|s| s.parse())
        .collect::<Result<_, _>>()?;
    let params = Params {
        r_l: v[0],
        r_r: v[1],
        b: v[2],
        laser: Pose2::new(v[3], v[4], v[5]),
    };
    let ticks = log.params.ticks_per_revolution.map_or(2000.0, |t| t.0);
    let track = EncoderTrack::new(&log.encoders, ticks);
    let enc_t: Vec<f64> = log.encoders.iter().map(|e| e.t).collect();
    let times: Vec<f64> = (0..log.scans.len())
        .map(|i| {
            log.scans
                .get(i)
                .map_or(log.scans.scans[i].t, |s| reference_time(&s))
        })
        .collect();
    let limits = SyncLimits::from_streams(&enc_t, &times, stride);
    let laser = Pose2::new(v[3], v[4], v[5]);
    let mut pairs = Vec::new();
    let mut guesses = Vec::new();
    let rpt = track.rad_per_tick();
    for i in 0..log.scans.len().saturating_sub(stride) {
        let j = i + stride;
        let (Ok(t0), Ok(t1)) = (
            track.ticks_at(times[i] - offset, 0.2),
            track.ticks_at(times[j] - offset, 0.2),
        ) else {
            continue;
        };
        let (sl, sr) = (
            params.r_l * rpt * (t1.0 - t0.0),
            params.r_r * rpt * (t1.1 - t0.1),
        );
        let (ds, dth) = (0.5 * (sl + sr), (sr - sl) / params.b);
        let robot = Pose2::new(ds * (0.5 * dth).cos(), ds * (0.5 * dth).sin(), dth);
        guesses.push(laser.inverse().compose(&robot).compose(&laser));
        pairs.push((i, j));
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
    let (store, _) = compensated_pairs(&log.scans, &pairs, &track, &limits, &params, offset);
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
