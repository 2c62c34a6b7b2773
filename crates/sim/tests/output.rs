//! The written log and truth: determinism, the format's fields, and every fault doing
//! what it says.

use odocal_sim::{arc_motion, simulate, GroundTruth, LogSummary, SimConfig, SimRun, TRUTH_FORMAT};

fn config(preset: &str, seed: u64, duration: f64) -> SimConfig {
    let mut c = SimConfig::preset(preset).unwrap();
    c.seed = seed;
    c.duration = duration;
    c
}

fn write(run: &SimRun) -> (String, LogSummary, Vec<u8>) {
    let mut log = Vec::new();
    let summary = run.write_log(&mut log, &["test".to_string()]).unwrap();
    let mut truth = Vec::new();
    run.write_truth(&summary, &mut truth).unwrap();
    (String::from_utf8(log).unwrap(), summary, truth)
}

fn lines_starting<'a>(log: &'a str, name: &str) -> Vec<&'a str> {
    log.lines()
        .filter(|l| l.split_whitespace().next() == Some(name))
        .collect()
}

#[test]
fn same_seed_gives_the_same_bytes() {
    let mut c = config("khepera", 21, 8.0);
    c.faults.drop_fraction = 0.05;
    c.faults.garbage_fraction = 0.02;
    c.faults.slip_per_minute = 10.0;
    let a = write(&simulate(&c).unwrap());
    let b = write(&simulate(&c).unwrap());
    assert_eq!(a.0, b.0);
    assert_eq!(a.2, b.2);
    c.seed = 22;
    let d = write(&simulate(&c).unwrap());
    assert_ne!(a.0, d.0);
}

#[test]
fn log_has_the_params_and_messages_of_the_format() {
    let run = simulate(&config("khepera", 23, 5.0)).unwrap();
    let (log, summary, truth) = write(&run);
    assert!(log.lines().next().unwrap().starts_with('#'));
    assert!(log.contains("\nPARAM robot_wheel_ticks_per_revolution 2764.8 khepera 0\n"));
    assert!(!log.contains("robot_encoder_modulus"));
    let encoders = lines_starting(&log, "ENCODER");
    let scans = lines_starting(&log, "RAWLASER1");
    let odom = lines_starting(&log, "ODOM");
    assert_eq!(encoders.len(), summary.encoder_records);
    assert_eq!(scans.len(), summary.scans);
    assert_eq!(odom.len(), encoders.len());
    assert_eq!(summary.lines as usize, log.lines().count());
    for l in &encoders {
        assert_eq!(l.split_whitespace().count(), 6, "{l}");
    }
    for l in &scans {
        let t: Vec<&str> = l.split_whitespace().collect();
        assert_eq!(t[1], "2");
        assert_eq!(t[8], "681");
        assert_eq!(t.len(), 1 + 8 + 681 + 1 + 3, "{}", t.len());
        // Timestamps to the microsecond.
        let ts = t[t.len() - 3];
        assert!(ts.split('.').nth(1).is_none_or(|f| f.len() <= 6), "{ts}");
    }
    // Records in timestamp order.
    let times: Vec<f64> = log
        .lines()
        .filter(|l| !l.starts_with('#') && !l.starts_with("PARAM"))
        .map(|l| l.split_whitespace().rev().nth(2).unwrap().parse().unwrap())
        .collect();
    assert!(times.windows(2).all(|w| w[0] <= w[1]));
    let truth: GroundTruth = serde_json::from_slice(&truth).unwrap();
    assert_eq!(truth.format, TRUTH_FORMAT);
    assert_eq!(truth.scans.len(), scans.len());
    assert_eq!(truth.params.b, 0.0890);
    // The truth's scan times are the logged ones, and the sensor pose is robot ⊕ laser.
    for (ts, line) in truth.scans.iter().zip(&scans) {
        let logged: f64 = line
            .split_whitespace()
            .rev()
            .nth(2)
            .unwrap()
            .parse()
            .unwrap();
        assert_eq!(ts.t, logged);
        let robot = odocal_geom::Pose2::from_array(ts.robot);
        let sensor = robot.compose(&run.config.robot.laser);
        assert!((sensor.x - ts.sensor[0]).abs() < 1e-15 && (sensor.y - ts.sensor[1]).abs() < 1e-15);
    }
}

