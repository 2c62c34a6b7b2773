//! Issue 13's target "on a real log of a fast robot: a result or a reasoned refusal,
//! and two logs of the same robot agree within their σ", on the closest simulated
//! stand-in for that log: a Pioneer-class robot with a sweeping URG-04LX driven like
//! with a joystick (straights and arcs, no spins in place: the `no-spins` trajectory)
//! at up to 0.6 m/s for 75 s, the encoder counts stored with each scan, the laser clock
//! 0.15 s ahead of the encoders. "Two logs of the same robot" are two seeds with the
//! same true parameters. The recommended command (`--estimate-time-offset`) must give,
//! for each log, either a refusal that names the parameter and a fix, or numbers
//! within 4σ of the truth; two logs that both give numbers must agree within the 3σ
//! level of χ² (difference against the sum of the covariances). The default command
//! (no clock flag) estimates the offset its quick check finds and meets the same
//! bounds; with the offset given as known (`--time-offset 0`), each log is refused with
//! the offset named, or its numbers come with the clock-offset warning that names the
//! flag. Seeds are held out.

mod common;

use common::accuracy::NAMES;
use common::{cleanup, simulated_log, Truth};
use odocal_log::{read_log, ReadOptions};
use odocal_pipeline::sync::DiscardReason;
use odocal_pipeline::{calibrate_log, FindingKind, NoProgress, Options, Outcome, PipelineError};
use odocal_sim::TrajectoryKind;
use odocal_solver::Verdict;
use std::path::{Path, PathBuf};

/// χ² at the 3σ level (p = 0.9973) for 1 to 6 degrees of freedom.
const CHI2_3SIGMA: [f64; 6] = [9.0, 11.83, 14.16, 16.25, 18.21, 20.06];

/// The stand-in log for `seed`; `turn_radius` is the driver's tightest turn (m).
fn fast_robot_log(seed: u64, turn_radius: f64) -> (PathBuf, Truth) {
    jittered_log(seed, turn_radius, None)
}

/// The stand-in log, the counts read `±jitter` s (uniform) around their stamp when
/// given (the preset's ±2 ms otherwise).
fn jittered_log(seed: u64, turn_radius: f64, jitter: Option<f64>) -> (PathBuf, Truth) {
    let name = format!("fast-robot-{seed}-{turn_radius}-{jitter:?}");
    simulated_log(&name, "pioneer", 75.0, seed, |c| {
        c.trajectory = TrajectoryKind::NoSpins;
        c.motion.max_speed = 0.6;
        c.motion.turn_radius = turn_radius;
        c.encoder.with_scans = true;
        c.faults.clock_offset = 0.15;
        if let Some(j) = jitter {
            // The record rate only bounds the jitter here (one record per scan).
            c.encoder.rate_hz = 10.0;
            c.encoder.jitter_s = j;
        }
    })
}

/// The read-time jitter warning, naming the fix.
fn jitter_warning(o: &Outcome) -> bool {
    o.health.iter().any(|f| {
        f.kind == FindingKind::ReadJitter
            && f.message.contains("record the counts at the scan's time")
    })
}

fn calibrate(path: &Path, opts: &Options) -> Result<Outcome, PipelineError> {
    let log = read_log(path, &ReadOptions::default()).expect("the simulated log reads");
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap();
    pool.install(|| calibrate_log(&log, opts, &NoProgress))
}

fn with_offset_estimate() -> Options {
    Options {
        estimate_time_offset: Some(0.5),
        ..Options::default()
    }
}

/// A refusal must name a parameter, the missing motion or the fault, and a fix.
fn assert_reasoned(label: &str, e: &PipelineError) {
    let text = e.to_string();
    let names_parameter = NAMES.iter().any(|n| text.contains(n));
    let names_fix = text.contains("--fix") && text.contains("--prior");
    assert!(
        names_parameter && names_fix,
        "{label}: refusal without a parameter or a fix: {text}"
    );
}

/// An estimate and its covariance.
type Estimate = ([f64; 6], [[f64; 6]; 6]);

/// Checks one log calibrated with `opts`; returns the estimate and its covariance
/// when it gave numbers. A log of clean counts must not be warned of read-time
/// jitter.
fn check_log(label: &str, path: &Path, truth: &Truth, opts: &Options) -> Option<Estimate> {
    match checked_log(label, path, truth, opts, false) {
        Checked::Numbers(e) => Some(*e),
        Checked::Refused | Checked::Warned(_) => None,
    }
}

/// What a calibration gave.
enum Checked {
    /// Numbers within 4σ, no read-time jitter warning.
    Numbers(Box<Estimate>),
    /// A reasoned refusal.
    Refused,
    /// Numbers with the read-time jitter warning (allowed when `jitter_allowed`).
    Warned(Box<Estimate>),
}

