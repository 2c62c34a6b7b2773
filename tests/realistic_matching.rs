//! The scan matcher on the realistic presets (docs/realistic-presets.md), measured
//! against the simulator's truth: the share of the pairs whose true overlap is at
//! least half the scan that the pipeline matches, and the error of every accepted
//! match against the true displacement of the sensor.
//!
//! The fast tests (20 s logs) assert what today's matcher reaches, with a margin.
//! The table, on longer logs and several seeds:
//! `cargo test --release --test realistic_matching -- --ignored --nocapture`.

mod common;

use odocal_geom::Pose2;
use odocal_pipeline::{calibrate_log, synchronize_and_match, NoProgress, Options, Timing};
use odocal_sim::{simulate_in, RealisticLaser, SimConfig, SimRun, World, REALISTIC_PRESETS};
use std::collections::BTreeMap;

/// Accepted matches farther than this from the truth are wrong (m, rad).
const MAX_ERROR_M: f64 = 0.005;
const MAX_ERROR_RAD: f64 = 0.5 * std::f64::consts::PI / 180.0;
/// A scan point of the second scan counts as seen by the first when the first's ray
/// toward it reaches it within this (m).
const VISIBLE_TOLERANCE_M: f64 = 0.05;
/// χ²(3)'s 99.7 % level: a right covariance leaves 0.3 % of the NEES above it.
const NEES_997: f64 = 14.16;

/// A covariance of `(x, y, θ)`.
type Covariance = [[f64; 3]; 3];

/// The squared Mahalanobis distance of `e` (x, y, θ) under `cov` (∞ when `cov` is
/// singular or not finite).
fn nees(e: [f64; 3], cov: &Covariance) -> f64 {
    let m = nalgebra::Matrix3::from_fn(|r, c| cov[r][c]);
    let v = nalgebra::Vector3::from(e);
    match m.try_inverse() {
        Some(inv) if inv.iter().all(|x| x.is_finite()) => (v.transpose() * inv * v)[0],
        _ => f64::INFINITY,
    }
}

/// The probability that an error drawn from N(0, `cov`) (a match's (x, y, θ)
/// covariance) is beyond 5 mm in translation or 0.5° in rotation: 4,000 draws from
/// a generator seeded with `seed`. A covariance that is not positive semi-definite
/// counts its negative eigenvalues as 0.
fn predicted_beyond(cov: &Covariance, seed: u64) -> f64 {
    use rand::{Rng, SeedableRng};
    const DRAWS: usize = 4000;
    let m = nalgebra::Matrix3::from_fn(|r, c| cov[r][c]);
    if !m.iter().all(|x| x.is_finite()) {
        return 1.0;
    }
    let eigen = nalgebra::SymmetricEigen::new(m);
    let root = eigen.eigenvectors
        * nalgebra::Matrix3::from_diagonal(&eigen.eigenvalues.map(|l| l.max(0.0).sqrt()));
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let beyond = (0..DRAWS)
        .filter(|_| {
            let z: [f64; 3] = std::array::from_fn(|_| rng.sample(rand_distr::StandardNormal));
            let e = root * nalgebra::Vector3::from(z);
            e[0].hypot(e[1]) > MAX_ERROR_M || e[2].abs() > MAX_ERROR_RAD
        })
        .count();
    beyond as f64 / DRAWS as f64
}

/// What the matcher did on one log.
#[derive(Debug, Default, Clone)]
struct Yield {
    /// Pairs sent to the matcher (not discarded for wheel reasons).
    tried: usize,
    /// Of those, pairs whose true overlap is at least half the second scan.
    overlapping: usize,
    /// Of the overlapping pairs, those matched.
    overlapping_matched: usize,
    /// All accepted matches, and their errors against the truth (m, rad).
    errors: Vec<(f64, f64)>,
    /// Per accepted match (same order): its NEES, the error's squared Mahalanobis
    /// distance under the match's own covariance (χ²(3) when the covariance is right).
    nees: Vec<f64>,
    /// Per accepted match (same order): the probability, under the match's own
    /// covariance, of an error beyond 5 mm / 0.5° ([`predicted_beyond`]).
    predicted_beyond: Vec<f64>,
    /// The matcher's rejections, by reason.
    rejections: BTreeMap<&'static str, usize>,
    /// Per accepted match (same order): matched through the scans between the pair's
    /// two (`odocal_pipeline::chained`) rather than directly.
    chained: Vec<bool>,
    /// Per accepted match (same order): the neighbouring scans its scans were
    /// densified with (`odocal_pipeline::local_map`; 0: matched alone).
    neighboured: Vec<u32>,
    /// Per accepted match (same order): matched along a corridor, one direction left
    /// free (`odocal_icp::IcpResult::free_direction`).
    free: Vec<bool>,
    /// The errors against the truth (m, rad) of the samples the calibration of the log
    /// (`calibrate_log`, `--accept-weak`) matched in its second pass, from guesses by
    /// its first estimate (empty when it refuses the log).
    final_errors: Vec<(f64, f64)>,
    /// Of the overlapping pairs, those among the samples of that second pass (the
    /// matches the calibration uses).
    final_overlapping_matched: usize,
}

impl Yield {
    fn add(&mut self, other: &Yield) {
        self.tried += other.tried;
        self.overlapping += other.overlapping;
        self.overlapping_matched += other.overlapping_matched;
        self.final_overlapping_matched += other.final_overlapping_matched;
        self.errors.extend_from_slice(&other.errors);
        self.nees.extend_from_slice(&other.nees);
        self.predicted_beyond
            .extend_from_slice(&other.predicted_beyond);
        self.chained.extend_from_slice(&other.chained);
        self.neighboured.extend_from_slice(&other.neighboured);
        self.free.extend_from_slice(&other.free);
        self.final_errors.extend_from_slice(&other.final_errors);
        for (k, v) in &other.rejections {
            *self.rejections.entry(k).or_default() += v;
        }
    }

