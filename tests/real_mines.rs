//! The real MinesRover logs (Hokuyo URG-04LX, 0.6 m/s, 55 % of the readings without a
//! return; /work/shared/real/mines, read from `../shared/real/mines` beside the
//! repository, skipped with a notice when absent): how many of the pairs the scan
//! matcher matches, and that every refusal is counted by its reason.

use odocal_pipeline::{calibrate_log, NoProgress, Options, Rejection};
use std::path::PathBuf;

fn mines_log(name: &str) -> Option<PathBuf> {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/real/mines")
        .join(name);
    if path.exists() {
        Some(path)
    } else {
        println!("skipped: {} is absent", path.display());
        None
    }
}

#[test]
fn most_pairs_of_the_real_mines_logs_match_and_every_refusal_has_its_reason() {
    // (log, share of the moving pairs matched at least): measured 99/175 (57 %) and
    // 75/147 (51 %) since runs ending at readings without a return are followed a
    // little further in sparse scans (89/175 and 66/147 before; docs/benchmarks.md).
    // A visibility-aware overlap gave more but accepted wrong matches in the basin
    // grid, and was withdrawn; matching the refused pairs again in the second pass
    // gave 109 and 80 but made fixtures/bags/turtlebot_tf.bag pass as well determined
    // with l_x 5 sigma off its truth, and was withdrawn: the yield target of issue 20
    // (80 %) is not met.
    for (name, min_yield) in [("exp1.log", 0.56), ("exp2.log", 0.48)] {
        let Some(path) = mines_log(name) else { return };
        let log = odocal_log::read_log(&path, &Default::default()).unwrap();
        let opts = Options {
            accept_weak: true,
            ..Options::default()
        };
        let outcome = calibrate_log(&log, &opts, &NoProgress).unwrap();
        let synced = &outcome.synced;
        let failed = synced
            .discarded
            .get(odocal_pipeline::sync::DiscardReason::MatchFailed);
        assert_eq!(synced.match_rejections.total(), failed, "{name}");
        let matched = synced.samples.len();
        let share = matched as f64 / (matched + failed) as f64;
        println!(
            "{name}: {matched} of {} moving pairs matched ({:.0} %); refused {:?}",
            matched + failed,
            100.0 * share,
            synced.match_rejections.0
        );
        assert!(share >= min_yield, "{name}: {:.0} % matched", 100.0 * share);
        // The matcher measures its own error there: measured 4.7 and 2.9 mm, 0.28° and
        // 0.18° per pair (closure of scan triples; 6.5 and 2.9 mm, 0.24° and 0.16°
        // before), 10-30x the simulator's.
        let check = synced.match_self_check.expect("scan triples close");
        assert!(check.triples >= 20, "{name}: {check:?}");
        assert!(
            (0.002..0.03).contains(&check.xy_m) && check.theta_rad.to_degrees() > 0.05,
            "{name}: {check:?}"
        );
        // No reason outside the matcher's (nothing lost as "other").
        assert_eq!(synced.match_rejections.get(Rejection::Other), 0, "{name}");
    }
}
