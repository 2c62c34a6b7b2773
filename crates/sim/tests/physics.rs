//! Physical properties of whole simulations: scans land on the walls, encoders count
//! the true wheel rotation, the robot stays off the walls, degenerate trajectories are
//! degenerate and the mixed one is mixed.

use odocal_geom::{wrap_angle, Pose2};
use odocal_sim::{simulate, LaserConfig, SimConfig, SimRun, TrajectoryKind};

fn run(preset: &str, seed: u64, duration: f64, edit: impl FnOnce(&mut SimConfig)) -> SimRun {
    let mut c = SimConfig::preset(preset).unwrap();
    c.seed = seed;
    c.duration = duration;
    edit(&mut c);
    simulate(&c).unwrap()
}

/// Largest distance from a scan's valid end points (projected from the true sensor
/// pose) to the nearest wall, over all scans; and the number of valid readings.
fn worst_reprojection(run: &SimRun) -> (f64, usize) {
    let angles = run.config.laser.angles();
    let mut worst: f64 = 0.0;
    let mut valid = 0;
    for s in &run.scans {
        for (r, a) in s.ranges.iter().zip(&angles) {
            if *r == 0.0 {
                continue;
            }
            let p = s
                .sensor
                .transform_point([*r as f64 * a.cos(), *r as f64 * a.sin()]);
            worst = worst.max(run.world.clearance(p));
            valid += 1;
        }
    }
    (worst, valid)
}

#[test]
fn noise_free_scans_land_exactly_on_the_walls() {
    for preset in ["khepera", "khepera-displaced", "office"] {
        let r = run(preset, 11, 15.0, |c| c.laser = LaserConfig::noise_free());
        let (worst, valid) = worst_reprojection(&r);
        // Only f32 rounding of ranges below 4 m remains.
        assert!(worst < 2e-6, "{preset}: {worst}");
        assert!(valid > 100 * r.scans.len(), "{preset}: {valid}");
    }
}

#[test]
fn noisy_scans_land_on_the_walls_within_the_noise() {
    let r = run("khepera", 12, 20.0, |_| {});
    let (worst, _) = worst_reprojection(&r);
    // 3 mm Gaussian + 0.5 mm quantization: nothing beyond ~6 σ among ~10^5 readings.
    assert!(worst < 0.02, "{worst}");
    // The spread of the along-ray error is the configured σ (plus quantization).
    let angles = r.config.laser.angles();
    let world = &r.world;
    let (mut n, mut s2) = (0.0, 0.0);
    for s in &r.scans {
        let truth = r.config.laser.true_ranges(world, &s.sensor);
        for ((m, t), _) in s.ranges.iter().zip(&truth).zip(&angles) {
            if *m != 0.0 {
                let e = *m as f64 - t;
                s2 += e * e;
                n += 1.0;
            }
        }
    }
    let sigma = (s2 / n).sqrt();
    let expected = (0.003f64.powi(2) + 0.001f64.powi(2) / 12.0).sqrt();
    assert!(
        (sigma - expected).abs() < 0.1 * expected,
        "σ {sigma} vs {expected}"
    );
}

#[test]
fn encoders_count_the_true_wheel_rotation_to_one_tick() {
    let r = run("khepera", 13, 60.0, |_| {});
    let k = r.config.encoder.ticks_per_revolution / std::f64::consts::TAU;
    for e in &r.encoders {
        for i in 0..2 {
            let exact = e.wheel_angles[i] * k;
            let d = exact - e.ticks[i] as f64;
            assert!((0.0..1.0).contains(&d), "ticks {} for {exact}", e.ticks[i]);
        }
    }
    for w in r.encoders.windows(2) {
        for i in 0..2 {
            let inc = (w[1].ticks[i] - w[0].ticks[i]) as f64;
            let exact = (w[1].wheel_angles[i] - w[0].wheel_angles[i]) * k;
            assert!((inc - exact).abs() < 1.0, "{inc} vs {exact}");
        }
    }
    // About 50 Hz.
    assert!(
        (2990..=3010).contains(&r.encoders.len()),
        "{}",
        r.encoders.len()
    );
    assert!((599..=601).contains(&r.scans.len()), "{}", r.scans.len());
}

/// The smallest distance (m) from the robot to a wall at the encoder records.
fn closest_wall(r: &SimRun) -> f64 {
    r.encoders
        .iter()
        .map(|e| r.world.clearance([e.robot.x, e.robot.y]))
        .fold(f64::INFINITY, f64::min)
}

#[test]
fn mixed_trajectories_keep_off_the_walls_in_every_world() {
    for preset in ["khepera", "office", "corridor"] {
        let r = run(preset, 14, 300.0, |c| c.laser.num_rays = 3);
        let worst = closest_wall(&r);
        assert!(worst > 0.19, "{preset}: came within {worst} m of a wall");
        let travelled: f64 = r
            .encoders
            .windows(2)
            .map(|w| w[0].robot.between(&w[1].robot).translation_norm())
            .sum();
        assert!(travelled > 5.0, "{preset}: only {travelled} m in 300 s");
    }
}