    /// Share of the overlapping pairs matched.
    /// The share of the overlapping pairs among the second pass's samples.
    fn final_share(&self) -> f64 {
        self.final_overlapping_matched as f64 / self.overlapping.max(1) as f64
    }

    fn share(&self) -> f64 {
        self.overlapping_matched as f64 / self.overlapping.max(1) as f64
    }

    /// Accepted matches beyond 5 mm or 0.5° of the truth.
    fn wrong(&self) -> usize {
        self.errors.iter().filter(|e| beyond(e)).count()
    }

    /// Accepted matches beyond 5 mm or 0.5° of the truth whose own covariance does not
    /// cover the error (NEES beyond χ²(3)'s 99.7 % level): confidently wrong.
    fn wrong_uncovered(&self) -> usize {
        self.errors
            .iter()
            .zip(&self.nees)
            .filter(|(e, n)| beyond(e) && **n > NEES_997)
            .count()
    }

    /// Accepted matches composed through intermediate scans, and of those the ones
    /// beyond 5 mm or 0.5° of the truth.
    fn chained_wrong(&self) -> (usize, usize) {
        let chained = self.chained.iter().filter(|c| **c).count();
        let wrong = self
            .errors
            .iter()
            .zip(&self.chained)
            .filter(|(e, c)| **c && beyond(e))
            .count();
        (chained, wrong)
    }

    /// Accepted matches of scans densified by their neighbours: how many, how many
    /// beyond 5 mm or 0.5° of the truth, and how many their own covariances predict
    /// beyond.
    fn neighboured_wrong(&self) -> (usize, usize, f64) {
        let mut out = (0, 0, 0.0);
        for ((e, n), p) in self
            .errors
            .iter()
            .zip(&self.neighboured)
            .zip(&self.predicted_beyond)
        {
            if *n > 0 {
                out.0 += 1;
                out.1 += usize::from(beyond(e));
                out.2 += p;
            }
        }
        out
    }

    /// Accepted matches that leave a direction free, and of those the ones whose
    /// NEES is beyond χ²(3)'s 99.7 % level: wrong in the directions they fix (along
    /// the free one their covariance is a metre wide).
    fn free_uncovered(&self) -> (usize, usize) {
        let free = self.free.iter().filter(|f| **f).count();
        let uncovered = self
            .nees
            .iter()
            .zip(&self.free)
            .filter(|(n, f)| **f && **n > NEES_997)
            .count();
        (free, uncovered)
    }

    /// How many accepted matches the matcher's own covariances put beyond 5 mm / 0.5°
    /// of the truth (the sum of their probabilities): what [`Yield::wrong`] would be
    /// if every covariance were right.
    fn predicted_wrong(&self) -> f64 {
        self.predicted_beyond.iter().sum()
    }

    /// Mean NEES of the accepted matches (3 when their covariances are right).
    fn mean_nees(&self) -> f64 {
        self.nees.iter().sum::<f64>() / self.nees.len().max(1) as f64
    }

    /// Share of the accepted matches whose NEES is beyond χ²(3)'s 99.7 % level
    /// (0.003 when their covariances are right).
    fn nees_beyond(&self) -> f64 {
        self.nees.iter().filter(|n| **n > NEES_997).count() as f64 / self.nees.len().max(1) as f64
    }

    /// RMS translation (mm) and rotation (°) error of the accepted matches.
    fn rms(&self) -> (f64, f64) {
        let n = self.errors.len().max(1) as f64;
        let d = self.errors.iter().map(|(d, _)| d * d).sum::<f64>() / n;
        let a = self.errors.iter().map(|(_, a)| a * a).sum::<f64>() / n;
        (d.sqrt() * 1e3, a.sqrt().to_degrees())
    }

    /// Largest translation (mm) and rotation (°) error.
    fn worst(&self) -> (f64, f64) {
        let (d, a) = worst(&self.errors);
        (d * 1e3, a.to_degrees())
    }

    fn row(&self, label: &str) -> String {
        let (rd, ra) = self.rms();
        let (wd, wa) = self.worst();
        let reasons: Vec<String> = self
            .rejections
            .iter()
            .filter(|(_, n)| **n > 0)
            .map(|(k, n)| format!("{k} {n}"))
            .collect();
        format!(
            "| {label} | {} | {} | {}/{} ({:.0} %) | {} | {rd:.1} mm / {ra:.2}° | {wd:.1} mm / {wa:.2}° | {} ({:.0} %) | {:.0} ({:.0} %) | {} | {:.1}, {:.1} % | {} | {} ({}) | {} ({}, {:.0}) | {} ({}) | {}, {}/{} ({:.0} %), {:.1} mm / {:.2}°, {} |",
            self.tried,
            self.overlapping,
            self.overlapping_matched,
            self.overlapping,
            100.0 * self.share(),
            self.errors.len(),
            self.wrong(),
            100.0 * self.wrong() as f64 / self.errors.len().max(1) as f64,
            self.predicted_wrong(),
            100.0 * self.predicted_wrong() / self.errors.len().max(1) as f64,
            self.wrong_uncovered(),
            self.mean_nees(),
            100.0 * self.nees_beyond(),
            reasons.join(", "),
            self.chained_wrong().0,
            self.chained_wrong().1,
            self.neighboured_wrong().0,
            self.neighboured_wrong().1,
            self.neighboured_wrong().2,
            self.free_uncovered().0,
            self.free_uncovered().1,
            self.final_errors.len(),
            self.final_overlapping_matched,
            self.overlapping,
            100.0 * self.final_share(),
            1e3 * worst(&self.final_errors).0,
            worst(&self.final_errors).1.to_degrees(),
            self.final_errors
                .iter()
                .filter(|e| beyond(e))
                .count(),
        )
    }
}