#[test]
fn clock_offset_shifts_the_laser_timestamps() {
    let mut c = config("khepera", 24, 5.0);
    let base = simulate(&c).unwrap();
    c.faults.clock_offset = 0.0371;
    let shifted = simulate(&c).unwrap();
    assert_eq!(base.scans.len(), shifted.scans.len());
    for (a, b) in base.scans.iter().zip(&shifted.scans) {
        assert!((b.t - b.t_true - 0.0371).abs() < 1e-6);
        assert_eq!(a.t_true, b.t_true);
        assert_eq!(a.robot, b.robot);
    }
    let (_, summary, truth) = write(&shifted);
    let truth: GroundTruth = serde_json::from_slice(&truth).unwrap();
    assert_eq!(truth.faults.clock_offset, 0.0371);
    assert_eq!(truth.scans.len(), summary.scans);
    assert!(truth
        .scans
        .iter()
        .all(|s| (s.t - s.t_encoder - 0.0371).abs() < 1e-6));
    // The encoder stream is untouched.
    assert_eq!(base.encoders, shifted.encoders);
}

#[test]
fn slip_moves_the_robot_less_than_the_wheels_say() {
    let mut c = config("khepera", 25, 120.0);
    c.laser.num_rays = 3;
    c.faults.slip_per_minute = 6.0;
    let run = simulate(&c).unwrap();
    assert_eq!(run.slips.len(), 12);
    // Over consecutive encoder readings inside an episode, the true motion is the
    // wheels' motion with the radii scaled by the slip factors; outside, unscaled.
    // (Constant-speed arcs over 20 ms: the motor lag makes this approximate.)
    let p = c.robot;
    let predict = |w: &[odocal_sim::SimEncoderRecord], f: [f64; 2]| {
        let dt = w[1].t - w[0].t;
        let dl = (w[1].wheel_angles[0] - w[0].wheel_angles[0]) * f[0];
        let dr = (w[1].wheel_angles[1] - w[0].wheel_angles[1]) * f[1];
        let (v, om) = p.body_velocity([dl / dt, dr / dt]);
        arc_motion(v, om, dt)
    };
    let t0 = c.start_time;
    let (mut checked, mut distinguishable) = (0, 0);
    for w in run.encoders.windows(2) {
        let actual = w[0].robot.between(&w[1].robot);
        let inside = run
            .slips
            .iter()
            .find(|e| t0 + e.start <= w[0].t && w[1].t <= t0 + e.end);
        let straddles = run.slips.iter().any(|e| {
            let (s, f) = (t0 + e.start, t0 + e.end);
            (w[0].t < s && s < w[1].t) || (w[0].t < f && f < w[1].t)
        });
        if straddles {
            continue;
        }
        let factors = inside.map(|e| e.factors).unwrap_or([1.0; 2]);
        let err = predict(w, factors).between(&actual);
        assert!(
            err.translation_norm() < 2e-5 && err.theta.abs() < 1e-3,
            "{err}"
        );
        if let Some(e) = inside {
            checked += 1;
            let plain = predict(w, [1.0; 2]).between(&actual).translation_norm();
            if plain > 1e-4 {
                distinguishable += 1;
            }
            assert!(e.end - e.start >= 0.5 - 1e-9 && e.end - e.start <= 1.0 + 1e-9);
        }
    }
    assert!(checked > 100, "{checked}");
    assert!(
        distinguishable * 3 > checked,
        "{distinguishable} of {checked}"
    );
    let (_, summary, truth) = write(&run);
    let truth: GroundTruth = serde_json::from_slice(&truth).unwrap();
    assert_eq!(truth.faults.slip_intervals.len(), 12);
    assert!(summary.garbage_lines.is_empty());
}

#[test]
fn dropped_messages_are_missing_and_listed() {
    let mut c = config("khepera", 26, 60.0);
    c.faults.drop_fraction = 0.1;
    let run = simulate(&c).unwrap();
    let (log, summary, truth) = write(&run);
    let truth: GroundTruth = serde_json::from_slice(&truth).unwrap();
    let total_enc = run.encoders.len();
    let total_scans = run.scans.len();
    let dropped_enc = truth.faults.dropped_encoder_times.len();
    let dropped_scans = truth.faults.dropped_scan_times.len();
    assert_eq!(summary.encoder_records + dropped_enc, total_enc);
    assert_eq!(summary.scans + dropped_scans, total_scans);
    assert_eq!(lines_starting(&log, "RAWLASER1").len(), summary.scans);
    // 10 % ± 4 binomial standard deviations.
    let frac = (dropped_enc + dropped_scans) as f64 / (total_enc + total_scans) as f64;
    assert!((frac - 0.1).abs() < 0.025, "{frac}");
    for t in &truth.faults.dropped_scan_times {
        assert!(!truth.scans.iter().any(|s| s.t == *t));
    }
}