fn checked_log(
    label: &str,
    path: &Path,
    truth: &Truth,
    opts: &Options,
    jitter_allowed: bool,
) -> Checked {
    match calibrate(path, opts) {
        Err(e) => {
            println!("{label}: refused: {e}");
            assert_reasoned(label, &e);
            Checked::Refused
        }
        Ok(o) if jitter_warning(&o) => {
            println!("{label}: read-time jitter warning");
            assert!(
                jitter_allowed,
                "{label}: read-time jitter found in clean counts"
            );
            let c = &o.calibration;
            Checked::Warned(Box::new((c.params.to_vector(), c.covariance)))
        }
        Ok(o) => {
            let c = &o.calibration;
            let est = c.params.to_vector();
            let mut line = format!(
                "{label}: offset {:+.3} s, {} samples, {} match failures;",
                o.synced.time_offset,
                c.samples_used,
                o.synced.discarded.get(DiscardReason::MatchFailed)
            );
            let mut beyond = Vec::new();
            for i in 0..6 {
                let sigma = c.covariance[i][i].sqrt();
                let z = (est[i] - truth[i]) / sigma;
                line += &format!(" {} {z:+.2}σ", NAMES[i]);
                if z.is_nan() || z.abs() > 4.0 {
                    beyond.push(NAMES[i]);
                }
            }
            println!("{line}");
            assert!(beyond.is_empty(), "{label}: {beyond:?} beyond 4σ: {line}");
            Checked::Numbers(Box::new((est, c.covariance)))
        }
    }
}

/// χ² of the difference of two estimates against the sum of their covariances, and
/// its degrees of freedom (parameters with a positive variance in the sum).
fn pair_chi2(a: &Estimate, b: &Estimate) -> (f64, usize) {
    let keep: Vec<usize> = (0..6).filter(|&i| a.1[i][i] + b.1[i][i] > 0.0).collect();
    let n = keep.len();
    let d = nalgebra::DVector::from_iterator(n, keep.iter().map(|&i| a.0[i] - b.0[i]));
    let s = nalgebra::DMatrix::from_fn(n, n, |r, c| {
        let (i, j) = (keep[r], keep[c]);
        a.1[i][j] + b.1[i][j]
    });
    let chi2 = s
        .cholesky()
        .map(|ch| d.dot(&ch.solve(&d)))
        .unwrap_or(f64::INFINITY);
    (chi2, n)
}

/// Two logs of the same robot agree within the 3σ level of χ².
fn assert_agree(seeds: (u64, u64), a: &Estimate, b: &Estimate) {
    let (chi2, dof) = pair_chi2(a, b);
    println!("seeds {seeds:?}: χ² {chi2:.1} for {dof} parameters");
    assert!(
        dof > 0 && chi2 <= CHI2_3SIGMA[dof - 1],
        "seeds {seeds:?}: two logs of the same robot disagree: χ² {chi2:.1} for {dof} \
         parameters (3σ level {})",
        CHI2_3SIGMA[dof - 1]
    );
}

/// Counts read `±jitter` s around their stamp: each log warned of it (the jitter
/// is large enough to matter). Returns whether the two logs disagree beyond the 3σ
/// level of χ² (their σ include the jitter left after smoothing).
fn check_jittered_pair(seeds: (u64, u64), jitter: f64) -> bool {
    let (pa, truth) = jittered_log(seeds.0, 1.0, Some(jitter));
    let (pb, _) = jittered_log(seeds.1, 1.0, Some(jitter));
    let label = |s: u64| format!("seed {s}, counts read ±{:.0} ms", 1e3 * jitter);
    let opts = with_offset_estimate();
    let a = checked_log(&label(seeds.0), &pa, &truth, &opts, true);
    let b = checked_log(&label(seeds.1), &pb, &truth, &opts, true);
    cleanup(&pa);
    cleanup(&pb);
    match (&a, &b) {
        (Checked::Warned(a), Checked::Warned(b)) => {
            let (chi2, dof) = pair_chi2(a, b);
            println!("seeds {seeds:?}: χ² {chi2:.1} for {dof} parameters");
            dof == 0 || chi2 > CHI2_3SIGMA[dof - 1]
        }
        _ => panic!("seeds {seeds:?}, counts read ±{jitter} s: read-time jitter not found"),
    }
}