/// Is the error `(distance, angle)` (m, rad) beyond 5 mm or 0.5°?
fn beyond(&(d, a): &(f64, f64)) -> bool {
    d > MAX_ERROR_M || a > MAX_ERROR_RAD
}

/// The largest distance and the largest angle of `errors` (m, rad; 0 when empty).
fn worst(errors: &[(f64, f64)]) -> (f64, f64) {
    errors
        .iter()
        .fold((0.0f64, 0.0f64), |(d, a), e| (d.max(e.0), a.max(e.1)))
}

const TABLE_HEADER: &str = "| preset, seeds | pairs tried | true overlap ≥ ½ | matched of those | accepted | RMS error | worst error | beyond 5 mm / 0.5° | beyond, as their own σ predict | of those, NEES > 14.2 | NEES: mean, share > 14.2 | rejections | matched through scans between (beyond) | matched with neighbouring scans (beyond, as their own σ predict) | matched along a corridor, one direction free (NEES > 14.2) | after the second pass: samples, overlapping pairs matched, worst error, beyond 5 mm / 0.5° |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|";

/// The share of the returns of `second` (taken from `p2`) that the sensor at `p1` sees
/// too: the ray from `p1` toward each point reaches it (nothing nearer in between,
/// within the range and the field of view).
fn true_overlap(run: &SimRun, p1: &Pose2, p2: &Pose2, second: &[f32]) -> f64 {
    let laser = &run.config.laser;
    let angles = laser.angles();
    let (lo, hi) = {
        let (a, b) = (angles[0], angles[angles.len() - 1]);
        (a.min(b), a.max(b))
    };
    let full_turn = hi - lo + laser.resolution.abs() >= std::f64::consts::TAU - 1e-9;
    let world: &World = &run.world;
    let (mut seen, mut valid) = (0usize, 0usize);
    for (&r, &a) in second.iter().zip(&angles) {
        if r <= 0.0 {
            continue;
        }
        valid += 1;
        let r = r as f64;
        let (s, c) = (p2.theta + a).sin_cos();
        let q = [p2.x + r * c, p2.y + r * s];
        let (dx, dy) = (q[0] - p1.x, q[1] - p1.y);
        let dist = dx.hypot(dy);
        if dist >= laser.max_range || dist <= laser.min_range {
            continue;
        }
        let bearing = odocal_geom::wrap_angle(dy.atan2(dx) - p1.theta);
        if !full_turn && (bearing < lo || bearing > hi) {
            continue;
        }
        let reach = world
            .cast_ray([p1.x, p1.y], dy.atan2(dx), laser.max_range)
            .unwrap_or(f64::INFINITY);
        if reach >= dist - VISIBLE_TOLERANCE_M {
            seen += 1;
        }
    }
    seen as f64 / valid.max(1) as f64
}

/// Simulates `preset` for `duration` s with `seed`, runs the pipeline's
/// synchronization and matching on it, and compares with the truth.
fn measure(preset: &str, seed: u64, duration: f64) -> Yield {
    measure_with(preset, seed, duration, false)
}

/// [`measure`], and with `second_pass` the log's calibration too
/// ([`Yield::final_errors`]).
fn measure_with(preset: &str, seed: u64, duration: f64, second_pass: bool) -> Yield {
    let mut config = SimConfig::preset(preset).unwrap();
    config.seed = seed;
    config.duration = duration;
    let world = World::preset(&config.world).unwrap();
    measure_in(config, &world, second_pass)
}

/// [`measure`] on the configuration `config` in `world`; with `second_pass`, the
/// log's calibration too ([`Yield::final_errors`]).
fn measure_in(config: SimConfig, world: &World, second_pass: bool) -> Yield {
    let run = simulate_in(&config, world).unwrap();
    let log = run.to_log();
    let mut timing = Timing::default();
    let synced =
        synchronize_and_match(&log, &Options::default(), &NoProgress, &mut timing).unwrap();
    let scans: Vec<_> = run.logged_scans().collect();
    let truth_pose = |i: usize| {
        if synced.sweep_compensated {
            scans[i].sensor_at_reference
        } else {
            scans[i].sensor
        }
    };
    let matched: BTreeMap<(usize, usize), _> = synced
        .samples
        .iter()
        .map(|s| ((s.pair.first, s.pair.second), &s.icp))
        .collect();
    let discarded_other = synced.discarded.0.values().sum::<usize>()
        - synced.discarded.0.get("match_failed").copied().unwrap_or(0);
    let mut y = Yield {
        tried: synced.pairs - discarded_other,
        rejections: synced.match_rejections.0.clone(),
        ..Yield::default()
    };
    let k = synced.stride;
    let mut i = 0;
    let mut overlapping_pairs = 0;
    let mut overlapping_set = std::collections::BTreeSet::new();
    while i + k < scans.len() {
        let (a, b) = (truth_pose(i), truth_pose(i + k));
        let overlap = true_overlap(&run, &a, &b, &scans[i + k].ranges);
        let accepted = matched.get(&(i, i + k));
        if overlap >= 0.5 {
            overlapping_pairs += 1;
            overlapping_set.insert((i, i + k));
            if accepted.is_some() {
                y.overlapping_matched += 1;
            }
        }
        if let Some(m) = accepted {
            let (pose, cov) = (&m.pose, &m.covariance);
            y.chained.push(m.links > 1);
            y.neighboured.push(m.neighbours);
            y.free.push(!m.fixes_every_direction());
            let truth = a.inverse().compose(&b);
            let e = truth.inverse().compose(pose);
            y.errors
                .push((e.x.hypot(e.y), odocal_geom::wrap_angle(e.theta).abs()));
            // The error in the parameters the covariance is of: ŝ's (x, y, θ) in the
            // first scan's frame.
            let d = [
                pose.x - truth.x,
                pose.y - truth.y,
                odocal_geom::wrap_angle(pose.theta - truth.theta),
            ];
            y.nees.push(nees(d, cov));
            y.predicted_beyond.push(predicted_beyond(cov, i as u64));
        }
        i += k;
    }
    // Pairs discarded for wheel reasons (robot still, encoder gaps) never reach the
    // matcher; they are counted out of the overlapping ones (a still robot's pair
    // overlaps fully).
    y.overlapping = overlapping_pairs - discarded_other.min(overlapping_pairs);
    let options = Options {
        accept_weak: true,
        ..Options::default()
    };
    if let Some(Ok(outcome)) = second_pass.then(|| calibrate_log(&log, &options, &NoProgress)) {
        let compensated = outcome.synced.sweep_compensated;
        let pose = |i: usize| {
            if compensated {
                scans[i].sensor_at_reference
            } else {
                scans[i].sensor
            }
        };
        y.final_overlapping_matched = outcome
            .synced
            .samples
            .iter()
            .filter(|s| overlapping_set.contains(&(s.pair.first, s.pair.second)))
            .count();
        y.final_errors = outcome
            .synced
            .samples
            .iter()
            .map(|s| {
                let truth = pose(s.pair.first).inverse().compose(&pose(s.pair.second));
                let e = truth.inverse().compose(&s.icp.pose);
                (e.x.hypot(e.y), odocal_geom::wrap_angle(e.theta).abs())
            })
            .collect();
    }
    y
}

