//! Why scan pairs fail on a log: matches every pair `stride` scans apart, from
//! odometry guesses with given parameters (sweep compensated), and tallies the errors.
//!
//! `cargo run --release -p odocal-pipeline --example match_diagnosis -- LOG STRIDE OFFSET r_l r_r b l_x l_y l_theta`
//!
//! On a simulated preset, with its truth (the true parameters give the guesses; every
//! result is compared with the true displacement of the sensor at mid-sweep, and
//! every refused pair is matched again without the consistency test to tell right
//! refusals from wrong ones):
//!
//! `cargo run --release -p odocal-pipeline --example match_diagnosis -- --preset NAME SEED STRIDE [DURATION]`
//!
//! Environment: `NOISE` prints the scans' own range noise; `DUMP` every pair's guess
//! and result or error; `RATIO`, `SHARE`, `MAXR` and `TYPICAL` override
//! `max_residual_to_noise`, `min_matched_share`, `max_reading` and
//! `typical_noise_sigma`.

use odocal_geom::Pose2;
use odocal_icp::IcpParams;
use odocal_log::Log;
use odocal_pipeline::matching::{match_pairs, MatchStats};
use odocal_pipeline::rejection::MatchFailure;
use odocal_pipeline::sweep::{compensated_pairs, reference_time};
use odocal_pipeline::sync::{EncoderTrack, SyncLimits};
use odocal_solver::Params;
use std::collections::BTreeMap;

/// Matches farther than this from the truth are wrong (m, rad).
const RIGHT_XY: f64 = 0.005;
const RIGHT_THETA: f64 = 0.5 * std::f64::consts::PI / 180.0;

type Outcome = Result<MatchStats, MatchFailure>;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let a: Vec<String> = std::env::args().collect();
    if a.len() >= 5 && a[1] == "--preset" {
        return preset_mode(&a[2], a[3].parse()?, a[4].parse()?, a.get(5));
    }
    if a.len() < 10 {
        return Err("usage: LOG STRIDE OFFSET r_l r_r b l_x l_y l_theta, or --preset NAME SEED STRIDE [DURATION]".into());
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
    if std::env::var("NOISE").is_ok() {
        print_noise(&log)?;
    }
    let Matched {
        pairs,
        guesses,
        results,
        store,
    } = match_log(&log, stride, offset, &params, &icp_params()?);
    tally(&results);
    if let Ok(first) = std::env::var("PLOT") {
        let first: usize = first.parse()?;
        let k = pairs
            .iter()
            .position(|p| p.0 == first)
            .ok_or("no such pair")?;
        let relaxed = IcpParams {
            max_residual_to_noise: f64::INFINITY,
            min_matched_share: 0.0,
            ..icp_params()?
        };
        let (a, b) = pairs[k];
        let r = match_pairs(&store, &[(a, b)], &[guesses[k]], &relaxed, || {});
        let pose = r[0].as_ref().map_or(guesses[k], |m| m.pose);
        for (scan, at) in [(a, Pose2::IDENTITY), (b, pose)] {
            let s = store.get(scan).ok_or("no scan")?;
            for (&range, &angle) in s.ranges.iter().zip(s.geometry.angles.iter()) {
                if range > 0.02 && f64::from(range) < s.geometry.max_range {
                    let q = Pose2::new(
                        f64::from(range) * angle.cos(),
                        f64::from(range) * angle.sin(),
                        0.0,
                    );
                    let p = at.compose(&q);
                    println!("P {scan} {:.4} {:.4}", p.x, p.y);
                }
            }
        }
    }
    if std::env::var("DUMP").is_ok() {
        for ((p, g), r) in pairs.iter().zip(&guesses).zip(&results) {
            println!("{}", pair_line(*p, g, r, None));
        }
    }
    Ok(())
}

/// The matcher's parameters, with the environment's overrides.
fn icp_params() -> Result<IcpParams, Box<dyn std::error::Error>> {
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
    if let Ok(v) = std::env::var("TYPICAL") {
        icp.typical_noise_sigma = v.parse()?;
    }
    Ok(icp)
}

/// The pairs of a log, their guesses, the matcher's outcomes, and the
/// (sweep-compensated) scans matched.
struct Matched {
    pairs: Vec<(usize, usize)>,
    guesses: Vec<Pose2>,
    results: Vec<Outcome>,
    store: odocal_log::ScanStore,
}

/// Every pair `stride` scans apart with wheel readings around both scans: the pairs,
/// their odometry guesses, and the matcher's outcomes.
fn match_log(log: &Log, stride: usize, offset: f64, params: &Params, icp: &IcpParams) -> Matched {
    let ticks = log
        .params
        .ticks_per_revolution
        .as_ref()
        .map_or(2000.0, |t| t.0);
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
        let laser = params.laser;
        guesses.push(laser.inverse().compose(&robot).compose(&laser));
        pairs.push((i, j));
    }
    let (store, _) = compensated_pairs(&log.scans, &pairs, &track, &limits, params, offset);
    let results = match_pairs(&store, &pairs, &guesses, icp, || {});
    Matched {
        pairs,
        guesses,
        results,
        store,
    }
}

