//! The matcher against the Cramér–Rao bound (CRB): on the pairs of
//! `tests/sim_accuracy.rs` (40 s of a preset's driving, pairs 1 and 4 scans apart,
//! the same first guesses and parameters), the bound of each pair's displacement with
//! the walls unknown (see `common/cramer_rao_bound.rs`) against the matcher's errors.
//!
//! Reported per case, each floor being `sqrt(mean over pairs of a variance)` of x, y
//! and θ:
//! - the CRB floor (all readable rays): no unbiased estimator does better;
//! - the CRB floor without the grazing rays (incidence cosine below the matcher's
//!   `min_incidence_cos`, the floor of the cosine in its weights): a diagnostic of
//!   how much of the bound comes from rays the matcher weighs less than their worth;
//! - the least-squares floor: the covariance of ordinary least squares on all rays
//!   (walls unknown), i.e. of the best estimator that takes the range noise as
//!   independent — the same as the CRB for independent noise;
//! - the RMS errors of an oracle that knows which wall line each ray reads (not
//!   where the lines are) and fits the pose and the lines to the ranges by
//!   generalised least squares (GLS: weighed by the noise covariance) and by ordinary
//!   least squares (OLS): the GLS oracle reaching the CRB floor shows the bound is
//!   attainable on the simulated data, rounding and all;
//! - the matcher's RMS error on the same pairs, its ratio to the CRB floor (its
//!   distance from an efficient estimator) and to the least-squares floor;
//! - the mean over pairs of `eᵀ CRB⁻¹ e` (3 for an efficient estimator, more for a
//!   less precise one).
//!
//! `cargo test --release -p odocal-icp --test cramer_rao -- --nocapture`
//! (`--include-ignored` for simulation seeds 2 and 3 and the bound's sensitivity to
//! the white part of the noise).

#[path = "common/cramer_rao_bound.rs"]
mod cramer_rao_bound;
#[path = "common/sim_pairs.rs"]
mod sim_pairs;

use cramer_rao_bound::{
    oracle_estimate, pair_bound, wall_hits, RangeNoise, WallHit, WallLines, Weighting,
};
use nalgebra::{Matrix3, Vector3};
use odocal_icp::IcpParams;
use odocal_sim::SimRun;
use sim_pairs::{guess_seed, match_pairs, simulate_preset, GAPS};

/// Issue 3's RMS targets: x and y (m), θ (rad).
const TARGETS: [f64; 3] = [0.5e-3, 0.5e-3, 0.02 * std::f64::consts::PI / 180.0];

/// The floors and the matcher's errors over the pairs of one case.
struct Comparison {
    label: String,
    /// Whether the sensor's noise is correlated between rays.
    correlated: bool,
    /// Pairs matched and bounded (ill-conditioned results and failures left out).
    pairs: usize,
    /// Pairs left out.
    left_out: usize,
    /// CRB floor per coordinate (m, m, rad).
    floor: [f64; 3],
    /// CRB floor without the grazing rays.
    floor_without_grazing: [f64; 3],
    /// Floor of ordinary least squares (noise taken as independent).
    floor_least_squares: [f64; 3],
    /// The matcher's RMS error per coordinate (m, m, rad).
    measured: [f64; 3],
    /// RMS error of the oracle (knows which line each ray reads) weighing by the
    /// noise covariance, and weighing equally.
    oracle: [[f64; 3]; 2],
    /// Mean of `eᵀ CRB⁻¹ e`.
    nees: f64,
    /// Largest range mismatch of the bound's model at the truth (m).
    max_range_mismatch: f64,
    /// Mean number of lines read by both scans of a pair.
    mean_shared_lines: f64,
}

/// `[x (mm), y (mm), θ (°)]` of a `[m, m, rad]` triple, for printing.
fn mm_mm_deg(v: [f64; 3]) -> String {
    format!(
        "{:.3} / {:.3} mm, {:.4}°",
        v[0] * 1e3,
        v[1] * 1e3,
        v[2].to_degrees()
    )
}

impl Comparison {
    /// Measured RMS / CRB floor per coordinate.
    fn ratio(&self) -> [f64; 3] {
        [0, 1, 2].map(|k| self.measured[k] / self.floor[k])
    }