fn print_rows(preset: &str, seeds: &[u64], duration: f64) -> Yield {
    let mut total = Yield::default();
    for &seed in seeds {
        let y = measure_with(preset, seed, duration, true);
        println!("{}", y.row(&format!("{preset} seed {seed}")));
        total.add(&y);
    }
    total
}

/// The fast check of one preset: the share matched at least `min_share`, and no
/// accepted match beyond 5 mm / 0.5° of the truth.
fn check(preset: &str, min_share: f64) {
    let y = measure(preset, 1, 20.0);
    println!("{TABLE_HEADER}\n{}", y.row(preset));
    assert!(
        y.overlapping >= 10,
        "{preset}: {} overlapping pairs",
        y.overlapping
    );
    assert!(
        y.share() >= min_share,
        "{preset}: {:.2} of the overlapping pairs matched",
        y.share()
    );
    assert_eq!(
        y.wrong(),
        0,
        "{preset}: accepted matches beyond 5 mm / 0.5°"
    );
}

// Today's matcher accepts matches beyond 5 mm / 0.5° of the truth on mines-rover and
// turtlebot4-rplidar (on these 20 s logs 28 of 43 and 10 of 28 after the basin test;
// most of the rover's within their own covariance: the tables in docs/benchmarks.md),
// so their tests fail on the last assertion and stay ignored: on these lasers, as
// many matches are beyond 5 mm as their own covariances predict
// (`matches_beyond_5_mm_are_no_more_than_their_own_sigma_predict`). The shares
// asserted are main at 4d58c6a's (61 %, 66 %) less a margin.

#[test]
#[ignore = "today's matcher accepts matches beyond 5 mm / 0.5° here (docs/benchmarks.md)"]
fn mines_rover_matches_without_wrong_matches() {
    check("mines-rover", 0.45);
}

/// The Neato's sparse scans go to the sparse matcher (docs/realistic-presets.md). On
/// this 20 s log the robot drives along a wall: its matches are uncertain along it.
/// They are kept with their covariance (calibration needs them:
/// `tests/sparse_calibration.rs`), 13 of the 23 accepted are beyond 5 mm / 0.5°, 2
/// beyond their own covariance, so this test fails on the last assertion, like the
/// other presets'. The share asserted is main's at f505d56 (0 %, when matches with a
/// σ above 3 mm / 0.3° were refused).
#[test]
#[ignore = "matches along a wall are kept with their covariance, beyond 5 mm / 0.5° of the truth (docs/benchmarks.md)"]
fn neato_lds_matches_without_wrong_matches() {
    check("neato-lds", 0.0);
}

#[test]
#[ignore = "today's matcher accepts matches beyond 5 mm / 0.5° here (docs/benchmarks.md)"]
fn turtlebot4_rplidar_matches_without_wrong_matches() {
    check("turtlebot4-rplidar", 0.5);
}

/// What the matcher can promise instead of "none beyond 5 mm / 0.5°" (the three ignored
/// tests above): on these lasers, whose range noise grows with range (σ = 3–6 mm +
/// 0.25–0.5 %·r), a match along a wall or over far points is uncertain by more than
/// 5 mm, and it is kept with that covariance because the calibration needs it
/// (`tests/sparse_calibration.rs`). So the accepted matches beyond 5 mm / 0.5° must be
/// no more than their own covariances predict (the sum over the matches of the chance
/// of such an error under N(0, Σ)), within three Poisson σ and three matches of slack.
/// On the 20 s logs: 19 beyond against 20 predicted (rover), 14 against 9 (Neato), 7
/// against 8 (TurtleBot 4); with every covariance quartered (σ halved), 5 and 3 are
/// predicted on the rover and the Neato and the test fails on both.
#[test]
fn matches_beyond_5_mm_are_no_more_than_their_own_sigma_predict() {
    for preset in REALISTIC_PRESETS {
        let y = measure(preset, 1, 20.0);
        println!("{TABLE_HEADER}\n{}", y.row(preset));
        let predicted = y.predicted_wrong();
        assert!(
            y.wrong() as f64 <= predicted + 3.0 * predicted.sqrt() + 3.0,
            "{preset}: {} accepted matches beyond 5 mm / 0.5°, their covariances predict {predicted:.1}",
            y.wrong()
        );
    }
}

