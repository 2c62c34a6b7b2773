//! A log played backwards holds the same data: the robot drives the same path in
//! reverse, every scan pair is matched with its two scans' roles exchanged, and a
//! calibration without a preferred direction finds the same robot. The difference
//! between the two calibrations is an error of the matching (or of the pipeline)
//! measured without ground truth.
//!
//! Measured (docs/benchmarks.md, "Logs played backwards"; the same pairs both ways):
//! every log comes out smaller backwards, the clean Khepera log by 0.07 %, the
//! realistic rover by 0.4–0.5 %, the real MinesRover logs by 0.7–2.0 % (exp1 r_L
//! −1.28 %, exp2 b −1.96 %). The wheels agree pair for pair; the scan matches do not:
//! a pair matched with its scans' roles exchanged comes out shorter (median ratio of
//! the translations 1.0000 on Khepera, 0.9956 on the rover, 0.9915 and 0.9906 on the
//! real logs). The point-to-line matcher prefers a direction: not fixed yet.

mod common;

use common::{mines_log, rays_listed_backwards, simulated_120s};
use odocal_geom::Pose2;
use odocal_log::{EncoderRecord, Log, ScanGeometry, ScanStore};
use odocal_pipeline::{calibrate_log, NoProgress, Options};
use std::collections::BTreeMap;

/// `log` played backwards: every record at `t_first + t_last − t`, in the new time
/// order; the encoder counts as they are (the wheels turn backwards); the rays of each
/// scan in reverse order (a negative angular step), stamped with the time of the last
/// ray so that the sweep still runs forward in time. The firmware's odometry poses
/// are left out, and so are the `skip` last scans of `log` (the first ones played).
/// Also returns `t_first + t_last`: a time `t` of `log` is that minus `t` backwards.
fn played_backwards(log: &Log, skip: usize) -> (Log, f64) {
    let sweep_end = |t: f64, g: &ScanGeometry| t + g.sweep_duration();
    let times = log.encoders.iter().map(|e| e.t).chain(
        log.scans
            .iter()
            .flat_map(|s| [s.t, sweep_end(s.t, s.geometry)]),
    );
    let (first, last) = times.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), t| {
        (lo.min(t), hi.max(t))
    });
    let mirror = first + last;
    let encoders: Vec<EncoderRecord> = log
        .encoders
        .iter()
        .rev()
        .map(|e| EncoderRecord {
            t: mirror - e.t,
            ..*e
        })
        .collect();
    let mut scans = ScanStore::default();
    let last_first = (0..log.scans.len()).rev().skip(skip);
    for s in last_first.filter_map(|i| log.scans.get(i)) {
        let (geometry, ranges) = rays_listed_backwards(s.geometry, s.ranges);
        scans.push(
            mirror - sweep_end(s.t, s.geometry),
            &geometry,
            &ranges,
            s.kind,
            s.line,
        );
    }
    let played = Log {
        encoders,
        odom: Vec::new(),
        scans,
        ..log.clone()
    };
    (played, mirror)
}

/// Forward and backward calibrations of `log`: the six parameters and their data σ.
/// The scans are paired `stride` apart from the first one played, so the backward log
/// leaves out as many of its first scans as make it pair the same scans as the
/// forward one (otherwise the two calibrate different pairs of the same log: on the
/// real exp1, the four ways of pairing every fourth scan alone spread r_L over
/// 74.08–74.65 mm and ℓx over 105–143 mm).
fn both_ways(log: &Log) -> BothWays {
    let opts = Options {
        accept_weak: true,
        ..Options::default()
    };
    let calibrated =
        |l: &Log| calibrate_log(l, &opts, &NoProgress).unwrap_or_else(|e| panic!("refused: {e}"));
    let forward = calibrated(log);
    let skip = (log.scans.len() - 1) % forward.synced.stride.max(1);
    let (played, mirror) = played_backwards(log, skip);
    let backward = calibrated(&played);
    // A pair's scans by their times (µs; a scan's time backwards is `mirror` minus its
    // time forwards): the backward match, inverted, against the forward one.
    let key = |t0: f64, t1: f64| ((t0 * 1e6).round() as i64, (t1 * 1e6).round() as i64);
    let matches: BTreeMap<(i64, i64), Pose2> = backward
        .synced
        .samples
        .iter()
        .map(|s| {
            let pose = s.icp.pose.inverse();
            (key(mirror - s.pair.t1, mirror - s.pair.t0), pose)
        })
        .collect();
    let mut ratios: Vec<f64> = forward
        .synced
        .samples
        .iter()
        .filter_map(|s| {
            let f = s.icp.pose;
            let b = matches.get(&key(s.pair.t0, s.pair.t1))?;
            (f.translation_norm() > MIN_TRANSLATION)
                .then(|| b.translation_norm() / f.translation_norm())
        })
        .collect();
    ratios.sort_by(f64::total_cmp);
    let summary = |o: &odocal_pipeline::Outcome| {
        let c = &o.calibration;
        (
            c.params.to_vector(),
            std::array::from_fn(|i| c.covariance[i][i].sqrt()),
        )
    };
    BothWays {
        forward: summary(&forward),
        backward: summary(&backward),
        pairs: ratios.len(),
        length_ratio: ratios.get(ratios.len() / 2).copied().unwrap_or(f64::NAN),
    }
}

