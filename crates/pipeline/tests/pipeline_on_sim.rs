//! The pipeline on short simulated logs: the synchronized wheel rotations agree with
//! the simulator's true wheel angles to within the encoder quantization, the clock
//! offset is applied with the simulator's sign, and the results do not depend on the
//! number of threads.

use odocal_log::{read_log, Log, ReadOptions};
use odocal_pipeline::{calibrate_log, synchronize_and_match, NoProgress, Options, Timing};
use odocal_sim::{simulate, SimConfig, SimRun};
use std::f64::consts::TAU;

fn sim(seed: u64, duration: f64, clock_offset: f64) -> (SimRun, Log) {
    let mut config = SimConfig::preset("khepera").unwrap();
    config.seed = seed;
    config.duration = duration;
    config.faults.clock_offset = clock_offset;
    let run = simulate(&config).unwrap();
    let path =
        std::env::temp_dir().join(format!("odocal-pipeline-{}-{seed}.log", std::process::id()));
    let file = std::fs::File::create(&path).unwrap();
    run.write_log(std::io::BufWriter::new(file), &[]).unwrap();
    let log = read_log(&path, &ReadOptions::default()).unwrap();
    let _ = std::fs::remove_file(&path);
    (run, log)
}

fn in_pool<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(f)
}

/// Wheel rotations from interpolated ticks vs the simulator's exact wheel angles at the
/// scan instants: within about one tick (quantization of the two interpolated counts).
fn worst_rotation_error(run: &SimRun, log: &Log, opts: &Options) -> (f64, usize) {
    let mut timing = Timing::default();
    let synced = synchronize_and_match(log, opts, &NoProgress, &mut timing).unwrap();
    let scans: Vec<_> = run.logged_scans().collect();
    assert_eq!(scans.len(), log.scans.len());
    let tick = TAU / run.config.encoder.ticks_per_revolution;
    let mut worst: f64 = 0.0;
    for s in &synced.samples {
        let (a, b) = (scans[s.pair.first], scans[s.pair.second]);
        assert_eq!(a.t, s.pair.t0);
        let true_l = b.wheel_angles[0] - a.wheel_angles[0];
        let true_r = b.wheel_angles[1] - a.wheel_angles[1];
        worst = worst
            .max((s.wheel.dphi_l - true_l).abs())
            .max((s.wheel.dphi_r - true_r).abs());
        let sum: f64 = s.wheel.profile.iter().map(|p| p.dphi_l).sum();
        assert!((sum - s.wheel.dphi_l).abs() < 1e-9);
    }
    println!("worst wheel-rotation error: {:.3} ticks", worst / tick);
    (worst / tick, synced.samples.len())
}

#[test]
fn wheel_rotations_match_the_truth() {
    let (run, log) = sim(31, 60.0, 0.0);
    let (worst, n) = worst_rotation_error(&run, &log, &Options::default());
    assert!(worst <= 1.5, "worst error {worst} ticks");
    assert!(n > 130, "{n} samples");
}

#[test]
fn clock_offset_uses_the_simulator_sign() {
    let (run, log) = sim(32, 60.0, 0.05);
    // With the right offset the rotations agree with the truth …
    let opts = Options {
        time_offset: 0.05,
        ..Options::default()
    };
    let (worst, _) = worst_rotation_error(&run, &log, &opts);
    assert!(worst <= 1.5, "worst error {worst} ticks");
    // … with the opposite sign they do not.
    let wrong = Options {
        time_offset: -0.05,
        ..Options::default()
    };
    let (worst, _) = worst_rotation_error(&run, &log, &wrong);
    assert!(
        worst > 10.0,
        "a wrong offset went unnoticed ({worst} ticks)"
    );
}