/// The measurement itself sees what it should: on clean presets with a sweeping
/// laser (`pioneer`: a URG-04LX in the plain hall; `turtlebot`: an LDS in the plain
/// office) nearly every pair overlaps, most are matched (the hall's pairs refused
/// are ill-conditioned ones, 8 of 46), and every accepted match is within 5 mm /
/// 0.5° of the truth (RMS 1.2 and 1.7 mm): the truth compared with is right.
#[test]
fn measurement_finds_the_clean_presets_clean() {
    for (preset, min_share) in [("pioneer", 0.75), ("turtlebot", 0.9)] {
        let y = measure(preset, 1, 20.0);
        println!("{TABLE_HEADER}\n{}", y.row(preset));
        assert!(
            y.overlapping as f64 >= 0.9 * y.tried as f64,
            "{preset}: {y:?}"
        );
        assert!(y.share() >= min_share, "{preset}: {:.2}", y.share());
        assert_eq!(y.wrong(), 0, "{preset}: {:?}", y.worst());
        assert!(y.rms().0 < 2.5, "{preset}: {:?}", y.rms());
    }
}

/// People walking past the rover in the hall (`mines-rover`, seed 1, 120 s): where the
/// walls leave the direction along the hall weak, a person's legs drag the iterations
/// along, and the covariance found at the dragged pose does not show it (pair
/// 1008–1012: 182 mm off with a σ of 2.9 mm, NEES 4,721). The matcher now matches such a
/// pair again without the small objects in front of the walls and widens the result's
/// covariance by the difference (`crates/icp/src/small_objects.rs`): the accepted
/// matches' mean NEES was 40.3, and is 11.2 (that pair's σ along the hall 26 mm), the
/// matched share unchanged (94 %).
#[test]
fn people_walking_past_the_rover_do_not_make_its_matches_overconfident() {
    let y = measure("mines-rover", 1, 120.0);
    println!("{TABLE_HEADER}\n{}", y.row("mines-rover seed 1"));
    assert!(y.share() >= 0.9, "{:.2}", y.share());
    assert!(y.mean_nees() < 20.0, "mean NEES {:.1}", y.mean_nees());
}

/// A pair whose cost is flat along the robot's motion is not called determined: on the
/// TurtleBot 4's laser (σ = 3 mm + 0.5 %·r) in the cluttered office (no people, no
/// sweep, no other realism), scans 72 and 75 matched from identity stopped 108 mm
/// short of the truth with a reported σ of 2.7 mm along it (NEES ≈ 1,700; started
/// 30 mm either side of the truth, the iterations stay 30 mm off). The match must be
/// refused, flagged ill-conditioned, or carry a covariance that covers its error.
#[test]
fn a_flat_cost_is_not_called_determined() {
    let mut config = SimConfig::preset("turtlebot4-rplidar").unwrap();
    config.duration = 10.0;
    config.laser.time_increment = 0.0;
    let r = config.laser.realism.as_mut().unwrap();
    (r.half_return_range, r.grazing_angle) = (1e3, 1.5);
    (r.bias_offset, r.bias_quadratic, r.drift) = (0.0, 0.0, 0.0);
    r.mixed_pixel_probability = 0.0;
    let world = World::preset(&config.world).unwrap().with_walkers(vec![]);
    let run = simulate_in(&config, &world).unwrap();
    let scans: Vec<_> = run.logged_scans().collect();
    let angles = run.config.laser.angles();
    let params = odocal_icp::IcpParams {
        typical_noise_sigma: 0.005,
        ..odocal_icp::IcpParams::default()
    };
    let prepare = |i: usize| {
        odocal_icp::PreparedScan::new(
            &scans[i].ranges,
            &angles,
            config.laser.min_range,
            config.laser.max_range,
            &params,
        )
        .unwrap()
    };
    let (a, b) = (72, 75);
    let truth = scans[a].sensor.inverse().compose(&scans[b].sensor);
    assert!(truth.x > 0.08, "the robot drives forward here: {truth}");
    let mut matcher = odocal_icp::Matcher::new(params.clone());
    let Ok(r) = matcher.match_scans(&prepare(a), &prepare(b), Pose2::IDENTITY) else {
        return;
    };
    let d = [
        r.pose.x - truth.x,
        r.pose.y - truth.y,
        odocal_geom::wrap_angle(r.pose.theta - truth.theta),
    ];
    let q = nees(d, &r.covariance);
    assert!(
        r.ill_conditioned || q <= NEES_997,
        "accepted {} against the truth {truth}, σx {:.1} mm, NEES {q:.0}",
        r.pose,
        r.covariance[0][0].sqrt() * 1e3
    );
}