/// Body velocities over each scan interval, from the true poses.
fn interval_motions(r: &SimRun) -> Vec<Pose2> {
    r.scans
        .windows(2)
        .map(|w| w[0].robot.between(&w[1].robot))
        .collect()
}

#[test]
fn mixed_trajectory_has_spins_straight_runs_and_arcs() {
    let r = run("khepera", 15, 300.0, |c| c.laser.num_rays = 3);
    let (mut spins, mut straights, mut arcs, mut moving) = (0, 0, 0, 0);
    for d in interval_motions(&r) {
        let dist = d.translation_norm();
        let turn = d.theta.abs();
        if dist < 1e-4 && turn < 1e-4 {
            continue;
        }
        moving += 1;
        if dist < 1e-3 && turn > 0.02 {
            spins += 1;
        } else if dist > 3e-3 && turn < 1e-3 {
            straights += 1;
        } else if dist > 3e-3 && turn > 0.01 {
            arcs += 1;
        }
    }
    for (what, n) in [
        ("spins", spins),
        ("straight runs", straights),
        ("arcs", arcs),
    ] {
        assert!(n * 20 > moving, "{what}: {n} of {moving} moving intervals");
    }
}

#[test]
fn straight_only_is_straight() {
    let r = run("straight-only", 16, 120.0, |c| c.laser.num_rays = 3);
    let start = r.start_pose;
    let mut longest: f64 = 0.0;
    for e in &r.encoders {
        assert!(wrap_angle(e.robot.theta - start.theta).abs() < 1e-9);
        let local = start.between(&e.robot);
        assert!(local.y.abs() < 1e-9, "off the line by {}", local.y);
        longest = longest.max(local.x.abs());
    }
    assert!(longest > 0.3, "{longest}");
    // Both directions.
    let d = interval_motions(&r);
    assert!(d.iter().any(|m| m.x > 1e-3) && d.iter().any(|m| m.x < -1e-3));
}

#[test]
fn spin_only_does_not_translate() {
    let r = run("spin-only", 17, 120.0, |c| c.laser.num_rays = 3);
    let mut turned: f64 = 0.0;
    for w in r.encoders.windows(2) {
        assert!(w[1].robot.between(&r.start_pose).translation_norm() < 1e-9);
        turned += w[0].robot.between(&w[1].robot).theta.abs();
    }
    assert!(turned > 20.0, "{turned}");
    assert_eq!(r.config.trajectory, TrajectoryKind::SpinOnly);
}

#[test]
fn identical_turns_keep_one_curvature() {
    let r = run("identical-turns", 18, 120.0, |c| c.laser.num_rays = 3);
    // Every interval's wheel increments have the same ratio, and every pose is on
    // one circle of the configured radius.
    let radius = r.config.motion.turn_radius;
    let p0 = r.start_pose;
    let mut ratios = Vec::new();
    for w in r.encoders.windows(2) {
        let dl = w[1].wheel_angles[0] - w[0].wheel_angles[0];
        let dr = w[1].wheel_angles[1] - w[0].wheel_angles[1];
        if dl.abs() > 1e-3 {
            ratios.push(dr / dl);
        }
        let local = p0.between(&w[1].robot);
        // Circle through the start, tangent to its heading, centre at (0, ±R).
        let sign = if r.encoders.iter().any(|e| p0.between(&e.robot).y > 1e-3) {
            1.0
        } else {
            -1.0
        };
        let dist = local.x.hypot(local.y - sign * radius);
        assert!((dist - radius).abs() < 1e-9, "{dist}");
    }
    assert!(ratios.len() > 100);
    let (min, max) = ratios
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
            (a.min(x), b.max(x))
        });
    assert!(max - min < 1e-9, "ratios from {min} to {max}");
    assert!((min - 1.0).abs() > 0.1, "not turning: ratio {min}");
}

