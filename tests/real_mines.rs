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
/// calibration is the full log's, within 2σ of their difference (this draw, stop 51:
/// 159 samples used against 148, ℓx +1.48σ (23 mm), b +1.08σ, the others within
/// 0.3σ).
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
    // The two estimates compared as two estimates are (the two halves', the logs'
    // agreement): by the σ of their difference, each estimate's σ added. (Until stop
    // 51 by the thinned log's σ alone, as if the full log's estimate were exact: ℓx
    // 1.90σ apart, within the 2σ then allowed only because one outlying closure of
    // the thinned log's self-check inflated its σ by 12 %; left out, as the solver
    // leaves out samples, it is 2.13σ for the same 23 mm.)
    let d = pb.difference(pa);
    for (i, name) in ["r_L", "r_R", "b", "l_x", "l_y", "l_theta"]
        .iter()
        .enumerate()
    {
        let sigma = (a.calibration.covariance[i][i] + b.calibration.covariance[i][i]).sqrt();
        println!(
            "{name}: thinned − full {:+.2}σ ({:+.2} mm or mrad)",
            d[i] / sigma,
            1e3 * d[i]
        );
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

/// At 0.6 m/s the robot moves up to 24 cm between a pair's scans: from the identity
/// the matcher refuses many of them ("correction too large"), and without a nominal
/// the bootstrap matches every pair of these short logs. Its runs guess each pair by
/// the motion the pair before it measured (odocal_pipeline::bootstrap_runs): here
/// (scan stamps, every moving pair) 114 of exp1's 181 pairs against 99 from the
/// identity; in `calibrate` 105 of 177 against 96.
#[test]
fn the_bootstrap_runs_match_more_of_a_fast_real_log_than_the_identity() {
    use odocal_pipeline::bootstrap_runs::{match_runs, BootstrapPair};
    use odocal_pipeline::matching::{match_pairs, typical_noise_sigma, with_typical_noise};
    use odocal_pipeline::sync::{default_stride, scan_pairs, EncoderTrack, SyncLimits};
    let Some(path) = mines_log("exp1.log") else {
        return;
    };
    let log = odocal_log::read_log(&path, &Default::default()).unwrap();
    let times: Vec<f64> = log.scans.scans.iter().map(|s| s.t).collect();
    let encoder_times: Vec<f64> = log.encoders.iter().map(|e| e.t).collect();
    let stride = default_stride(&times);
    let limits = SyncLimits::from_streams(&encoder_times, &times, stride);
    let ticks = log
        .params
        .ticks_per_revolution
        .as_ref()
        .expect("exp1 states its ticks")
        .0;
    let track = EncoderTrack::new(&log.encoders, ticks);
    let pairs: Vec<BootstrapPair> = scan_pairs(&times, stride)
        .iter()
        .filter_map(|p| {
            let m = track.motion(p.t0, p.t1, &limits).ok()?;
            Some((p.first, p.second, [m.dphi_l, m.dphi_r]))
        })
        .enumerate()
        .map(|(kept, (first, second, wheels))| BootstrapPair {
            kept,
            first,
            second,
            wheels,
        })
        .collect();
    let opts = Options::default();
    let matcher = opts.icp_for(&log);
    let icp = with_typical_noise(&matcher, typical_noise_sigma(&log.scans, &matcher));
    let ends: Vec<(usize, usize)> = pairs.iter().map(|p| (p.first, p.second)).collect();
    let identity = vec![odocal_geom::Pose2::IDENTITY; ends.len()];
    let from_identity = match_pairs(&log.scans, &ends, &identity, &icp, || ());
    let runs = match_runs(&log.scans, &pairs, &icp, || ());
    let count = |r: &[Result<_, _>]| r.iter().filter(|m| m.is_ok()).count();
    let (identity_ok, runs_ok) = (count(&from_identity), count(&runs));
    println!(
        "exp1: {} pairs, {identity_ok} matched from the identity, {runs_ok} by the runs",
        pairs.len()
    );
    // Every pair the identity matched is matched (a failed guess is retried from it).
    for (k, (a, b)) in from_identity.iter().zip(&runs).enumerate() {
        assert!(a.is_err() || b.is_ok(), "pair {k} lost");
    }
    assert!(runs_ok >= identity_ok + 10, "{runs_ok} vs {identity_ok}");
}