/// A washboard cost is not called precise. On the TurtleBot 4's laser (σ = 3 mm +
/// 0.5 %·r) in the cluttered office, the pair of scans 96 and 99 of seed 1's first
/// 20 s, simulated again 60 times as instantaneous scans at the true mid-sweep poses
/// with fresh noise and matched from the truth: the results scatter 9.9 mm along the
/// robot's motion (centred: mean 3.8 mm of 17), and the covariance said 1.6 mm — the
/// "biased basins" of docs/benchmarks.md, which are not biased. With the cost
/// envelope test (crates/icp/src/cost_envelope.rs) the reported σ must be at least
/// half the scatter.
#[test]
fn a_washboard_cost_is_not_called_precise() {
    use rand::SeedableRng;
    let mut config = SimConfig::preset("turtlebot4-rplidar").unwrap();
    config.duration = 20.0;
    let world = World::preset(&config.world).unwrap();
    let run = simulate_in(&config, &world).unwrap();
    let scans: Vec<_> = run.logged_scans().collect();
    let (a, b) = (&scans[96], &scans[99]);
    let truth = a
        .sensor_at_reference
        .inverse()
        .compose(&b.sensor_at_reference);
    let laser = &config.laser;
    let realism = laser.realism.expect("a realistic preset");
    let angles = laser.angles();
    let params = odocal_icp::IcpParams {
        typical_noise_sigma: 0.005,
        ..odocal_icp::IcpParams::default()
    };
    let mut matcher = odocal_icp::Matcher::new(params.clone());
    let (mut errors, mut reported) = (Vec::new(), Vec::new());
    for seed in 0..60 {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed + 100);
        let mut scan = |pose: &Pose2, t: f64| {
            let ranges = laser.realistic_scan(&realism, &world, &[*pose], t, &mut rng);
            odocal_icp::PreparedScan::new(
                &ranges,
                &angles,
                laser.min_range,
                laser.max_range,
                &params,
            )
        };
        let (Ok(first), Ok(second)) = (
            scan(&a.sensor_at_reference, a.t_true),
            scan(&b.sensor_at_reference, b.t_true),
        ) else {
            continue;
        };
        match matcher.match_scans(&first, &second, truth) {
            Ok(r) if !r.ill_conditioned => {
                errors.push(r.pose.x - truth.x);
                reported.push(r.covariance[0][0]);
            }
            _ => {}
        }
    }
    let n = errors.len();
    assert!(n >= 10, "{n} of 60 draws matched");
    let mean = errors.iter().sum::<f64>() / n as f64;
    let spread = (errors.iter().map(|e| (e - mean).powi(2)).sum::<f64>() / (n - 1) as f64).sqrt();
    let sigma = (reported.iter().sum::<f64>() / n as f64).sqrt();
    println!(
        "{n} matched: scatter along x {:.1} mm (mean {:.1} mm), reported σ {:.1} mm",
        spread * 1e3,
        mean * 1e3,
        sigma * 1e3
    );
    assert!(
        sigma >= 0.5 * spread,
        "reported σ {:.1} mm against a scatter of {:.1} mm",
        sigma * 1e3,
        spread * 1e3
    );
}

/// The accepted matches' covariances on the TurtleBot 4 preset (20 s): before the
/// sandwich covariance and the basin test, their NEES averaged 51 (3 when right) and
/// 52 % were beyond χ²(3)'s 99.7 % level; now 17 and 29 %. Not yet consistent (see
/// docs/benchmarks.md): the bound guards what was gained.
#[test]
fn turtlebot4_covariances_cover_most_errors() {
    let y = measure("turtlebot4-rplidar", 1, 20.0);
    println!("{TABLE_HEADER}\n{}", y.row("turtlebot4-rplidar"));
    assert!(y.nees.len() >= 10, "{} accepted", y.nees.len());
    assert!(y.mean_nees() < 30.0, "mean NEES {:.1}", y.mean_nees());
    assert!(y.nees_beyond() < 0.4, "{:.2} beyond", y.nees_beyond());
}

/// The table of docs/benchmarks.md: 120 s of each realistic preset, three seeds.
#[test]
#[ignore = "heavy (about 20 s): prints the table of docs/benchmarks.md"]
fn realistic_presets_match_table() {
    println!("{TABLE_HEADER}");
    for preset in REALISTIC_PRESETS {
        if std::env::var("ZZ_PRESET").is_ok_and(|p| p != preset) {
            continue;
        }
        let total = print_rows(preset, &[1, 2, 3], 120.0);
        println!("{}", total.row(&format!("**{preset}, 3 seeds**")));
    }
}

/// Which effect of the realistic mode does what to the matcher: each preset (20 s,
/// seed 1) as is, then with one effect taken out, then with only one kept.
#[test]
#[ignore = "diagnostic for the matcher work: prints the ablation table of docs/benchmarks.md"]
fn realistic_effects_ablation() {
    type Change = fn(&mut SimConfig, &mut World);
    fn realism(c: &mut SimConfig) -> &mut RealisticLaser {
        c.laser.realism.as_mut().expect("a realistic preset")
    }
    fn plain_world(c: &mut SimConfig, w: &mut World) {
        let plain = if w.name().starts_with("hall") {
            "hall"
        } else {
            "office"
        };
        *w = World::preset(plain).unwrap();
        c.world = plain.into();
    }
    fn no_fading(c: &mut SimConfig) {
        realism(c).half_return_range = 1e3;
        realism(c).grazing_angle = 1.5;
    }
    fn no_systematic(c: &mut SimConfig) {
        let r = realism(c);
        (r.bias_offset, r.bias_quadratic, r.drift) = (0.0, 0.0, 0.0);
    }
    let variants: [(&str, Change); 9] = [
        ("as is", |_, _| {}),
        ("plain laser (no realism, no people, no glass)", |c, _| {
            c.laser.realism = None
        }),
        ("no people", |_, w| *w = w.clone().with_walkers(vec![])),
        ("plain world (no clutter, glass, people)", plain_world),
        ("no bias, no drift", |c, _| no_systematic(c)),
        ("no mixed pixels", |c, _| {
            realism(c).mixed_pixel_probability = 0.0
        }),
        ("no noise growth with range", |c, _| {
            realism(c).sigma_per_metre = 0.0
        }),
        ("no fading with range and incidence", |c, _| no_fading(c)),
        ("only noise growth (plain world)", |c, w| {
            no_fading(c);
            no_systematic(c);
            realism(c).mixed_pixel_probability = 0.0;
            plain_world(c, w);
        }),
    ];
    println!("{TABLE_HEADER}");
    for preset in REALISTIC_PRESETS {
        for (label, change) in variants {
            let mut config = SimConfig::preset(preset).unwrap();
            config.duration = 20.0;
            let mut world = World::preset(&config.world).unwrap();
            change(&mut config, &mut world);
            let y = measure_in(config, &world, false);
            println!("{}", y.row(&format!("{preset}: {label}")));
        }
    }
}

