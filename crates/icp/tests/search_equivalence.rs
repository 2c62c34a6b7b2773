//! The angular search finds exactly the closest points, like the k-d tree: both give
//! the same matches, hence the same poses, on noisy simulated pairs.

use odocal_geom::Pose2;
use odocal_icp::{IcpParams, Matcher, NeighbourSearch, PreparedScan};
use odocal_sim::{simulate, PresetRegistry};

#[test]
fn angular_and_kd_tree_searches_agree() {
    for preset in ["khepera", "office"] {
        let mut config = PresetRegistry::builtin().get(preset).expect("preset");
        config.duration = 8.0;
        let run = simulate(&config).expect("simulation");
        let angles = run.config.laser.angles();
        let angular = IcpParams::default();
        let tree = IcpParams {
            search: NeighbourSearch::KdTree,
            ..IcpParams::default()
        };
        let prepare = |params: &IcpParams| -> Vec<PreparedScan> {
            run.scans
                .iter()
                .map(|s| PreparedScan::new(&s.ranges, &angles, 0.02, 4.0, params).expect("scan"))
                .collect()
        };
        let (scans_a, scans_t) = (prepare(&angular), prepare(&tree));
        let mut matcher_a = Matcher::new(angular);
        let mut matcher_t = Matcher::new(tree);
        for gap in [1, 4] {
            for k in 0..run.scans.len() - gap {
                let truth = run.scans[k].sensor.between(&run.scans[k + gap].sensor);
                let guess = Pose2::new(truth.x + 0.003, truth.y - 0.002, truth.theta + 0.006);
                let a = matcher_a.match_scans(&scans_a[k], &scans_a[k + gap], guess);
                let t = matcher_t.match_scans(&scans_t[k], &scans_t[k + gap], guess);
                let (a, t) = (a.expect("angular"), t.expect("k-d tree"));
                assert_eq!(a.iterations, t.iterations, "{preset} pair {k}+{gap}");
                assert_eq!(
                    a.correspondences, t.correspondences,
                    "{preset} pair {k}+{gap}"
                );
                assert_eq!(a.pose, t.pose, "{preset} pair {k}+{gap}");
            }
        }
    }
}

#[test]
fn prepared_scans_and_matchers_can_be_shared_across_threads() {
    fn send_sync<T: Send + Sync>() {}
    send_sync::<PreparedScan>();
    send_sync::<Matcher>();
    send_sync::<IcpParams>();
}