    /// Measured RMS / least-squares floor per coordinate.
    fn ratio_least_squares(&self) -> [f64; 3] {
        [0, 1, 2].map(|k| self.measured[k] / self.floor_least_squares[k])
    }

    fn print(&self) {
        let [rx, ry, rt] = self.ratio();
        let [lx, ly, lt] = self.ratio_least_squares();
        println!(
            "{}: {} pairs ({} left out), {:.1} lines seen by both scans\n  CRB floor {} | CRB without grazing rays {} | least squares {}\n  oracle GLS {} | oracle OLS {}\n  measured {} | measured/CRB {rx:.2} {ry:.2} {rt:.2} | measured/LS {lx:.2} {ly:.2} {lt:.2} | mean eᵀ CRB⁻¹ e {:.2}",
            self.label,
            self.pairs,
            self.left_out,
            self.mean_shared_lines,
            mm_mm_deg(self.floor),
            mm_mm_deg(self.floor_without_grazing),
            mm_mm_deg(self.floor_least_squares),
            mm_mm_deg(self.oracle[0]),
            mm_mm_deg(self.oracle[1]),
            mm_mm_deg(self.measured),
            self.nees
        );
    }
}

/// The pairs `gap` scans apart of `run`, matched as in `sim_accuracy` and bounded
/// with the noise model `noise`.
fn compare(run: &SimRun, gap: usize, label: String, noise: &RangeNoise) -> Comparison {
    let laser = &run.config.laser;
    let lines = WallLines::of(&run.world);
    let angles = laser.angles();
    let min_incidence_cos = IcpParams::default().min_incidence_cos;
    let hits: Vec<Vec<WallHit>> = run
        .scans
        .iter()
        .map(|s| wall_hits(&run.world, &lines, laser, &s.sensor, &s.ranges))
        .collect();
    let not_grazing: Vec<Vec<WallHit>> = hits
        .iter()
        .map(|h| {
            h.iter()
                .filter(|h| h.incidence_cos >= min_incidence_cos)
                .copied()
                .collect()
        })
        .collect();
    let bound = |i: usize, j: usize, hits: &[Vec<WallHit>]| {
        pair_bound(
            &lines,
            noise,
            &angles,
            (&run.scans[i].sensor, &hits[i]),
            (&run.scans[j].sensor, &hits[j]),
        )
        .unwrap_or_else(|| panic!("{label}: pair {i}+{gap} has no bound"))
    };
    let mut variances = [Matrix3::zeros(); 3];
    let mut squared_errors = Vector3::zeros();
    let mut oracle_squared_errors = [Vector3::zeros(); 2];
    let (mut pairs, mut left_out, mut nees, mut mismatch, mut shared) = (0, 0, 0.0, 0.0f64, 0);
    for pair in match_pairs(run, gap, guess_seed(gap)) {
        let Some(e) = pair.error() else {
            left_out += 1;
            continue;
        };
        let e = Vector3::from(e);
        let (all, without_grazing) = (
            bound(pair.first, pair.second, &hits),
            bound(pair.first, pair.second, &not_grazing),
        );
        variances[0] += all.covariance;
        variances[1] += without_grazing.covariance;
        variances[2] += all.least_squares_covariance;
        squared_errors += e.component_mul(&e);
        for (sum, weighting) in oracle_squared_errors
            .iter_mut()
            .zip([Weighting::Covariance, Weighting::Equal])
        {
            let (i, j) = (pair.first, pair.second);
            let estimate = oracle_estimate(
                &lines,
                noise,
                &angles,
                (&run.scans[i].sensor, &hits[i], &run.scans[i].ranges),
                (&run.scans[j].sensor, &hits[j], &run.scans[j].ranges),
                weighting,
            )
            .unwrap_or_else(|| panic!("{label}: pair {i}+{gap}: oracle failed"));
            let e = Vector3::from(pair.error_of(&estimate));
            *sum += e.component_mul(&e);
        }
        nees += e.dot(&(all.information * e));
        mismatch = mismatch.max(all.max_range_mismatch);
        shared += all.shared_lines;
        pairs += 1;
    }
    let n = pairs as f64;
    let floor = |m: &Matrix3<f64>| [0, 1, 2].map(|k| (m[(k, k)] / n).sqrt());
    Comparison {
        correlated: noise.correlation_rays > 1,
        pairs,
        left_out,
        floor: floor(&variances[0]),
        floor_without_grazing: floor(&variances[1]),
        floor_least_squares: floor(&variances[2]),
        measured: [0, 1, 2].map(|k| (squared_errors[k] / n).sqrt()),
        oracle: oracle_squared_errors.map(|s| [0, 1, 2].map(|k| (s[k] / n).sqrt())),
        nees: nees / n,
        max_range_mismatch: mismatch,
        mean_shared_lines: shared as f64 / n,
        label,
    }
}

