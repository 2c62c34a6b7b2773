//! The reported covariance against the empirical scatter over many noisy pairs.

use odocal_geom::{wrap_angle, Pose2};
use odocal_icp::{IcpParams, Matcher, PreparedScan};
use odocal_sim::{LaserConfig, World};
use rand::{rngs::StdRng, SeedableRng};

/// Empirical / reported standard deviation per axis over `trials` noise draws.
fn ratios(
    laser: &LaserConfig,
    world: &World,
    from: Pose2,
    step: Pose2,
    trials: usize,
) -> ([f64; 3], f64) {
    let params = IcpParams::default();
    let angles = laser.angles();
    let to = from.compose(&step);
    let mut rng = StdRng::seed_from_u64(42);
    let mut matcher = Matcher::new(params.clone());
    let mut errors = Vec::with_capacity(trials);
    let mut reported = [0.0; 3];
    let mut inflation = 0.0;
    for _ in 0..trials {
        let prepare = |ranges: Vec<f32>| {
            PreparedScan::new(&ranges, &angles, laser.min_range, laser.max_range, &params)
                .expect("scan")
        };
        let reference = prepare(laser.scan(world, &from, &mut rng));
        let current = prepare(laser.scan(world, &to, &mut rng));
        let guess = Pose2::new(step.x + 0.002, step.y - 0.002, step.theta + 0.004);
        let r = matcher
            .match_scans(&reference, &current, guess)
            .expect("match");
        assert!(!r.ill_conditioned);
        inflation += r.residual_correlation_inflation;
        errors.push([
            r.pose.x - step.x,
            r.pose.y - step.y,
            wrap_angle(r.pose.theta - step.theta),
        ]);
        for (axis, value) in reported.iter_mut().enumerate() {
            *value += r.covariance[axis][axis];
        }
    }
    let n = trials as f64;
    let mut out = [0.0; 3];
    for axis in 0..3 {
        let mean = errors.iter().map(|e| e[axis]).sum::<f64>() / n;
        let var = errors.iter().map(|e| (e[axis] - mean).powi(2)).sum::<f64>() / (n - 1.0);
        out[axis] = (var / (reported[axis] / n)).sqrt();
    }
    (out, inflation / n)
}

fn check(name: &str, laser: LaserConfig) {
    let arena = World::khepera_arena();
    let office = World::office();
    for (world_name, world, from) in [
        ("arena", &arena, Pose2::new(1.5, 1.2, 0.3)),
        ("office", &office, Pose2::new(3.0, 2.5, 2.0)),
    ] {
        let (r, inflation) = ratios(&laser, world, from, Pose2::new(0.02, 0.005, 0.03), 150);
        let s = inflation.sqrt();
        println!(
            "{name:10} {world_name:6}: empirical / reported σ: x {:.2}, y {:.2}, θ {:.2} \
             (mean inflation {inflation:.2}; without it: x {:.2}, y {:.2}, θ {:.2})",
            r[0],
            r[1],
            r[2],
            r[0] * s,
            r[1] * s,
            r[2] * s
        );
        for (axis, ratio) in ["x", "y", "θ"].iter().zip(r) {
            assert!(
                (0.5..=2.0).contains(&ratio),
                "{name} {world_name}: σ ratio {ratio:.2} along {axis} outside [0.5, 2]"
            );
        }
    }
}

#[test]
fn covariance_matches_scatter_with_correlated_noise() {
    check("correlated", LaserConfig::default());
}

#[test]
fn covariance_matches_scatter_with_independent_noise() {
    check(
        "white",
        LaserConfig {
            correlation_rays: 1,
            ..LaserConfig::default()
        },
    );
}