#[test]
fn garbage_lines_are_malformed_and_listed() {
    let mut c = config("khepera", 27, 30.0);
    c.faults.garbage_fraction = 0.05;
    let run = simulate(&c).unwrap();
    let (log, summary, _) = write(&run);
    let lines: Vec<&str> = log.lines().collect();
    let n = summary.garbage_lines.len();
    let messages = summary.encoder_records + summary.scans;
    assert!(n > messages / 40 && n < messages / 10, "{n} of {messages}");
    assert_eq!(lines.len(), summary.lines as usize);
    for &i in &summary.garbage_lines {
        let l = lines[i as usize - 1];
        let t: Vec<&str> = l.split_whitespace().collect();
        let malformed = match t[0] {
            "ENCODER" => t.len() != 6 || t[1..3].iter().any(|x| x.parse::<i64>().is_err()),
            "RAWLASER1" => {
                let n: usize = t[8].parse().unwrap();
                t.len() != 1 + 8 + n + 1 + 3
                    || t[9..9 + n].iter().any(|x| x.parse::<f32>().is_err())
            }
            _ => false,
        };
        assert!(malformed, "line {i} is not malformed: {l}");
    }
    // Every other message line is well formed.
    let good_enc = lines
        .iter()
        .filter(|l| l.starts_with("ENCODER") && l.split_whitespace().count() == 6)
        .filter(|l| {
            l.split_whitespace()
                .skip(1)
                .take(2)
                .all(|x| x.parse::<i64>().is_ok())
        })
        .count();
    assert_eq!(good_enc, summary.encoder_records);
}

#[test]
fn wrapped_counters_unwrap_to_the_true_counts() {
    let mut c = config("khepera", 28, 30.0);
    c.encoder.modulus = Some(4096);
    c.encoder.initial_ticks = [4000, 10];
    let run = simulate(&c).unwrap();
    let (log, _, _) = write(&run);
    assert!(log.contains("\nPARAM robot_encoder_modulus 4096 khepera 0\n"));
    let mut prev: Option<[i64; 2]> = None;
    let mut unwrapped = [0i64; 2];
    let mut wraps = 0;
    for (line, truth) in lines_starting(&log, "ENCODER").iter().zip(&run.encoders) {
        let t: Vec<i64> = line
            .split_whitespace()
            .skip(1)
            .take(2)
            .map(|x| x.parse().unwrap())
            .collect();
        assert!(t.iter().all(|v| (0..4096).contains(v)));
        match prev {
            None => unwrapped = [t[0], t[1]],
            Some(p) => {
                for i in 0..2 {
                    let mut d = t[i] - p[i];
                    if d > 2048 {
                        d -= 4096;
                        wraps += 1;
                    } else if d < -2048 {
                        d += 4096;
                        wraps += 1;
                    }
                    unwrapped[i] += d;
                }
            }
        }
        prev = Some([t[0], t[1]]);
        assert_eq!(
            unwrapped[0] - run.encoders[0].ticks[0],
            truth.ticks[0] - run.encoders[0].ticks[0]
        );
        assert_eq!(
            unwrapped[1] - run.encoders[0].ticks[1],
            truth.ticks[1] - run.encoders[0].ticks[1]
        );
    }
    assert!(wraps > 0);
}

#[test]
fn firmware_odometry_follows_the_encoders_with_nominal_parameters() {
    let mut c = config("khepera", 29, 20.0);
    c.laser.num_rays = 3;
    // With nominal = true parameters and an error-free world, ODOM tracks the true
    // motion up to tick quantization and the 6-decimal rounding.
    c.nominal = c.robot;
    let run = simulate(&c).unwrap();
    let p0 = run.encoders[0].robot;
    let last = run.encoders.last().unwrap();
    let truth = p0.between(&last.robot);
    let odom = run.odom.last().unwrap().pose;
    let err = truth.between(&odom);
    assert!(
        err.translation_norm() < 0.02 && err.theta.abs() < 0.05,
        "{err}"
    );
}