#[test]
fn swept_rays_are_taken_from_the_pose_at_their_own_time() {
    for preset in ["turtlebot", "pioneer"] {
        let r = run(preset, 15, 20.0, |c| {
            c.laser = LaserConfig {
                range_sigma: 0.0,
                quantization: 0.0,
                dropout_probability: 0.0,
                ..c.laser.clone()
            }
        });
        let laser = &r.config.laser;
        assert!(laser.time_increment > 0.0, "{preset}: sweeps by default");
        let angles = laser.angles();
        let n = angles.len();
        let (mut worst_ends, mut worst_inside, mut worst_unswept) = (0.0f64, 0.0f64, 0.0f64);
        for s in &r.scans {
            let (a, b) = (s.sensor, s.sensor_at_last_ray);
            let turn = wrap_angle(b.theta - a.theta);
            for (i, (r_i, angle)) in s.ranges.iter().zip(&angles).enumerate() {
                if *r_i == 0.0 {
                    continue;
                }
                let local = [*r_i as f64 * angle.cos(), *r_i as f64 * angle.sin()];
                // The pose at the ray's time, interpolated between the first and the
                // last ray (exact at both ends).
                let u = i as f64 / (n - 1) as f64;
                let pose = Pose2::new(
                    a.x + u * (b.x - a.x),
                    a.y + u * (b.y - a.y),
                    a.theta + u * turn,
                );
                let off = r.world.clearance(pose.transform_point(local));
                if i == 0 || i == n - 1 {
                    worst_ends = worst_ends.max(off);
                } else {
                    worst_inside = worst_inside.max(off);
                }
                worst_unswept = worst_unswept.max(r.world.clearance(a.transform_point(local)));
            }
        }
        assert!(
            worst_ends < 2e-6,
            "{preset}: first/last rays off by {worst_ends}"
        );
        assert!(worst_inside < 0.01, "{preset}: rays off by {worst_inside}");
        assert!(
            worst_unswept > 0.02,
            "{preset}: all rays from the first pose fit within {worst_unswept}"
        );
    }
}

#[test]
fn fast_robots_stay_off_the_walls_and_drive_fast() {
    for (preset, fastest) in [("turtlebot", 0.16), ("pioneer", 0.4)] {
        let r = run(preset, 16, 300.0, |c| c.laser.num_rays = 3);
        let worst = closest_wall(&r);
        assert!(worst > 0.19, "{preset}: came within {worst} m of a wall");
        let top = r
            .encoders
            .windows(2)
            .map(|w| w[0].robot.between(&w[1].robot).translation_norm() / (w[1].t - w[0].t))
            .fold(0.0, f64::max);
        assert!(top > fastest, "{preset}: top speed {top} m/s");
    }
}

#[test]
fn no_spins_drives_straights_and_arcs_but_never_spins() {
    for seed in [19, 20] {
        let r = run("pioneer", seed, 120.0, |c| {
            c.laser.num_rays = 3;
            c.trajectory = TrajectoryKind::NoSpins;
            c.motion.max_speed = 0.6;
        });
        let radius = r.config.motion.turn_radius;
        let (mut straights, mut arcs, mut tight, mut moving) = (0, 0, 0, 0);
        let mut travelled = 0.0;
        for d in interval_motions(&r) {
            let dist = d.translation_norm();
            let turn = d.theta.abs();
            travelled += dist;
            if dist < 1e-4 && turn < 1e-4 {
                continue;
            }
            moving += 1;
            // Never a spin in place (as defined for the mixed trajectory) ...
            assert!(
                !(dist < 1e-3 && turn > 0.02),
                "seed {seed}: turned {turn} rad over {dist} m"
            );
            // ... and rarely a circle tighter than the smallest radius (only when the
            // motors' lag blends a forward and a backward run).
            if turn > 1e-4 && dist / turn < 0.95 * radius {
                tight += 1;
            }
            if turn < 1e-3 {
                straights += 1;
            } else if turn > 0.01 {
                arcs += 1;
            }
        }
        assert!(
            straights * 10 > moving,
            "seed {seed}: {straights} straight of {moving}"
        );
        assert!(arcs * 5 > moving, "seed {seed}: {arcs} arcs of {moving}");
        assert!(
            tight * 50 < moving,
            "seed {seed}: {tight} tight turns of {moving}"
        );
        assert!(travelled > 30.0, "seed {seed}: only {travelled} m in 120 s");
        let worst = closest_wall(&r);
        assert!(worst > 0.19, "seed {seed}: came within {worst} m of a wall");
    }
}

#[test]
fn encoders_stored_with_each_scan_carry_its_timestamp() {
    let r = run("pioneer", 21, 20.0, |c| {
        c.laser.num_rays = 3;
        c.encoder.with_scans = true;
        c.faults.clock_offset = 0.15;
    });
    let stamps: Vec<f64> = r.logged_scans().map(|s| s.t).collect();
    let records: Vec<_> = r.logged_encoders().collect();
    // The first 0.15 s of scans have no counts (read before the start).
    assert!(records.len() + 3 >= stamps.len() && records.len() < stamps.len());
    for e in &records {
        assert!(stamps.iter().any(|t| (t - e.t).abs() < 1e-9), "{}", e.t);
    }
    // One record per scan period (0.1 s at up to 0.5 m/s), in order.
    for w in records.windows(2) {
        assert!(
            (w[1].t - w[0].t - 0.1).abs() < 0.01,
            "{} {}",
            w[0].t,
            w[1].t
        );
        let moved = w[0].robot.between(&w[1].robot).translation_norm();
        assert!(moved < 0.06, "{moved}");
    }
}
