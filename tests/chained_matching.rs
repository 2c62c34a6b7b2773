//! Pairs matched through the scans between them (`odocal_pipeline::chained`) against
//! the simulator's truth: on a clean TurtleBot-class log, every pair four scans apart
//! matched as a chain of shorter matches (from identity guesses, as without any
//! estimate) lands on the true displacement of the sensor about as well as the direct
//! match, within what its composed covariance says.

use odocal_geom::{wrap_angle, Pose2};
use odocal_pipeline::chained::match_through_intermediate_scans;
use odocal_pipeline::matching::{match_pairs, typical_noise_sigma, with_typical_noise};
use odocal_pipeline::Options;
use odocal_sim::{simulate_in, SimConfig, World};

#[test]
fn chains_of_short_matches_land_on_the_true_displacement() {
    let mut config = SimConfig::preset("turtlebot").expect("preset");
    config.seed = 3;
    config.duration = 60.0;
    // No sweep: the truth is the sensor pose at the scan's timestamp.
    config.laser.time_increment = 0.0;
    let world = World::preset(&config.world).expect("world");
    let run = simulate_in(&config, &world).expect("simulates");
    let log = run.to_log();
    let truth: Vec<Pose2> = run.logged_scans().map(|s| s.sensor).collect();
    let base = Options::default().icp;
    let params = with_typical_noise(&base, typical_noise_sigma(&log.scans, &base));
    let pairs: Vec<(usize, usize)> = (0..truth.len().saturating_sub(4))
        .step_by(4)
        .map(|a| (a, a + 4))
        .collect();
    assert!(pairs.len() >= 50, "{} pairs", pairs.len());
    let chained =
        match_through_intermediate_scans(&log.scans, &pairs, &|_, _| Pose2::IDENTITY, &params);
    let direct = match_pairs(
        &log.scans,
        &pairs,
        &vec![Pose2::IDENTITY; pairs.len()],
        &params,
        || {},
    );
    let (mut composed, mut nees_sum) = (0, 0.0);
    // Squared translation errors of the pairs matched both ways: chained, direct.
    let (mut both, mut sq_chained, mut sq_direct) = (0, 0.0, 0.0);
    let mut worst = (0.0f64, 0.0f64);
    for ((&(a, b), c), d) in pairs.iter().zip(&chained).zip(&direct) {
        let Some(c) = c else { continue };
        composed += 1;
        assert!(c.links >= 2, "pair ({a}, {b}): {} links", c.links);
        let t = truth[a].between(&truth[b]);
        let e = [
            c.pose.x - t.x,
            c.pose.y - t.y,
            wrap_angle(c.pose.theta - t.theta),
        ];
        worst.0 = worst.0.max(e[0].hypot(e[1]));
        worst.1 = worst.1.max(e[2].abs());
        let m = nalgebra::Matrix3::from_fn(|r, k| c.covariance[r][k]);
        let inv = m.try_inverse().expect("covariance invertible");
        let v = nalgebra::Vector3::from(e);
        nees_sum += (v.transpose() * inv * v)[0];
        if let Ok(d) = d {
            both += 1;
            sq_chained += e[0] * e[0] + e[1] * e[1];
            sq_direct += t.between(&d.pose).translation_norm().powi(2);
        }
    }
    assert!(
        composed as f64 >= 0.9 * pairs.len() as f64,
        "{composed} of {} pairs composed",
        pairs.len()
    );
    // Two links of half the motion: about √2 times one match's error, not more.
    let (rms_chained, rms_direct) = (
        (sq_chained / both.max(1) as f64).sqrt(),
        (sq_direct / both.max(1) as f64).sqrt(),
    );
    assert!(both >= 30, "{both} pairs matched both ways");
    assert!(
        rms_chained < 1.6 * rms_direct,
        "RMS error chained {:.2} mm, direct {:.2} mm",
        rms_chained * 1e3,
        rms_direct * 1e3
    );
    assert!(
        worst.0 < 0.02 && worst.1 < 0.3f64.to_radians(),
        "worst error {:.2} mm / {:.3}°",
        worst.0 * 1e3,
        worst.1.to_degrees()
    );
    // The composed covariance covers the errors (χ²(3): mean 3).
    let mean_nees = nees_sum / composed as f64;
    assert!(mean_nees < 9.0, "mean NEES {mean_nees:.1}");
    println!(
        "{composed} of {} composed; RMS error chained {:.2} mm, direct {:.2} mm ({both} pairs); \
         worst {:.2} mm / {:.3}°; mean NEES {mean_nees:.2}",
        pairs.len(),
        rms_chained * 1e3,
        rms_direct * 1e3,
        worst.0 * 1e3,
        worst.1.to_degrees()
    );
}
