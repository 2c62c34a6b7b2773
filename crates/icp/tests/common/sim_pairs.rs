//! Scan pairs of a simulated run matched from an odometry-like first guess: the
//! procedure of `tests/sim_accuracy.rs`, shared with `tests/cramer_rao.rs` so that
//! both measure the matcher on exactly the same pairs, guesses and parameters.
//! Include with `#[path = "common/sim_pairs.rs"] mod sim_pairs;`.
#![allow(dead_code)]

use odocal_geom::{wrap_angle, Pose2};
use odocal_icp::{IcpParams, Matcher, PreparedScan};
use odocal_sim::{simulate, PresetRegistry, SimRun};
use rand::{rngs::StdRng, SeedableRng};
use rand_distr::{Distribution, Normal};

/// Seconds of driving simulated per preset.
pub const DURATION_S: f64 = 40.0;

/// The pair gaps (in scans) measured, with their labels: consecutive scans at 10 Hz
/// and scans 0.4 s apart.
pub const GAPS: [(usize, &str); 2] = [(1, "10 Hz"), (4, "0.4 s")];

/// The seed of the first-guess draws for the pairs `gap` scans apart.
pub fn guess_seed(gap: usize) -> u64 {
    7 + gap as u64
}

/// 40 s of the preset's driving; `correlation_rays` replaces the laser's noise
/// correlation length and `seed` the simulation seed (trajectory and noise) when given.
pub fn simulate_preset(preset: &str, correlation_rays: Option<usize>, seed: Option<u64>) -> SimRun {
    let mut config = PresetRegistry::builtin().get(preset).expect("preset");
    config.duration = DURATION_S;
    if let Some(seed) = seed {
        config.seed = seed;
    }
    if let Some(rays) = correlation_rays {
        config.laser.correlation_rays = rays;
    }
    simulate(&config).expect("simulation")
}

/// A first guess like odometry's: the truth off by 5 % of the motion plus 2 mm / 0.3°.
pub fn first_guess(truth: &Pose2, rng: &mut StdRng) -> Pose2 {
    let unit = Normal::new(0.0, 1.0).expect("unit normal");
    let sxy = 0.05 * truth.translation_norm() + 0.002;
    let sth = 0.05 * truth.theta.abs() + 0.3f64.to_radians();
    Pose2::new(
        truth.x + sxy * unit.sample(rng),
        truth.y + sxy * unit.sample(rng),
        truth.theta + sth * unit.sample(rng),
    )
}

/// What matching one pair gave.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PairOutcome {
    /// A result not flagged ill-conditioned: the estimate.
    Matched(Pose2),
    /// A result flagged ill-conditioned (not to be trusted by the caller).
    IllConditioned,
    /// The match failed.
    Failed,
}

/// One pair: scans `first` and `first + gap`, the true displacement of the sensor
/// (second pose in the first's frame) and the outcome.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MatchedPair {
    /// Index of the first scan in `SimRun::scans`.
    pub first: usize,
    /// Index of the second scan.
    pub second: usize,
    /// True displacement.
    pub truth: Pose2,
    /// What the matcher gave.
    pub outcome: PairOutcome,
}

impl MatchedPair {
    /// Error of `estimate` (x, y, wrapped θ).
    pub fn error_of(&self, estimate: &Pose2) -> [f64; 3] {
        [
            estimate.x - self.truth.x,
            estimate.y - self.truth.y,
            wrap_angle(estimate.theta - self.truth.theta),
        ]
    }

    /// Error of the estimate, when matched.
    pub fn error(&self) -> Option<[f64; 3]> {
        match self.outcome {
            PairOutcome::Matched(estimate) => Some(self.error_of(&estimate)),
            _ => None,
        }
    }
}

/// Matches every pair `gap` scans apart with the default parameters, from
/// [`first_guess`] drawn with `guess_seed` (one draw per pair, in order). Failures
/// are printed to stderr.
pub fn match_pairs(run: &SimRun, gap: usize, guess_seed: u64) -> Vec<MatchedPair> {
    let params = IcpParams::default();
    let angles = run.config.laser.angles();
    let (min_r, max_r) = (run.config.laser.min_range, run.config.laser.max_range);
    let prepared: Vec<PreparedScan> = run
        .scans
        .iter()
        .map(|s| PreparedScan::new(&s.ranges, &angles, min_r, max_r, &params).expect("scan"))
        .collect();
    let mut matcher = Matcher::new(params);
    let mut rng = StdRng::seed_from_u64(guess_seed);
    let mut pairs = Vec::with_capacity(run.scans.len().saturating_sub(gap));
    for k in 0..run.scans.len() - gap {
        let truth = run.scans[k].sensor.between(&run.scans[k + gap].sensor);
        let guess = first_guess(&truth, &mut rng);
        let outcome = match matcher.match_scans(&prepared[k], &prepared[k + gap], guess) {
            Ok(r) if r.ill_conditioned => PairOutcome::IllConditioned,
            Ok(r) => PairOutcome::Matched(r.pose),
            Err(e) => {
                eprintln!("pair {k}+{gap}: {e}");
                PairOutcome::Failed
            }
        };
        pairs.push(MatchedPair {
            first: k,
            second: k + gap,
            truth,
            outcome,
        });
    }
    pairs
}

/// Root mean square.
pub fn rms(v: &[f64]) -> f64 {
    (v.iter().map(|e| e * e).sum::<f64>() / v.len() as f64).sqrt()
}

/// 99th percentile of the absolute values.
pub fn p99(v: &[f64]) -> f64 {
    let mut a: Vec<f64> = v.iter().map(|e| e.abs()).collect();
    a.sort_by(f64::total_cmp);
    a[((0.99 * a.len() as f64).ceil() as usize).clamp(1, a.len()) - 1]
}