/// The realistic presets are on the command line: listed, and simulated with their
/// truth file (which names the realistic laser and the cluttered world).
#[test]
fn realistic_presets_are_on_the_command_line() {
    let odocal = env!("CARGO_BIN_EXE_odocal");
    let out = std::process::Command::new(odocal)
        .args(["simulate", "--list-presets"])
        .output()
        .expect("run odocal");
    let listed = String::from_utf8_lossy(&out.stdout);
    let dir = std::env::temp_dir().join(format!("odocal-realistic-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("a temporary directory");
    for preset in REALISTIC_PRESETS {
        assert!(
            listed.lines().any(|l| l == preset),
            "{preset} not in\n{listed}"
        );
        let prefix = dir.join(preset);
        let out = std::process::Command::new(odocal)
            .args(["simulate", "--preset", preset, "--duration", "2", "--out"])
            .arg(&prefix)
            .output()
            .expect("run odocal");
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let truth = std::fs::read_to_string(prefix.with_extension("truth.json")).unwrap();
        let truth: serde_json::Value = serde_json::from_str(&truth).unwrap();
        assert!(truth["config"]["laser"]["realism"].is_object(), "{preset}");
        assert!(truth["world"].as_str().unwrap().ends_with("-cluttered"));
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// Pairs of sparse scans refused when matched alone are matched again with each scan
/// densified by the scan beyond it (or two), placed by odometry
/// (`odocal_pipeline::local_map`).
/// On this 20 s Neato log 9 pairs are (of 27 matched), 5 of them beyond 5 mm / 0.5° of
/// the truth where their own covariances predict 3: within the slack of
/// `matches_beyond_5_mm_are_no_more_than_their_own_sigma_predict`.
#[test]
fn sparse_pairs_refused_alone_are_matched_with_their_neighbouring_scans() {
    let y = measure("neato-lds", 5, 20.0);
    println!("{TABLE_HEADER}\n{}", y.row("neato-lds seed 5"));
    let (matched, wrong, predicted) = y.neighboured_wrong();
    assert!(
        matched >= 5,
        "{matched} pairs matched with their neighbours"
    );
    assert!(
        wrong as f64 <= predicted + 3.0 * predicted.sqrt() + 3.0,
        "{wrong} of them beyond 5 mm / 0.5°, their covariances predict {predicted:.1}"
    );
}

/// Scans of a few dozen returns or fewer (the Neato's first 20 s of seed 7): a cloud
/// of such a scan and the one beyond it holds too few points, so it takes the next
/// one too (`odocal_pipeline::local_map::CLOUD_POINTS`), and a scan of fewer returns
/// than a scan matched alone needs is matched in its cloud (`MIN_OWN_POINTS`). Here
/// 42 of 48 overlapping pairs are matched (main at bd38436: 37), 11 with their
/// neighbours (6), 7 of those beyond 5 mm / 0.5° where their covariances predict 4.
#[test]
fn scans_of_few_returns_take_a_second_neighbour() {
    let y = measure("neato-lds", 7, 20.0);
    println!("{TABLE_HEADER}\n{}", y.row("neato-lds seed 7"));
    assert!(
        y.share() >= 0.85,
        "{:.2} of the overlapping pairs",
        y.share()
    );
    assert!(
        y.neighboured.iter().any(|&n| n > 2),
        "no cloud took two neighbours on a side: {:?}",
        y.neighboured
    );
    let (_, wrong, predicted) = y.neighboured_wrong();
    assert!(
        wrong as f64 <= predicted + 3.0 * predicted.sqrt() + 3.0,
        "{wrong} beyond 5 mm / 0.5°, their covariances predict {predicted:.1}"
    );
}

/// The second pass matches every pair again from odometry with the first estimate,
/// within the error that odometry can have (`odocal_pipeline::guess_window`). On the
/// Neato's seed 2 (120 s) the first pass accepts matches 250–300 mm from the truth,
/// from guesses of 9–22 mm: a structure repeated about 0.3 m on explains these sparse
/// scans better than their true alignment. Main's second pass (bd38436) kept one,
/// 297 mm off, among the samples it calibrated with; the calibration must use none
/// beyond what the floor of the window (50 mm) allows.
#[test]
fn the_second_pass_keeps_no_alignment_odometry_cannot_explain() {
    let y = measure_with("neato-lds", 2, 120.0, true);
    println!("{TABLE_HEADER}\n{}", y.row("neato-lds seed 2"));
    assert!(
        y.final_errors.len() >= 200,
        "{} samples",
        y.final_errors.len()
    );
    let (d, a) = worst(&y.final_errors);
    assert!(
        d < 0.05 && a < 2f64.to_radians(),
        "a sample {:.1} mm / {:.2}° from the truth",
        1e3 * d,
        a.to_degrees()
    );
}

/// Issue 20's yield on sparse scans, on the Neato's hardest log of the table (seed 2,
/// 120 s: a quarter of its scans hold 10–29 returns). The calibration's samples hold
/// at least 85 % of the pairs whose true overlap is half a scan or more: 76 % when a
/// cloud's match had to explain 40 % of its own points, 88 % at 25 % within the
/// window of its guess (`odocal_pipeline::local_map`, docs/benchmarks.md, stop 49).
/// And no pair of the first pass matched with its neighbouring scans lies farther
/// from the truth than that window allows: without it, one was 297 mm off along a
/// wall, guessed by odometry with the bootstrap's estimate.
#[test]
fn sparse_scans_are_matched_nine_in_ten_within_the_window_of_their_guess() {
    let y = measure_with("neato-lds", 2, 120.0, true);
    println!("{TABLE_HEADER}\n{}", y.row("neato-lds seed 2"));
    assert!(
        y.final_share() >= 0.85,
        "{} of {} overlapping pairs among the samples",
        y.final_overlapping_matched,
        y.overlapping
    );
    let clouds: Vec<(f64, f64)> = y
        .errors
        .iter()
        .zip(&y.neighboured)
        .filter(|(_, &n)| n > 0)
        .map(|(e, _)| *e)
        .collect();
    let (d, a) = worst(&clouds);
    assert!(
        clouds.len() >= 100 && d < 0.1 && a < 3f64.to_radians(),
        "{} clouds matched, the worst {:.1} mm / {:.2}° from the truth",
        clouds.len(),
        1e3 * d,
        a.to_degrees()
    );
}

/// Runs the binary with `args`; its standard output (the run must succeed).
fn run_odocal(args: &[&str]) -> String {
    let o = common::odocal(args);
    assert!(o.status.success(), "{}", common::stderr(&o));
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// A 20 s `neato-lds` log of `seed` calibrated (`--accept-weak`) through the binary
/// in a temporary directory named after `tag`: the directory, the output directory,
/// the summary and `results.json`.
fn neato_calibration(
    tag: &str,
    seed: u64,
) -> (
    std::path::PathBuf,
    std::path::PathBuf,
    String,
    serde_json::Value,
) {
    let dir = common::temp_dir(tag);
    let prefix = dir.join("neato");
    let out = dir.join("out");
    let log = prefix.with_extension("log");
    run_odocal(&[
        "simulate",
        "--preset",
        "neato-lds",
        "--seed",
        &seed.to_string(),
        "--duration",
        "20",
        "--out",
        prefix.to_str().unwrap(),
    ]);
    let summary = run_odocal(&[
        "calibrate",
        "--accept-weak",
        "--out",
        out.to_str().unwrap(),
        log.to_str().unwrap(),
    ]);
    let results =
        serde_json::from_str(&std::fs::read_to_string(out.join("results.json")).unwrap()).unwrap();
    (dir, out, summary, results)
}

/// The pairs matched with their neighbouring scans are reported alike in the
/// summary, `results.json` (`neighbour_matches`) and the tuples (`icp_neighbours`),
/// and the summary says how many scans densified each one.
#[test]
fn pairs_matched_with_their_neighbouring_scans_are_reported_in_every_output() {
    let (dir, out, summary, results) = neato_calibration("neighbours", 5);
    let n = results["neighbour_matches"].as_u64().unwrap();
    assert!(n > 0, "{summary}");
    let tuples = std::fs::read_to_string(out.join("samples.tuple")).unwrap();
    let in_tuples = tuples
        .lines()
        .filter(|l| {
            let t: serde_json::Value = serde_json::from_str(l).unwrap();
            t["icp_neighbours"].as_u64().unwrap_or(0) > 0
        })
        .count() as u64;
    assert_eq!(in_tuples, n);
    let line = format!("matched with their neighbouring scans: {n} pairs");
    assert!(summary.contains(&line), "{summary}");
    assert!(
        summary.contains("densified by the scan beyond it"),
        "{summary}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// The pairs matched along a corridor (one direction left free) are reported alike
/// in the summary, `results.json` (`free_direction_matches`) and the tuples
/// (`free_direction`), and `odocal solve` honours the tuples' free directions: the
/// free samples' ŝ moved 5 cm along them give the same estimate.
#[test]
fn pairs_matched_along_a_corridor_are_reported_and_solved_alike() {
    // Seed 1 drives along a wall.
    let (dir, out, summary, results) = neato_calibration("corridor", 1);
    let n = results["free_direction_matches"].as_u64().unwrap();
    assert!(n > 0, "{summary}");
    assert!(
        summary.contains(&format!("matched along a corridor: {n} pairs")),
        "{summary}"
    );
    let tuples = out.join("samples.tuple");
    let records: Vec<serde_json::Value> = std::fs::read_to_string(&tuples)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    let free = records
        .iter()
        .filter(|t| t["free_direction"].is_array())
        .count() as u64;
    assert_eq!(free, n);
    // The free samples' ŝ moved 5 cm along their free direction.
    let moved: Vec<String> = records
        .iter()
        .map(|t| {
            let mut t = t.clone();
            if let Some(d) = t["free_direction"].as_array().cloned() {
                let d: Vec<f64> = d.iter().map(|v| v.as_f64().unwrap()).collect();
                let norm = d.iter().map(|v| v * v).sum::<f64>().sqrt();
                for (c, v) in d.iter().enumerate() {
                    let sm = t["sm"][c].as_f64().unwrap();
                    t["sm"][c] = (sm + 0.05 * v / norm).into();
                }
            }
            t.to_string()
        })
        .collect();
    let moved_path = dir.join("moved.tuple");
    std::fs::write(&moved_path, moved.join("\n")).unwrap();
    let solve = |path: &std::path::Path| -> serde_json::Value {
        serde_json::from_str(&run_odocal(&["solve", "--json", path.to_str().unwrap()])).unwrap()
    };
    let (a, b) = (solve(&tuples), solve(&moved_path));
    for key in ["r_l", "r_r", "b", "l_x", "l_y", "l_theta"] {
        let (x, y) = (a[key].as_f64().unwrap(), b[key].as_f64().unwrap());
        assert!(
            (x - y).abs() <= 1e-9 * x.abs().max(0.1),
            "{key}: {x} and {y}"
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}