/// Checks both logs of a pair with the recommended command and their agreement, and
/// one of them without the offset estimate.
fn check_pair(seeds: (u64, u64), turn_radius: f64) {
    let (pa, truth) = fast_robot_log(seeds.0, turn_radius);
    let (pb, truth_b) = fast_robot_log(seeds.1, turn_radius);
    assert_eq!(truth, truth_b, "the same robot");
    let a = check_log(
        &format!("seed {}", seeds.0),
        &pa,
        &truth,
        &with_offset_estimate(),
    );
    let b = check_log(
        &format!("seed {}", seeds.1),
        &pb,
        &truth,
        &with_offset_estimate(),
    );
    if let (Some(a), Some(b)) = (a, b) {
        assert_agree(seeds, &a, &b);
    }
    // The offset given as known (`--time-offset 0`): refused with the offset named, or
    // numbers with the warning that names the flag.
    let label = format!("seed {} with the offset given as 0", seeds.0);
    let known = Options {
        estimate_found_time_offset: false,
        ..Options::default()
    };
    match calibrate(&pa, &known) {
        Err(e) => {
            let text = e.to_string();
            assert!(text.contains("--estimate-time-offset"), "{label}: {text}");
        }
        Ok(o) => assert!(
            o.health.iter().any(|f| f.kind == FindingKind::ClockOffset
                && f.message.contains("--estimate-time-offset")),
            "{label}: numbers without the clock-offset warning"
        ),
    }
    // Not given (the default): the offset the quick check finds is estimated, so the
    // default command meets the same bounds.
    let label = format!("seed {} without --estimate-time-offset", seeds.0);
    check_log(&label, &pa, &truth, &Options::default());
    cleanup(&pa);
    cleanup(&pb);
}

#[test]
fn fast_robot_without_spins_gives_results_that_agree() {
    check_pair((1301, 1302), 1.0);
    check_pair((1303, 1304), 1.0);
}

#[test]
fn gentle_driver_without_spins_is_refused_or_agrees() {
    // Turns no tighter than 5 m: without the offset estimate this reproduces the real
    // log's refusal ("the data do not determine l_y").
    check_pair((1305, 1306), 5.0);
}

/// `--accept-weak` decides whether numbers are returned, never which: the first
/// guesses and the clock-offset search solve without verdicts. (Before, their solves
/// refused weak data; with `--estimate-time-offset` these two gentle-driver logs were
/// then refused as "l_y weak" although with `--accept-weak` every parameter was judged
/// well determined and within 2.2σ of the truth.)
#[test]
fn accept_weak_changes_whether_not_which_numbers() {
    for seed in [6, 17] {
        let (path, _) = fast_robot_log(seed, 10.0);
        let strict = calibrate(&path, &with_offset_estimate());
        let lenient = Options {
            accept_weak: true,
            ..with_offset_estimate()
        };
        let lenient = calibrate(&path, &lenient).expect("numbers with accept_weak");
        match strict {
            Ok(o) => assert_eq!(
                o.calibration.params.to_vector(),
                lenient.calibration.params.to_vector(),
                "seed {seed}"
            ),
            Err(e) => assert!(
                lenient
                    .calibration
                    .observability
                    .parameters
                    .iter()
                    .any(|p| p.verdict != Verdict::WellDetermined),
                "seed {seed}: refused ({e}) although --accept-weak judges every parameter \
                 well determined"
            ),
        }
        cleanup(&path);
    }
}

#[test]
fn counts_read_with_jitter_are_warned_of() {
    check_jittered_pair((1601, 1602), 0.01);
    check_jittered_pair((1603, 1604), 0.03);
}

#[test]
#[ignore = "twelve seed pairs per jitter (about 30 s on 2 cores); run by .ci/run"]
fn counts_read_with_jitter_over_seed_pairs() {
    // Twelve pairs per jitter: at the 3σ level (0.27 %) one pair beyond is already
    // unlikely, two mean the σ miss something (before the σ included the jitter left
    // after smoothing: 2 of 24 pairs beyond at ±10 ms, 3 of 24 at ±30 ms).
    for (first, jitter) in [(1701, 0.01), (1801, 0.03)] {
        let beyond = (0..12u64)
            .filter(|k| check_jittered_pair((first + 2 * k, first + 1 + 2 * k), jitter))
            .count();
        assert!(
            beyond <= 1,
            "counts read ±{jitter} s: {beyond} of 12 pairs disagree beyond the 3σ level of χ²"
        );
    }
}

#[test]
#[ignore = "ten seed pairs per driver (about a minute on 2 cores); run by .ci/run"]
fn fast_robot_target_holds_over_seed_pairs() {
    for k in 0..10 {
        check_pair((1401 + 2 * k, 1402 + 2 * k), 1.0);
        check_pair((1501 + 2 * k, 1502 + 2 * k), 5.0);
    }
}
