//! Helpers shared by the integration tests: the original package's reference data
//! and synthetic samples.

#![allow(dead_code)]

use odocal_geom::Pose2;
use odocal_solver::{Params, Predictor, ProfileSegment, Sample};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use rand_distr::{Distribution, Normal};
use std::path::PathBuf;

/// `../shared/reference/` beside the workspace, if present.
pub fn reference_dir() -> Option<PathBuf> {
    let dir = PathBuf::from(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../../shared/reference"
    ));
    if dir.join("lstraight.tuple").is_file() {
        Some(dir)
    } else {
        eprintln!(
            "NOTICE: reference data not found at {} — skipping the published-results test",
            dir.display()
        );
        None
    }
}

/// Reads a tuple file (stream of JSON objects) into samples.
pub fn read_reference_tuples(path: &std::path::Path) -> Vec<Sample> {
    let text = std::fs::read_to_string(path).expect("read tuple file");
    serde_json::Deserializer::from_str(&text)
        .into_iter::<serde_json::Value>()
        .map(|v| {
            let v = v.expect("valid JSON object");
            let f = |k: &str| v[k].as_f64().expect("number");
            let sm = v["sm"].as_array().expect("sm array");
            let sm: Vec<f64> = sm.iter().map(|x| x.as_f64().unwrap()).collect();
            Sample::from_speeds(
                f("T"),
                f("phi_l"),
                f("phi_r"),
                Pose2::new(sm[0], sm[1], sm[2]),
            )
        })
        .collect()
}

/// Published results of a reference file: (params, covariance).
pub fn read_reference_results(path: &std::path::Path) -> (Params, [[f64; 6]; 6]) {
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).expect("read results")).unwrap();
    let f = |k: &str| v[k].as_f64().unwrap();
    let params = Params {
        r_l: f("l_diam") / 2.0,
        r_r: f("r_diam") / 2.0,
        b: f("axle"),
        laser: Pose2::new(f("l_x"), f("l_y"), f("l_theta")),
    };
    let mut cov = [[0.0; 6]; 6];
    for i in 0..6 {
        for j in 0..6 {
            cov[i][j] = v["covariance"][i][j].as_f64().unwrap();
        }
    }
    (params, cov)
}

/// The robot of the synthetic tests: unequal radii, a displaced and turned sensor.
pub fn test_robot() -> Params {
    Params {
        r_l: 0.0305,
        r_r: 0.0298,
        b: 0.32,
        laser: Pose2::new(0.08, -0.03, 0.6),
    }
}

/// A seeded random generator.
pub fn rng(seed: u64) -> StdRng {
    StdRng::seed_from_u64(seed)
}

/// Random but plausible parameters; `laser_theta` overrides ℓθ when given.
pub fn random_params(rng: &mut StdRng, laser_theta: Option<f64>) -> Params {
    let r = rng.random_range(0.02..0.2);
    let b = rng.random_range(0.1..0.8);
    Params {
        r_l: r * rng.random_range(0.95..1.05),
        r_r: r * rng.random_range(0.95..1.05),
        b,
        laser: Pose2::new(
            rng.random_range(-0.5..0.5) * b,
            rng.random_range(-0.5..0.5) * b,
            laser_theta
                .unwrap_or_else(|| rng.random_range(-std::f64::consts::PI..std::f64::consts::PI)),
        ),
    }
}

/// Kinds of motion in a synthetic drive.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Motion {
    Straight,
    Spin,
    Arc,
}

/// Wheel rotations (left, right) over one interval for a motion kind, such that the
/// robot turns less than about 1 rad.
pub fn wheel_rotations(rng: &mut StdRng, p: &Params, motion: Motion) -> (f64, f64) {
    // Forward travel d (m) and heading change w (rad).
    let (d, w) = match motion {
        Motion::Straight => (rng.random_range(-0.3..0.3), 0.0),
        Motion::Spin => (0.0, rng.random_range(-0.8..0.8)),
        Motion::Arc => (rng.random_range(-0.3..0.3), rng.random_range(-0.8..0.8)),
    };
    // d = (r_l a_l + r_r a_r)/2, w = (r_r a_r − r_l a_l)/b.
    let a_r = (d + 0.5 * w * p.b) / p.r_r;
    let a_l = (d - 0.5 * w * p.b) / p.r_l;
    (a_l, a_r)
}

/// A mixed drive: motions cycling through straight, spin and arc; with `pieces`
/// > 1, each interval is a random non-constant-speed profile. `ŝ` is exact.
pub fn exact_samples(rng: &mut StdRng, p: &Params, n: usize, pieces: usize) -> Vec<Sample> {
    let pred = Predictor::new(p, true);
    (0..n)
        .map(|k| {
            let motion = [Motion::Straight, Motion::Spin, Motion::Arc][k % 3];
            let s = make_sample(rng, p, motion, pieces);
            let sm = pred.predict(&s);
            Sample {
                sm: Pose2::from_array(sm),
                ..s
            }
        })
        .collect()
}

/// One sample (ŝ left at identity) of the given motion, split into `pieces` pieces
/// with random speeds when `pieces` > 1.
pub fn make_sample(rng: &mut StdRng, p: &Params, motion: Motion, pieces: usize) -> Sample {
    let (a_l, a_r) = wheel_rotations(rng, p, motion);
    let t = rng.random_range(0.05..0.5);
    if pieces <= 1 {
        return Sample::from_rotations(t, a_l, a_r, Pose2::IDENTITY);
    }
    // Random positive weights per piece and per wheel: speeds change inside the interval.
    let wl: Vec<f64> = (0..pieces).map(|_| rng.random_range(0.1..1.0)).collect();
    let wr: Vec<f64> = (0..pieces).map(|_| rng.random_range(0.1..1.0)).collect();
    let (sl, sr): (f64, f64) = (wl.iter().sum(), wr.iter().sum());
    let segs = (0..pieces)
        .map(|i| ProfileSegment {
            duration: t / pieces as f64,
            dphi_l: a_l * wl[i] / sl,
            dphi_r: a_r * wr[i] / sr,
        })
        .collect();
    Sample::from_profile(segs, Pose2::IDENTITY)
}

/// Adds Gaussian noise of standard deviations `sigma` (x, y, θ) to every `ŝ`.
pub fn add_noise(rng: &mut StdRng, samples: &mut [Sample], sigma: [f64; 3]) {
    let n: Vec<Normal<f64>> = sigma
        .iter()
        .map(|&s| Normal::new(0.0, s).unwrap())
        .collect();
    for s in samples {
        s.sm = Pose2::new(
            s.sm.x + n[0].sample(rng),
            s.sm.y + n[1].sample(rng),
            s.sm.theta + n[2].sample(rng),
        );
    }
}