/// The scans' own range noise (distribution over the log).
fn print_noise(log: &Log) -> Result<(), Box<dyn std::error::Error>> {
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
    Ok(())
}

/// Matched share and refusals by reason.
fn tally(results: &[Outcome]) {
    let mut by_reason: BTreeMap<String, usize> = BTreeMap::new();
    let mut ok = 0;
    for r in results {
        match r {
            Ok(_) => ok += 1,
            Err(e) => *by_reason.entry(e.reason.key().to_string()).or_default() += 1,
        }
    }
    println!(
        "{} pairs, {} matched ({:.0} %)",
        results.len(),
        ok,
        100.0 * ok as f64 / results.len().max(1) as f64
    );
    for (k, n) in by_reason {
        println!("  {n:5}  {k}");
    }
}

/// One pair's guess and outcome (and its error against the truth when known).
fn pair_line(p: (usize, usize), g: &Pose2, r: &Outcome, error: Option<(f64, f64)>) -> String {
    let head = format!(
        "{:4} {:4} guess {:.3} {:.3} {:.2}°",
        p.0,
        p.1,
        g.x,
        g.y,
        g.theta.to_degrees()
    );
    let truth = error.map_or(String::new(), |(d, a)| {
        format!(" | err {:.1} mm {:.2}°", d * 1e3, a.to_degrees())
    });
    match r {
        Ok(m) => format!(
            "{head} ok {:.3} {:.3} {:.2}° res {:.1} mm{truth}",
            m.pose.x,
            m.pose.y,
            m.pose.theta.to_degrees(),
            m.mean_residual * 1e3
        ),
        Err(e) => format!("{head} ERR {e}{truth}"),
    }
}

/// Error of `pose` against `truth`: translation (m) and rotation (rad).
fn error(truth: &Pose2, pose: &Pose2) -> (f64, f64) {
    let e = truth.inverse().compose(pose);
    (e.x.hypot(e.y), odocal_geom::wrap_angle(e.theta).abs())
}

fn is_right(e: (f64, f64)) -> bool {
    e.0 <= RIGHT_XY && e.1 <= RIGHT_THETA
}

/// The simulated preset `name`, matched with the true parameters' guesses and
/// compared with the truth.
fn preset_mode(
    name: &str,
    seed: u64,
    stride: usize,
    duration: Option<&String>,
) -> Result<(), Box<dyn std::error::Error>> {
    let mut config = odocal_sim::SimConfig::preset(name)?;
    config.seed = seed;
    if let Some(d) = duration {
        config.duration = d.parse()?;
    }
    let run = odocal_sim::simulate(&config)?;
    let log = run.to_log();
    let truth_scans: Vec<Pose2> = run.logged_scans().map(|s| s.sensor_at_reference).collect();
    let robot = &config.robot;
    let params = Params {
        r_l: robot.r_l,
        r_r: robot.r_r,
        b: robot.b,
        laser: robot.laser,
    };
    if std::env::var("NOISE").is_ok() {
        print_noise(&log)?;
    }
    let icp = icp_params()?;
    let Matched {
        pairs,
        guesses,
        results,
        ..
    } = match_log(&log, stride, 0.0, &params, &icp);
    let relaxed_icp = IcpParams {
        max_residual_to_noise: f64::INFINITY,
        min_matched_share: 0.0,
        ..icp.clone()
    };
    let relaxed = match_log(&log, stride, 0.0, &params, &relaxed_icp).results;
    let truth: Vec<Pose2> = pairs
        .iter()
        .map(|&(i, j)| truth_scans[i].inverse().compose(&truth_scans[j]))
        .collect();
    tally(&results);
    // Accepted: right or wrong; refused: what the match without the consistency
    // test would have given (right, wrong, or still failing).
    let (mut right, mut wrong) = (0, 0);
    let mut refused: BTreeMap<String, [usize; 3]> = BTreeMap::new();
    for k in 0..pairs.len() {
        match &results[k] {
            Ok(m) => {
                if is_right(error(&truth[k], &m.pose)) {
                    right += 1
                } else {
                    wrong += 1
                }
            }
            Err(e) => {
                let slot = match &relaxed[k] {
                    Ok(m) if is_right(error(&truth[k], &m.pose)) => 0,
                    Ok(_) => 1,
                    Err(_) => 2,
                };
                refused.entry(e.reason.key().to_string()).or_default()[slot] += 1;
            }
        }
    }
    println!("accepted: {right} within 5 mm / 0.5° of the truth, {wrong} beyond");
    for (k, [r, w, f]) in refused {
        println!("refused {k}: without the consistency test {r} right, {w} wrong, {f} failing");
    }
    if std::env::var("DUMP").is_ok() {
        for k in 0..pairs.len() {
            let r = &results[k];
            let e = match r {
                Ok(m) => Some(error(&truth[k], &m.pose)),
                Err(_) => relaxed[k].as_ref().ok().map(|m| error(&truth[k], &m.pose)),
            };
            println!("{}", pair_line(pairs[k], &guesses[k], r, e));
        }
    }
    Ok(())
}
