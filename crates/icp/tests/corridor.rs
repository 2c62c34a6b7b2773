//! A corridor longer than the sensor range: motion along it is not observable, and
//! the result must say so instead of claiming a precise answer.

use odocal_geom::Pose2;
use odocal_icp::{IcpParams, Matcher, PreparedScan};
use odocal_sim::{LaserConfig, World};
use rand::{rngs::StdRng, SeedableRng};

/// `min_ratio`: least σ along / σ across the corridor. Without noise the motion along
/// is exactly unobservable (ratio ~1e6); with noise, the tilt of the noisy local
/// normals makes up some apparent information along the walls, so the flag and the
/// weakest direction are what tells the caller not to trust that component.
fn check(laser: LaserConfig, min_ratio: f64) {
    let world = World::corridor();
    let params = IcpParams::default();
    let angles = laser.angles();
    let mut rng = StdRng::seed_from_u64(5);
    let mut matcher = Matcher::new(params.clone());
    for heading in [0.0f64, 0.4, -0.3, 3.0] {
        let from = Pose2::new(20.0, 1.0, heading);
        let step = Pose2::new(0.05, 0.01, 0.02);
        let to = from.compose(&step);
        let prepare =
            |r: Vec<f32>| PreparedScan::new(&r, &angles, 0.02, 4.0, &params).expect("scan");
        let reference = prepare(laser.scan(&world, &from, &mut rng));
        let current = prepare(laser.scan(&world, &to, &mut rng));
        // Odometry says 3 cm along the corridor: that is all the matcher can keep.
        let guess = Pose2::new(0.03, 0.012, 0.025);
        let r = matcher
            .match_scans(&reference, &current, guess)
            .expect("match");
        // Direction along the corridor, in the reference sensor frame.
        let along = [(-heading).cos(), (-heading).sin()];
        let across = [-along[1], along[0]];
        let c = &r.covariance;
        let var = |u: [f64; 2]| {
            u[0] * u[0] * c[0][0] + 2.0 * u[0] * u[1] * c[0][1] + u[1] * u[1] * c[1][1]
        };
        let (sd_along, sd_across) = (var(along).sqrt(), var(across).sqrt());
        let w = r.weakest_direction;
        let weakest_along = (w[0] * along[0] + w[1] * along[1]).abs();
        println!(
            "heading {heading:+.1}: cond {:.3e}, ill {}, σ along {:.3e} m, across {:.3e} m, \
             weakest·along {weakest_along:.3}, pose {}",
            r.condition_number, r.ill_conditioned, sd_along, sd_across, r.pose
        );
        assert!(r.ill_conditioned, "corridor must be flagged");
        assert!(
            weakest_along > 0.99,
            "weakest direction must be along the corridor"
        );
        assert!(
            sd_along >= min_ratio * sd_across,
            "covariance must be far larger along the corridor: {sd_along:.2e} vs {sd_across:.2e}"
        );
        // Across the corridor and in rotation the answer is still good.
        let err_across = (r.pose.x - step.x) * across[0] + (r.pose.y - step.y) * across[1];
        assert!(err_across.abs() < 2e-3, "error across {err_across:.2e}");
        assert!((r.pose.theta - step.theta).abs() < 1e-3);
        // Along the corridor the result is the first guess, not a made-up correction.
        let kept = (r.pose.x - guess.x) * along[0] + (r.pose.y - guess.y) * along[1];
        assert!(kept.abs() < 1e-3, "moved {kept:.2e} m along the corridor");
    }
}

#[test]
fn noise_free_corridor_is_flagged() {
    check(LaserConfig::noise_free(), 1e4);
}

#[test]
fn noisy_corridor_is_flagged() {
    check(LaserConfig::default(), 3.0);
}
