//! The real MinesRover logs (Hokuyo URG-04LX, 0.6 m/s, 55 % of the readings without a
//! return; /work/shared/real/mines, read from `../shared/real/mines` beside the
//! repository, skipped with a notice when absent): how many of the pairs the scan
//! matcher matches, and that every refusal is counted by its reason.

mod common;

use common::mines_log;
use odocal_pipeline::{calibrate_log, NoProgress, Options, Rejection};

#[test]
fn most_pairs_of_the_real_mines_logs_match_and_every_refusal_has_its_reason() {
    // (log, share of the moving pairs matched at least): measured 160/174 (92 %) and
    // 116/147 (79 %) since the overlap share leaves out points landing where the
    // reference has no local line (151/174 and 112/147 before; docs/benchmarks.md),
    // 150/174 (86 %) and 112/147 (76 %) since refused pairs are matched through the
    // scans between them (odocal_pipeline::chained; 99/175 and 75/147 before, 89/175
    // and 66/147 before
    // runs ending at readings without a return were followed; docs/benchmarks.md).
    // A visibility-aware overlap gave more but accepted wrong matches in the basin
    // grid, and was withdrawn; matching the refused pairs again in the second pass
    // made fixtures/bags/turtlebot_tf.bag pass as well determined with l_x 5 sigma off
    // its truth (one spin decided it: now caught by the one-sample rule of the solver).
    // 163/174 (94 %) and 121/147 (82 %) since runs go across up to two readings
    // without a return (IcpParams::bridged_missing_rays; docs/benchmarks.md).
    // Issue 20's target (80 %) is met on both.
    for (name, min_yield) in [("exp1.log", 0.90), ("exp2.log", 0.80)] {
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
        // The matcher measures its own error there: measured 5.1 and 4.6 mm, 0.32° and
        // 0.16° per pair (closure of scan triples; 4.7 and 2.9 mm, 0.28° and 0.18° before
        // the overlap share's change; 6.5 and 2.9 mm, 0.24° and 0.16° before chaining),
        // 10-30x the simulator's.
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

/// Half of the returns of a real log dropped at random (the URG-04LX's 55 % of
/// readings without a return become 78 %: a darker room, a weaker sensor). Before
/// runs went across missing readings, no run of seven consecutive returns was left to
/// show the scans' noise, the noise was taken as none, and every one of exp1's 181
/// pairs was refused as a wrong alignment ("residuals"): no calibration. Now the
/// calibration is the full log's, within the thinned log's σ (this draw: 158 samples
/// used against 155, ℓy −1.82σ, the others within 0.6σ; another draw gave b +1.42σ,
/// ℓx +1.37σ).
#[test]
fn a_real_log_with_half_its_returns_dropped_calibrates_like_the_full_one() {
    let Some(path) = mines_log("exp1.log") else {
        return;
    };
    let full = odocal_log::read_log(&path, &Default::default()).unwrap();
    use rand::{Rng, SeedableRng};
    let mut thinned = full.clone();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
    let (mut kept, mut dropped) = (0usize, 0usize);
    for r in thinned.scans.ranges.iter_mut().filter(|r| **r > 0.0) {
        if rng.random_bool(0.5) {
            *r = 0.0;
            dropped += 1;
        } else {
            kept += 1;
        }
    }
    let missing = 1.0 - kept as f64 / thinned.scans.ranges.len() as f64;
    println!(
        "dropped {dropped} returns, kept {kept}: {:.0} % missing",
        100.0 * missing
    );
    assert!((0.74..0.82).contains(&missing), "{missing}");
    let opts = Options {
        accept_weak: true,
        ..Options::default()
    };
    let a = calibrate_log(&full, &opts, &NoProgress).unwrap();
    let b = calibrate_log(&thinned, &opts, &NoProgress).unwrap();
    let (pa, pb) = (&a.calibration.params, &b.calibration.params);
    println!(
        "samples: full {} of {} pairs, thinned {} of {}",
        a.calibration.samples_used, a.synced.pairs, b.calibration.samples_used, b.synced.pairs
    );
    assert!(
        b.calibration.samples_used >= 100,
        "{}",
        b.calibration.samples_used
    );
    let d = pb.difference(pa);
    for (i, name) in ["r_L", "r_R", "b", "l_x", "l_y", "l_theta"]
        .iter()
        .enumerate()
    {
        let sigma = b.calibration.covariance[i][i].sqrt();
        println!("{name}: thinned − full {:+.2}σ", d[i] / sigma);
        assert!(
            d[i].abs() < 2.0 * sigma,
            "{name}: {:+.2}σ apart",
            d[i] / sigma
        );
    }
}

/// The real exp1 thinned to a Neato-like scan: every third ray (1.05° apart, 227 of
/// 681), 60 % of their returns dropped, about 35 returns a scan; such scans go to the
/// sparse matcher. With its neighbourhood lines through points within 30 cm, too few
/// pairs matched (this test fails; a Python-made draw: 19 samples, refused); within
/// 45 cm (`neighbourhood_lines::MATCHING_RADIUS`) the log calibrates, weakly (this
/// draw: 41 returns a scan, 29 samples), and agrees with the full log within their
/// joint σ (every parameter within 0.54σ). With the pairs refused alone matched with
/// their neighbouring scans (`odocal_pipeline::local_map`): 42 samples, every
/// parameter within 1.10σ (over ten draws of each real log: docs/benchmarks.md,
/// stop 37); with a cloud's share taken over its own scan's points (stop 38): 58
/// samples, every parameter within 1.47σ.
#[test]
fn a_real_log_thinned_to_a_neato_like_scan_calibrates_like_the_full_one() {
    let Some(path) = mines_log("exp1.log") else {
        return;
    };
    use rand::{Rng, SeedableRng};
    let full = odocal_log::read_log(&path, &Default::default()).unwrap();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
    let mut thinned = odocal_log::Log {
        scans: odocal_log::ScanStore::default(),
        ..full.clone()
    };
    let mut returns = 0usize;
    for scan in full.scans.iter() {
        let g = scan.geometry;
        let angles: Vec<f64> = g.angles.iter().step_by(3).copied().collect();
        let geometry = odocal_log::ScanGeometry {
            resolution: 3.0 * g.resolution,
            fov: angles.last().unwrap() - angles[0],
            time_increment: 3.0 * g.time_increment,
            angles: angles.into(),
            ..g.clone()
        };
        let ranges: Vec<f32> = scan
            .ranges
            .iter()
            .step_by(3)
            .map(|&r| if rng.random_bool(0.6) { 0.0 } else { r })
            .collect();
        returns += ranges.iter().filter(|&&r| g.is_valid(r)).count();
        thinned
            .scans
            .push(scan.t, &geometry, &ranges, scan.kind, scan.line);
    }
    let per_scan = returns as f64 / thinned.scans.len() as f64;
    println!("{per_scan:.0} returns a scan");
    assert!((25.0..50.0).contains(&per_scan), "{per_scan}");
    let opts = Options {
        accept_weak: true,
        ..Options::default()
    };
    let a = calibrate_log(&full, &opts, &NoProgress).unwrap();
    let b = match calibrate_log(&thinned, &opts, &NoProgress) {
        Ok(b) => b,
        Err(e) => panic!("the thinned log is refused: {e}"),
    };
    println!(
        "samples: full {}, thinned {} of {} pairs",
        a.calibration.samples_used, b.calibration.samples_used, b.synced.pairs
    );
    let d = b.calibration.params.difference(&a.calibration.params);
    for (i, name) in ["r_L", "r_R", "b", "l_x", "l_y", "l_theta"]
        .iter()
        .enumerate()
    {
        let sigma = (b.calibration.covariance[i][i] + a.calibration.covariance[i][i]).sqrt();
        println!("{name}: thinned − full {:+.2}σ", d[i] / sigma);
        assert!(
            d[i].abs() < 3.0 * sigma,
            "{name}: {:+.2}σ apart",
            d[i] / sigma
        );
    }
}