/// Every gap of 40 s of the preset's driving (see `sim_pairs::simulate_preset`),
/// bounded with the simulated laser's own noise model.
fn comparisons(
    noise: &str,
    preset: &str,
    correlation_rays: Option<usize>,
    seed: Option<u64>,
) -> Vec<Comparison> {
    let run = simulate_preset(preset, correlation_rays, seed);
    let model = RangeNoise::of(&run.config.laser);
    GAPS.iter()
        .map(|&(gap, label)| {
            let label = format!("{noise} {preset} seed {} {label}", run.config.seed);
            let c = compare(&run, gap, label, &model);
            c.print();
            c
        })
        .collect()
}

/// How far above the CRB floor the matcher may be, per coordinate: measured on the
/// preset seed and seeds 2 and 3 (docs/benchmarks.md, icp, Accuracy), the matcher is
/// at 1.04–1.22 × the floor with independent noise and 1.17–1.65 × with the default
/// correlated noise (the matcher treats the noise as independent: it is at
/// 0.99–1.14 × the least-squares floor, which is itself 1.09–1.54 × the CRB there).
/// The limits leave about 15 % to those worst ratios.
fn efficiency_limit(correlated: bool) -> f64 {
    if correlated {
        1.9
    } else {
        1.4
    }
}

/// How far above the least-squares floor (the best estimator that takes the noise
/// as independent) the matcher may be on the correlated-noise sensor: measured
/// 0.99–1.14 ×, limit with about 15 % to spare. (With independent noise that floor
/// is the CRB floor, see [`efficiency_limit`].)
const LEAST_SQUARES_LIMIT: f64 = 1.3;

/// The GLS oracle's RMS error / CRB floor, measured 0.92–1.10 on the preset seed and
/// seeds 2 and 3 (the spread of an RMS over a few hundred correlated pairs): it must
/// stay within these, i.e. the bound is a bound and is reached.
const ORACLE_RATIO: std::ops::RangeInclusive<f64> = 0.85..=1.15;

/// Physics, not tuning: no unbiased estimator beats the bound (so the measured RMS
/// is at least the floor, up to the sampling spread of a few hundred correlated
/// pairs: 0.9×), an estimator that models the noise reaches it ([`ORACLE_RATIO`]),
/// and the matcher stays near it (see [`efficiency_limit`]).
fn check(c: &Comparison) {
    assert!(c.pairs > 350, "{}: only {} pairs", c.label, c.pairs);
    assert!(
        c.max_range_mismatch < 1e-9,
        "{}: the bound's ranges differ from the ray casts by {} m",
        c.label,
        c.max_range_mismatch
    );
    let limit = efficiency_limit(c.correlated);
    for (k, axis) in ["x", "y", "θ"].iter().enumerate() {
        let (ratio, ratio_ls) = (c.ratio()[k], c.ratio_least_squares()[k]);
        let oracle = c.oracle[0][k] / c.floor[k];
        assert!(
            ORACLE_RATIO.contains(&oracle),
            "{} {axis}: the GLS oracle's RMS {:.3e} is {oracle:.2} × the CRB floor {:.3e}",
            c.label,
            c.oracle[0][k],
            c.floor[k]
        );
        assert!(
            ratio >= 0.9,
            "{} {axis}: measured RMS {:.3e} below 0.9 × the CRB floor {:.3e}",
            c.label,
            c.measured[k],
            c.floor[k]
        );
        assert!(
            ratio <= limit,
            "{} {axis}: measured RMS {:.3e} is {ratio:.2} × the CRB floor {:.3e} (> {limit})",
            c.label,
            c.measured[k],
            c.floor[k]
        );
        assert!(
            !c.correlated || ratio_ls <= LEAST_SQUARES_LIMIT,
            "{} {axis}: measured RMS {:.3e} is {ratio_ls:.2} × the least-squares floor {:.3e}",
            c.label,
            c.measured[k],
            c.floor_least_squares[k]
        );
    }
    assert!(
        c.nees >= 0.9 * 3.0,
        "{}: mean eᵀ CRB⁻¹ e {:.2} below 3",
        c.label,
        c.nees
    );
}

