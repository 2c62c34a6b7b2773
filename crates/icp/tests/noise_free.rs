//! Noise-free scans: exact recovery of the displacement.

mod common;

use common::{exact, urg_angles, World};
use odocal_geom::{wrap_angle, Pose2};
use odocal_icp::{IcpParams, Matcher, NeighbourSearch, PreparedScan};

fn recover_grid(search: NeighbourSearch) {
    let world = World::room();
    let angles = urg_angles();
    let params = IcpParams {
        search,
        ..IcpParams::default()
    };
    let mut matcher = Matcher::new(params.clone());
    let mut worst = (0.0f64, 0.0f64);
    let mut total_iterations = 0;
    let mut count = 0;
    for &origin in &[Pose2::new(0.1, -0.2, 0.3), Pose2::new(-0.4, 0.5, -2.0)] {
        let reference = PreparedScan::new(
            &exact(&world.scan(&origin, &angles)),
            &angles,
            0.02,
            4.0,
            &params,
        )
        .expect("reference");
        for &dx in &[-0.05, -0.02, 0.0, 0.03, 0.05] {
            for &dy in &[-0.05, 0.0, 0.02, 0.05] {
                for &dth_deg in &[-10.0, -4.0, 0.0, 3.0, 10.0] {
                    let truth = Pose2::new(dx, dy, f64::to_radians(dth_deg));
                    let pose = origin.compose(&truth);
                    let current = PreparedScan::new(
                        &exact(&world.scan(&pose, &angles)),
                        &angles,
                        0.02,
                        4.0,
                        &params,
                    )
                    .expect("current");
                    let result = matcher
                        .match_scans(&reference, &current, Pose2::IDENTITY)
                        .unwrap_or_else(|e| panic!("{truth} from {origin}: {e}"));
                    let ex = (result.pose.x - truth.x).hypot(result.pose.y - truth.y);
                    let et = wrap_angle(result.pose.theta - truth.theta).abs();
                    worst = (worst.0.max(ex), worst.1.max(et));
                    total_iterations += result.iterations;
                    count += 1;
                    assert!(
                        ex < 1e-6 && et < 1e-7,
                        "{search:?}: truth {truth} from {origin}: got {} (err {ex:.2e} m, {et:.2e} rad, {} it)",
                        result.pose,
                        result.iterations
                    );
                    assert!(!result.ill_conditioned);
                }
            }
        }
    }
    println!(
        "{search:?}: {count} displacements, worst error {:.2e} m, {:.2e} rad, mean {:.1} iterations",
        worst.0,
        worst.1,
        total_iterations as f64 / count as f64
    );
}

#[test]
fn noise_free_grid_is_recovered_exactly_angular() {
    recover_grid(NeighbourSearch::Angular);
}

#[test]
fn noise_free_grid_is_recovered_exactly_kdtree() {
    recover_grid(NeighbourSearch::KdTree);
}