/// Pairs whose forward match moves the sensor less than this (m) are left out of the
/// length ratio.
const MIN_TRANSLATION: f64 = 0.02;

/// The calibrations of a log both ways (parameters and their data σ), and the median
/// ratio of the backward matches' translations to the forward ones over the `pairs`
/// pairs both matched (the backward ones inverted).
struct BothWays {
    forward: ([f64; 6], [f64; 6]),
    backward: ([f64; 6], [f64; 6]),
    pairs: usize,
    length_ratio: f64,
}

const NAMES: [&str; 6] = ["r_L", "r_R", "b", "l_x", "l_y", "l_theta"];

/// Prints the two calibrations and returns the relative differences of r_L, r_R, b
/// and the differences of ℓx, ℓy (m) and ℓθ (rad), backward minus forward, and the
/// median ratio of the backward matches' translations to the forward ones.
fn report(label: &str, log: &Log) -> ([f64; 6], f64) {
    let both = both_ways(log);
    let ((f, fs), (b, _)) = (both.forward, both.backward);
    println!(
        "{label}: the backward matches' translations against the forward ones over {} \
         pairs: median ratio {:.4}",
        both.pairs, both.length_ratio
    );
    let d: [f64; 6] = std::array::from_fn(|i| {
        if i < 3 {
            b[i] / f[i] - 1.0
        } else {
            b[i] - f[i]
        }
    });
    for i in 0..6 {
        println!(
            "{label} {}: forward {:.5} ± {:.5}, backward {:.5} ({})",
            NAMES[i],
            f[i],
            fs[i],
            b[i],
            if i < 3 {
                format!("{:+.2} %", 100.0 * d[i])
            } else {
                format!("{:+.5}", d[i])
            }
        );
    }
    (d, both.length_ratio)
}

#[test]
fn a_clean_log_calibrates_the_same_played_backwards() {
    // Measured: r_L, r_R, b −0.07 %, ℓx −0.10 mm, ℓy −0.19 mm, ℓθ −0.12 mrad (seed 7,
    // 120 s; data σ of r_L 0.04 %), the matches' translations the same both ways
    // (median ratio 1.0000 over 134 pairs): the pipeline's own preference for a
    // direction of time, on scans that match exactly, is this small.
    let (d, length_ratio) = report("khepera", &simulated_120s("khepera", 7));
    assert!((length_ratio - 1.0).abs() < 1e-3, "{length_ratio}");
    for (i, limit) in [0.002, 0.002, 0.002, 5e-4, 5e-4, 1e-3]
        .into_iter()
        .enumerate()
    {
        assert!(d[i].abs() < limit, "{}: {:+e} backwards", NAMES[i], d[i]);
    }
}

#[test]
fn a_swept_log_calibrates_the_same_played_backwards() {
    // The reversal keeps each sweep running forward in time (the rays in reverse order
    // from the last one's time): the realistic rover (0.6 m/s, a 67 ms sweep, people,
    // range bias, mixed pixels) calibrates the same both ways to within the 1 %
    // range-scale σ. Measured (seed 8): r_L −0.41 %, r_R −0.45 %, b −0.47 %, the
    // matches' translations 0.44 % shorter backwards (median ratio 0.9956, 175 pairs).
    // The real logs are held to about this level by the ignored test below (exp1 r_L
    // −1.28 %, its matches 0.85 % shorter).
    // It is a bound on the matching's preference for a direction, not a check of the
    // reversal: the sweep stamped at the wrong end (the first ray's time, 67 ms off)
    // gives +0.10 %, +0.06 %, +0.06 %.
    let (d, length_ratio) = report("mines-rover", &simulated_120s("mines-rover", 8));
    assert!((length_ratio - 1.0).abs() < 0.01, "{length_ratio}");
    for (i, &di) in d.iter().enumerate().take(3) {
        assert!(
            di.abs() < 0.01,
            "{}: {:+.2} % backwards",
            NAMES[i],
            100.0 * di
        );
    }
}

#[test]
#[ignore = "issue 20's open problem, fails today: the real MinesRover logs move up to 2 % when played backwards (printed on demand)"]
fn the_real_logs_calibrate_the_same_played_backwards() {
    // The target: the real logs move no more than the simulated rover (1 % on the
    // radii and b, 0.5 % on the matches' translations). Today: exp1 r_L −1.28 %, r_R
    // −1.38 %, b −0.83 %, matches 0.9915; exp2 r_L −0.86 %, r_R −0.65 %, b −1.96 %,
    // matches 0.9906.
    // `cargo test --release --test played_backwards -- --ignored --nocapture`.
    let mut failures = Vec::new();
    for name in ["exp1.log", "exp2.log"] {
        let Some(path) = mines_log(name) else { return };
        let log = odocal_log::read_log(&path, &Default::default()).unwrap();
        let (d, length_ratio) = report(name, &log);
        if (length_ratio - 1.0).abs() >= 0.005 {
            failures.push(format!("{name} matches: {length_ratio:.4}"));
        }
        for (i, &di) in d.iter().enumerate().take(3) {
            if di.abs() >= 0.01 {
                failures.push(format!("{name} {}: {:+.2} %", NAMES[i], 100.0 * di));
            }
        }
    }
    assert!(failures.is_empty(), "moved backwards: {failures:?}");
}