/// Khepera arena, default sensor (noise correlated over 4 rays) and independent noise.
#[test]
fn arena_matcher_is_near_the_cramer_rao_floor() {
    let mut all = comparisons("correlated", "khepera", None, None);
    all.extend(comparisons("white", "khepera", Some(1), None));
    all.iter().for_each(check);
}

/// Office, default sensor (noise correlated over 4 rays) and independent noise.
#[test]
fn office_matcher_is_near_the_cramer_rao_floor() {
    let mut all = comparisons("correlated", "office", None, None);
    all.extend(comparisons("white", "office", Some(1), None));
    all.iter().for_each(check);
}

/// Simulation seeds 2 and 3 of the default sensor: the floors against issue 3's
/// targets (printed: which targets lie below a floor — unreachable for an estimator
/// of that class on that trajectory), and the same checks.
#[test]
#[ignore = "four more simulations; run with --include-ignored"]
fn other_seeds_floor_against_the_targets() {
    let mut all = vec![];
    for seed in [2, 3] {
        for preset in ["khepera", "office"] {
            all.extend(comparisons("correlated", preset, None, Some(seed)));
        }
    }
    for c in &all {
        let above = |floor: [f64; 3]| -> Vec<&str> {
            ["x", "y", "θ"]
                .into_iter()
                .enumerate()
                .filter(|&(k, _)| floor[k] > TARGETS[k])
                .map(|(_, axis)| axis)
                .collect()
        };
        println!(
            "{}: targets below the CRB floor in {:?}, below the least-squares floor in {:?}",
            c.label,
            above(c.floor),
            above(c.floor_least_squares)
        );
    }
    all.iter().for_each(check);
}

/// The default sensor's noise is a moving sum of 4 white values, whose spectrum is
/// zero at 1/4 and 1/2 of the ray rate; only the 1 mm rounding (variance 1/12 mm²
/// against σ² = 9 mm²) fills those zeros. An estimator knowing this exactly can read
/// the noise almost without error in those directions, where the ends of each wall's
/// run of rays put some of the pose signal: that is much of the gap between the CRB
/// and least squares. This prints the CRB floor with a larger white part (the
/// rounding variance of 2 and 4 mm steps in the bound only; the data are unchanged),
/// and checks that the bound grows with it and stays below least squares.
#[test]
#[ignore = "sensitivity study; run with --include-ignored"]
fn floor_rests_on_the_white_part_of_the_correlated_noise() {
    for preset in ["khepera", "office"] {
        let run = simulate_preset(preset, None, None);
        let (gap, label) = GAPS[0];
        let model = RangeNoise::of(&run.config.laser);
        let mut previous = [0.0; 3];
        for step in [model.quantization, 0.002, 0.004] {
            let noise = RangeNoise {
                quantization: step,
                ..model
            };
            let c = compare(
                &run,
                gap,
                format!(
                    "correlated {preset} {label}, bound with {} mm rounding",
                    step * 1e3
                ),
                &noise,
            );
            c.print();
            for ((floor, before), least_squares) in
                c.floor.iter().zip(&previous).zip(&c.floor_least_squares)
            {
                assert!(floor > before, "{}: the floor must grow", c.label);
                assert!(floor < least_squares, "{}", c.label);
            }
            previous = c.floor;
        }
    }
}
