//! Basin of convergence of the matcher: simulated scan pairs matched from first
//! guesses off the truth by a grid of translations (up to 0.25 m, 8 directions) and
//! rotations (up to ±45°). Every match must end in one of two ways: the truth
//! (within [`CORRECT_XY`] and [`CORRECT_THETA_DEG`]) or a failure with a reason (an
//! error, or a result flagged ill-conditioned); anything else is a false accept.
//! Shared by `tests/basin.rs` and `examples/basin.rs`: include with
//! `#[path = "common/basin.rs"] mod basin;`.
#![allow(dead_code)]

use odocal_geom::{wrap_angle, Pose2};
use odocal_icp::{IcpParams, Matcher, PreparedScan};
use odocal_sim::{simulate, PresetRegistry, SimRun};

/// A result this close to the truth has converged (m) …
pub const CORRECT_XY: f64 = 0.005;
/// … and (°). About ten times the matcher's RMS error on these pairs.
pub const CORRECT_THETA_DEG: f64 = 0.25;

/// Translation errors of the first guess (m), each in 8 directions (0 once).
pub const TRANSLATIONS: [f64; 4] = [0.0, 0.1, 0.18, 0.25];
/// Rotation errors of the first guess (°).
pub const ROTATIONS_DEG: [f64; 7] = [-45.0, -30.0, -15.0, 0.0, 15.0, 30.0, 45.0];

/// How one match ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Verdict {
    /// The truth.
    Converged,
    /// An error: refused with a reason.
    Refused,
    /// A result flagged ill-conditioned (not to be used: the caller refuses it).
    IllConditioned,
    /// A result away from the truth, not flagged: the outcome that must not happen.
    FalseAccept,
}

/// Tally of verdicts.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Tally {
    /// Matches that reached the truth.
    pub converged: usize,
    /// Matches refused with a reason.
    pub refused: usize,
    /// Results flagged ill-conditioned.
    pub ill_conditioned: usize,
    /// Wrong results not flagged.
    pub false_accepts: usize,
}

impl Tally {
    /// Counts one verdict.
    pub fn add(&mut self, v: Verdict) {
        match v {
            Verdict::Converged => self.converged += 1,
            Verdict::Refused => self.refused += 1,
            Verdict::IllConditioned => self.ill_conditioned += 1,
            Verdict::FalseAccept => self.false_accepts += 1,
        }
    }

    /// Matches counted.
    pub fn total(&self) -> usize {
        self.converged + self.refused + self.ill_conditioned + self.false_accepts
    }

    /// Adds another tally.
    pub fn merge(&mut self, other: &Tally) {
        self.converged += other.converged;
        self.refused += other.refused;
        self.ill_conditioned += other.ill_conditioned;
        self.false_accepts += other.false_accepts;
    }
}

/// `seconds` of a preset's driving with `seed`.
pub fn simulate_preset(preset: &str, seconds: f64, seed: u64) -> SimRun {
    let mut config = PresetRegistry::builtin().get(preset).expect("preset");
    config.duration = seconds;
    config.seed = seed;
    simulate(&config).expect("simulation")
}

/// Every scan of the run prepared with `params`.
pub fn prepare(run: &SimRun, params: &IcpParams) -> Vec<PreparedScan> {
    let angles = run.config.laser.angles();
    let (lo, hi) = (run.config.laser.min_range, run.config.laser.max_range);
    run.scans
        .iter()
        .map(|s| PreparedScan::new(&s.ranges, &angles, lo, hi, params).expect("scan"))
        .collect()
}

/// The first-guess errors of the grid: `(dx, dy, dθ)` (m, m, rad).
pub fn guess_errors() -> Vec<(f64, [f64; 3])> {
    let mut out = Vec::new();
    for &t in &TRANSLATIONS {
        let directions = if t == 0.0 { 1 } else { 8 };
        for d in 0..directions {
            let a = d as f64 * std::f64::consts::FRAC_PI_4;
            for &r in &ROTATIONS_DEG {
                out.push((t, [t * a.cos(), t * a.sin(), r.to_radians()]));
            }
        }
    }
    out
}

/// The verdict on matching `current` against `reference` from `guess`.
pub fn verdict(
    matcher: &mut Matcher,
    reference: &PreparedScan,
    current: &PreparedScan,
    truth: &Pose2,
    guess: Pose2,
) -> Verdict {
    match matcher.match_scans(reference, current, guess) {
        Err(_) => Verdict::Refused,
        Ok(r) if r.ill_conditioned => Verdict::IllConditioned,
        Ok(r) => {
            let exy = (r.pose.x - truth.x).hypot(r.pose.y - truth.y);
            let eth = wrap_angle(r.pose.theta - truth.theta).abs().to_degrees();
            if exy <= CORRECT_XY && eth <= CORRECT_THETA_DEG {
                Verdict::Converged
            } else {
                Verdict::FalseAccept
            }
        }
    }
}

/// The pairs `(k, k + gap)` for every `every`-th k.
pub fn pairs(run: &SimRun, gap: usize, every: usize) -> Vec<(usize, usize, Pose2)> {
    (0..run.scans.len().saturating_sub(gap))
        .step_by(every)
        .map(|k| {
            let truth = run.scans[k].sensor.between(&run.scans[k + gap].sensor);
            (k, k + gap, truth)
        })
        .collect()
}

/// Tallies per (translation error, rotation error) cell of the grid, over the pairs.
pub fn basin(
    scans: &[PreparedScan],
    pairs: &[(usize, usize, Pose2)],
    params: &IcpParams,
) -> Vec<((f64, f64), Tally)> {
    let mut matcher = Matcher::new(params.clone());
    let mut cells: Vec<((f64, f64), Tally)> = Vec::new();
    for (t, [dx, dy, dth]) in guess_errors() {
        let key = (t, dth.to_degrees().round());
        let at = match cells.iter().position(|(k, _)| *k == key) {
            Some(i) => i,
            None => {
                cells.push((key, Tally::default()));
                cells.len() - 1
            }
        };
        for &(a, b, truth) in pairs {
            let guess = Pose2::new(truth.x + dx, truth.y + dy, truth.theta + dth);
            let v = verdict(&mut matcher, &scans[a], &scans[b], &truth, guess);
            cells[at].1.add(v);
        }
    }
    cells
}
