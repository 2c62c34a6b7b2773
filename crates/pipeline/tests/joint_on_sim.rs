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
    for i in 0..6 {
        let z = (e.params[i] - truth[i]) / e.sigma[i];
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
}