#[test]
fn results_do_not_depend_on_the_thread_count() {
    // Long enough (625 pairs) for the bootstrap of the first guesses to run.
    let (_, log) = sim(33, 250.0, 0.0);
    let opts = Options::default();
    let one = in_pool(1, || calibrate_log(&log, &opts, &NoProgress).unwrap());
    // Chunks of the pairs, and the noise estimate's scans, spread over the threads.
    for threads in [2, 3] {
        let two = in_pool(threads, || calibrate_log(&log, &opts, &NoProgress).unwrap());
        assert_eq!(one.synced.samples, two.synced.samples);
        assert!(one.synced.match_self_check.is_some());
        assert_eq!(one.synced.match_self_check, two.synced.match_self_check);
        assert_eq!(one.synced.match_rejections, two.synced.match_rejections);
        assert_eq!(one.calibration.params, two.calibration.params);
        assert_eq!(one.calibration.covariance, two.calibration.covariance);
    }
}

#[test]
fn odometry_first_guesses_save_icp_iterations() {
    let (run, log) = sim(34, 60.0, 0.0);
    let truth = odocal_solver::Params {
        r_l: run.config.robot.r_l,
        r_r: run.config.robot.r_r,
        b: run.config.robot.b,
        laser: run.config.robot.laser,
    };
    let mean_iterations = |opts: &Options| {
        let mut timing = Timing::default();
        let s = synchronize_and_match(&log, opts, &NoProgress, &mut timing).unwrap();
        let total: u32 = s.samples.iter().map(|p| p.icp.iterations).sum();
        total as f64 / s.samples.len() as f64
    };
    let identity = mean_iterations(&Options {
        bootstrap_guesses: false,
        ..Options::default()
    });
    let guided = mean_iterations(&Options {
        initial_params: Some(truth),
        ..Options::default()
    });
    println!("mean ICP iterations: identity guess {identity:.2}, odometry guess {guided:.2}");
    assert!(guided < identity);
}

/// The bootstrap's runs guess each pair by the motion its predecessor measured: fewer
/// iterations than from the identity, no pair lost that the identity matched, and the
/// same displacements within their covariance.
#[test]
fn bootstrap_runs_need_fewer_iterations_and_lose_no_pair() {
    use odocal_pipeline::bootstrap_runs::{match_runs, BootstrapPair};
    use odocal_pipeline::matching::{match_pairs, typical_noise_sigma, with_typical_noise};
    let (_, log) = sim(36, 60.0, 0.0);
    let opts = Options::default();
    let mut timing = Timing::default();
    let synced = synchronize_and_match(&log, &opts, &NoProgress, &mut timing).unwrap();
    let pairs = BootstrapPair::of_samples(&synced.samples);
    let matcher = opts.icp_for(&log);
    let icp = with_typical_noise(&matcher, typical_noise_sigma(&log.scans, &matcher));
    let ends: Vec<(usize, usize)> = pairs.iter().map(|p| (p.first, p.second)).collect();
    let identity = vec![odocal_geom::Pose2::IDENTITY; ends.len()];
    let from_identity = match_pairs(&log.scans, &ends, &identity, &icp, || ());
    let chained = match_runs(&log.scans, &pairs, &icp, || ());
    let (mut it_identity, mut it_chained, mut both) = (0, 0, 0);
    for (a, b) in from_identity.iter().zip(&chained) {
        let Ok(a) = a else { continue };
        let b = b.as_ref().expect("a pair the identity matched is matched");
        both += 1;
        it_identity += a.iterations;
        it_chained += b.iterations;
        let d = [
            b.pose.x - a.pose.x,
            b.pose.y - a.pose.y,
            b.pose.theta - a.pose.theta,
        ];
        for (k, dk) in d.iter().enumerate() {
            let sigma = a.covariance[k][k].sqrt();
            assert!(dk.abs() < 3.0 * sigma, "pair apart by {dk:e} (σ {sigma:e})");
        }
    }
    println!(
        "{both} pairs: {:.2} iterations from the identity, {:.2} chained",
        it_identity as f64 / both as f64,
        it_chained as f64 / both as f64
    );
    assert!(both > 100);
    // 2.34 against 2.99 on this log (a 10-minute Khepera log: 2.6 against 4.1).
    assert!(
        (it_chained as f64) < 0.85 * it_identity as f64,
        "{it_chained} vs {it_identity}"
    );
}

/// With the true sensor displacements in place of ICP's, what remains is the
/// synchronization (interpolated ticks, profiles) and the kinematics: the parameters
/// come back to within the encoder quantization's effect.
#[test]
fn true_displacements_give_back_the_parameters() {
    let (run, log) = sim(35, 180.0, 0.0);
    let mut timing = Timing::default();
    let synced =
        synchronize_and_match(&log, &Options::default(), &NoProgress, &mut timing).unwrap();
    let scans: Vec<_> = run.logged_scans().collect();
    let samples: Vec<odocal_solver::Sample> = synced
        .samples
        .iter()
        .map(|s| {
            let mut sample = s.to_solver(true, false);
            sample.sm = scans[s.pair.first]
                .sensor
                .between(&scans[s.pair.second].sensor);
            sample
        })
        .collect();
    let opts = odocal_solver::SolveOptions {
        trim: odocal_solver::Trim::None,
        ..odocal_solver::SolveOptions::default()
    };
    let c = odocal_solver::calibrate(&samples, &opts).unwrap();
    let r = &run.config.robot;
    let e = c.params.difference(&odocal_solver::Params {
        r_l: r.r_l,
        r_r: r.r_r,
        b: r.b,
        laser: r.laser,
    });
    println!("errors with true ŝ ({} samples): {e:?}", samples.len());
    for (i, rel) in [(0, r.r_l), (1, r.r_r), (2, r.b)] {
        assert!(e[i].abs() < 1e-4 * rel, "parameter {i}: {}", e[i]);
    }
    assert!(
        e[3].abs() < 2e-5 && e[4].abs() < 2e-5,
        "ℓ error {:?}",
        &e[3..5]
    );
    assert!(e[5].abs() < 1e-4, "ℓθ error {}", e[5]);
}

/// Issue 13's short office log: 589 scans (under the 600 that enable the evenly spread
/// bootstrap), pairs 4 scans apart. With identity first guesses the matcher of main
/// at b5f363d accepted three 19–21° spins as turns of 1–2.5° (mean residual ≈ 0.1 m
/// against the scans' 1.8 mm noise) and failed two more. Now every sample is the truth
/// (within 5 mm and 0.25°), every spin in place is among them, and the only pairs
/// lost are the ones ICP flags ill-conditioned (office corridors).
#[test]
fn short_office_log_matches_every_spin() {
    let mut config = SimConfig::preset("office").unwrap();
    config.seed = 27;
    config.duration = 58.9;
    let run = simulate(&config).unwrap();
    let path = std::env::temp_dir().join(format!("odocal-office-{}.log", std::process::id()));
    let file = std::fs::File::create(&path).unwrap();
    run.write_log(std::io::BufWriter::new(file), &[]).unwrap();
    let log = read_log(&path, &ReadOptions::default()).unwrap();
    let _ = std::fs::remove_file(&path);
    assert_eq!(log.scans.len(), 589);
    let opts = Options {
        stride: Some(4),
        ..Options::default()
    };
    let mut timing = Timing::default();
    let synced = synchronize_and_match(&log, &opts, &NoProgress, &mut timing).unwrap();
    let scans: Vec<_> = run.logged_scans().collect();
    let truth_of = |first: usize, second: usize| scans[first].sensor.between(&scans[second].sensor);
    for s in &synced.samples {
        let truth = truth_of(s.pair.first, s.pair.second);
        let e = s.icp.pose.between(&truth);
        assert!(
            e.translation_norm() < 5e-3 && e.theta.abs() < 0.25f64.to_radians(),
            "pair {}–{}: ŝ {} against the truth {truth}",
            s.pair.first,
            s.pair.second,
            s.icp.pose
        );
    }
    let matched: std::collections::HashSet<usize> =
        synced.samples.iter().map(|s| s.pair.first).collect();
    let spins: Vec<usize> = (0..scans.len() - 4)
        .step_by(4)
        .filter(|&k| truth_of(k, k + 4).theta.abs() > 15f64.to_radians())
        .collect();
    assert!(spins.len() >= 10, "{} spins", spins.len());
    let lost: Vec<usize> = spins.into_iter().filter(|k| !matched.contains(k)).collect();
    assert!(
        lost.is_empty(),
        "spins not matched: pairs from scans {lost:?}"
    );
    println!(
        "{} samples of {} pairs; discarded {:?}",
        synced.samples.len(),
        synced.pairs,
        synced.discarded
    );
}
