//! Several lasers on one robot (`calibrate_lasers`): exact recovery of the shared
//! wheels and of each laser's pose on noise-free data, agreement with the
//! single-laser solve for one laser, and statistical consistency of the joint
//! covariance and of the laser-to-laser transform on noisy data.

#![allow(clippy::needless_range_loop)]

mod common;

use common::{add_noise, exact_samples, rng, test_robot};
use nalgebra::DMatrix;
use odocal_geom::Pose2;
use odocal_solver::{
    calibrate, calibrate_lasers, calibrate_lasers_constrained, Constraint, Params, Sample,
    SolveOptions, Verdict,
};
use rand::rngs::StdRng;

/// The test robot's wheels with a front laser and a rear laser turned by π.
fn two_lasers() -> (Params, Params) {
    let front = test_robot();
    let rear = Params {
        laser: Pose2::new(-0.12, 0.02, std::f64::consts::PI - 0.05),
        ..front
    };
    (front, rear)
}

/// `n` samples of each laser (noise `sigma` on ŝ when given), with their laser index.
fn drive(
    r: &mut StdRng,
    lasers: &[Params],
    n: usize,
    sigma: Option<[f64; 3]>,
) -> (Vec<Sample>, Vec<usize>) {
    let mut samples = Vec::new();
    let mut laser_of = Vec::new();
    for (k, p) in lasers.iter().enumerate() {
        let mut s = exact_samples(r, p, n, 1);
        if let Some(sigma) = sigma {
            add_noise(r, &mut s, sigma);
        }
        laser_of.extend(std::iter::repeat_n(k, s.len()));
        samples.extend(s);
    }
    (samples, laser_of)
}

fn truth_vector(lasers: &[Params]) -> Vec<f64> {
    let mut v = vec![lasers[0].r_l, lasers[0].r_r, lasers[0].b];
    for p in lasers {
        v.extend([p.laser.x, p.laser.y, p.laser.theta]);
    }
    v
}

fn angle_diff(a: f64, b: f64) -> f64 {
    odocal_geom::wrap_angle(a - b)
}

#[test]
fn noise_free_two_lasers_recovered_exactly() {
    let (front, rear) = two_lasers();
    let (samples, laser_of) = drive(&mut rng(1), &[front, rear], 90, None);
    let cal = calibrate_lasers(&samples, &laser_of, &SolveOptions::default()).unwrap();
    assert_eq!(cal.lasers(), 2);
    let truth = truth_vector(&[front, rear]);
    for (i, (got, want)) in cal.params.iter().zip(&truth).enumerate() {
        let err = if i % 3 == 2 && i >= 3 {
            angle_diff(*got, *want)
        } else {
            got - want
        };
        assert!(err.abs() < 1e-9, "parameter {i}: {got} vs {want}");
    }
    let (t, _) = cal.from_first(1);
    let want = front.laser.inverse().compose(&rear.laser);
    assert!((t.x - want.x).abs() < 1e-9 && (t.y - want.y).abs() < 1e-9);
    assert!(angle_diff(t.theta, want.theta).abs() < 1e-9);
    // The first laser's view: the shared wheels and ℓ₁.
    assert!((cal.first.params.b - front.b).abs() < 1e-9);
    assert!((cal.first.params.laser.x - front.laser.x).abs() < 1e-9);
}

#[test]
fn one_laser_agrees_with_the_single_laser_solve() {
    let mut r = rng(2);
    let mut samples = exact_samples(&mut r, &test_robot(), 200, 1);
    add_noise(&mut r, &mut samples, [0.002, 0.002, 0.004]);
    let single = calibrate(&samples, &SolveOptions::default()).unwrap();
    let joint =
        calibrate_lasers(&samples, &vec![0; samples.len()], &SolveOptions::default()).unwrap();
    let sigma = |i: usize| single.covariance[i][i].sqrt();
    for (i, v) in single.params.to_vector().iter().enumerate() {
        assert!(
            (joint.params[i] - v).abs() < 1e-6 * sigma(i),
            "parameter {i}: {} vs {v}",
            joint.params[i]
        );
        let ratio = joint.covariance[i][i].sqrt() / sigma(i);
        assert!(
            (ratio - 1.0).abs() < 1e-6,
            "σ of parameter {i}: ratio {ratio}"
        );
    }
    assert_eq!(joint.used, single.used);
}

/// The joint estimate minus the truth (headings wrapped).
fn joint_error(params: &[f64], truth: &[f64]) -> Vec<f64> {
    (0..params.len())
        .map(|i| {
            if i >= 3 && i % 3 == 2 {
                angle_diff(params[i], truth[i])
            } else {
                params[i] - truth[i]
            }
        })
        .collect()
}

/// Normalized estimation error squared of `err` under `cov`.
fn nees(err: &[f64], cov: &DMatrix<f64>) -> f64 {
    let e = nalgebra::DVector::from_column_slice(err);
    let inv = cov.clone().try_inverse().expect("covariance invertible");
    (e.transpose() * inv * e)[0]
}

/// Mean NEES of the 9 joint parameters and of the 3 of the laser-to-laser transform
/// over `runs` noisy drives, and the ratio of the joint σ of b to the best single
/// laser's.
fn monte_carlo(runs: usize, seed: u64) -> (f64, f64, f64) {
    let (front, rear) = two_lasers();
    let truth = truth_vector(&[front, rear]);
    let want = front.laser.inverse().compose(&rear.laser);
    let mut r = rng(seed);
    let (mut joint_sum, mut between_sum, mut ratio_sum) = (0.0, 0.0, 0.0);
    for _ in 0..runs {
        let (samples, laser_of) = drive(&mut r, &[front, rear], 150, Some([0.002, 0.002, 0.004]));
        let cal = calibrate_lasers(&samples, &laser_of, &SolveOptions::default()).unwrap();
        let err = joint_error(&cal.params, &truth);
        let cov = DMatrix::from_fn(9, 9, |i, j| cal.covariance[i][j]);
        joint_sum += nees(&err, &cov);
        let (t, c) = cal.from_first(1);
        let e = [t.x - want.x, t.y - want.y, angle_diff(t.theta, want.theta)];
        between_sum += nees(&e, &DMatrix::from_fn(3, 3, |i, j| c[i][j]));
        let best_single = cal
            .own
            .iter()
            .map(|o| o.covariance[2][2].sqrt())
            .fold(f64::INFINITY, f64::min);
        ratio_sum += cal.covariance[2][2].sqrt() / best_single;
    }
    let n = runs as f64;
    (joint_sum / n, between_sum / n, ratio_sum / n)
}

#[test]
fn noisy_two_lasers_consistent_short() {
    let runs = 40;
    let (joint, between, ratio) = monte_carlo(runs, 3);
    // χ²(9) mean 9, sd of the mean √(18/runs); χ²(3) mean 3, sd √(6/runs); 3.5 sd.
    let half9 = 3.5 * (18.0 / runs as f64).sqrt();
    let half3 = 3.5 * (6.0 / runs as f64).sqrt();
    assert!(
        (joint - 9.0).abs() < half9,
        "mean NEES of the joint {joint}"
    );
    assert!(
        (between - 3.0).abs() < half3,
        "mean NEES of ℓ₁⁻¹⊕ℓ₂ {between}"
    );
    // Twice the wheel data: b's σ about 1/√2 of one laser's.
    assert!(ratio < 0.8, "joint σ_b / best single σ_b = {ratio}");
}

#[test]
#[ignore = "Monte Carlo, 300 runs (0.2 s in release; kept with the other Monte Carlo suites)"]
fn noisy_two_lasers_consistent_long() {
    let runs = 300;
    let (joint, between, ratio) = monte_carlo(runs, 4);
    let half9 = 3.5 * (18.0 / runs as f64).sqrt();
    let half3 = 3.5 * (6.0 / runs as f64).sqrt();
    println!("mean NEES joint {joint:.3} (9), between {between:.3} (3), σ_b ratio {ratio:.3}");
    assert!(
        (joint - 9.0).abs() < half9,
        "mean NEES of the joint {joint}"
    );
    assert!(
        (between - 3.0).abs() < half3,
        "mean NEES of ℓ₁⁻¹⊕ℓ₂ {between}"
    );
    assert!(ratio < 0.8);
}

#[test]
fn laser_without_samples_is_an_error_not_a_panic() {
    let (front, _) = two_lasers();
    let samples = exact_samples(&mut rng(5), &front, 30, 1);
    // Laser 1 named but given no samples.
    let mut laser_of = vec![0; samples.len()];
    laser_of[0] = 2;
    assert!(calibrate_lasers(&samples, &laser_of, &SolveOptions::default()).is_err());
}

/// `samples` with consecutive scan times (each sample's second scan the next one's
/// first), so that the joint solve takes its shared-scan path (the lasers' own
/// estimates combined by generalized least squares).
fn chained(mut samples: Vec<Sample>) -> Vec<Sample> {
    for (i, s) in samples.iter_mut().enumerate() {
        s.scan_times = Some([i as f64, i as f64 + 1.0]);
    }
    samples
}

#[test]
fn second_laser_held_and_wheel_prior_counted_once() {
    let (front, rear) = two_lasers();
    let mut r = rng(7);
    let (samples, laser_of) = drive(&mut r, &[front, rear], 150, Some([0.002, 0.002, 0.004]));
    for shared in [false, true] {
        let samples = if shared {
            chained(samples.clone())
        } else {
            samples.clone()
        };
        let free = calibrate_lasers(&samples, &laser_of, &SolveOptions::default()).unwrap();
        let sigma_b = free.covariance[2][2].sqrt();
        // The rear laser's ℓx held at a value 5 mm off the truth: it stays there, with
        // zero variance, and its verdict says held.
        let held_x = rear.laser.x + 0.005;
        let mut options = SolveOptions::default();
        let prior_sigma = sigma_b;
        options.constraints.0[2] = Constraint::Prior {
            mean: front.b,
            sigma: prior_sigma,
        };
        let more = [[Constraint::Held(held_x), Constraint::Free, Constraint::Free]];
        let cal = calibrate_lasers_constrained(&samples, &laser_of, &options, &more).unwrap();
        assert_eq!(cal.params[6], held_x, "shared {shared}");
        assert!(cal.covariance[6].iter().all(|v| *v == 0.0));
        let view = cal.view(1);
        assert_eq!(
            view.observability.parameters[3].constraint,
            Constraint::Held(held_x)
        );
        assert_eq!(
            view.observability.parameters[3].verdict,
            Verdict::WellDetermined
        );
        assert_eq!(cal.constraints[1].held(3), Some(held_x));
        // The prior on b, in both lasers' own solves, counts once: with a prior as
        // informative as the data, σ_b is about 1/√2 = 0.71 of the free one's
        // (about 0.7 with independent samples, 0.75 through the lasers' own
        // sandwich covariances); counted twice it would be 1/√3 = 0.58, never 1.
        let ratio = cal.covariance[2][2].sqrt() / sigma_b;
        assert!(
            (0.65..0.8).contains(&ratio),
            "shared {shared}: σ_b with the prior / without = {ratio}"
        );
        // The first laser's ℓ moves little; the held value is not the truth, so the
        // rear laser's ℓy, ℓθ absorb part of it, but the wheels stay within 4σ.
        for i in 0..3 {
            let z = (cal.params[i] - free.params[i]) / free.covariance[i][i].sqrt();
            assert!(z.abs() < 4.0, "shared {shared}: wheel {i} moved {z:.1}σ");
        }
    }
}

#[test]
fn constraints_for_a_laser_without_samples_are_an_error() {
    let (front, _) = two_lasers();
    let samples = exact_samples(&mut rng(8), &front, 60, 1);
    let laser_of = vec![0; samples.len()];
    let more = [[Constraint::Held(0.1), Constraint::Free, Constraint::Free]];
    let e = calibrate_lasers_constrained(&samples, &laser_of, &SolveOptions::default(), &more);
    assert!(e.is_err());
}

/// One drive seen by both lasers over the same intervals (the worst case of two
/// lasers' samples sharing odometry: every interval overlaps fully): each laser's ŝ
/// is its true motion plus its own matching noise, and both lasers' samples carry the
/// same wheel rotations, off the true ones by one encoder error per wheel and
/// interval of standard deviation `encoder_sigma` (rad).
fn drive_shared_wheels(
    r: &mut StdRng,
    lasers: &[Params],
    n: usize,
    encoder_sigma: f64,
) -> (Vec<Sample>, Vec<usize>) {
    use rand_distr::{Distribution, Normal};
    let wheel = Normal::new(0.0, encoder_sigma).unwrap();
    let truth = exact_samples(r, &lasers[0], n, 1);
    let noisy: Vec<(f64, f64)> = truth
        .iter()
        .map(|s| (s.dphi_l + wheel.sample(r), s.dphi_r + wheel.sample(r)))
        .collect();
    let mut samples = Vec::new();
    let mut laser_of = Vec::new();
    for (k, p) in lasers.iter().enumerate() {
        let pred = odocal_solver::Predictor::new(p, true);
        let mut own: Vec<Sample> = truth
            .iter()
            .zip(&noisy)
            .map(|(s, &(l, rr))| {
                let sm = Pose2::from_array(pred.predict(s));
                Sample::from_rotations(s.t, l, rr, sm)
            })
            .collect();
        add_noise(r, &mut own, [0.002, 0.002, 0.004]);
        laser_of.extend(std::iter::repeat_n(k, own.len()));
        samples.extend(own);
    }
    (samples, laser_of)
}

/// Mean NEES of the 9 joint parameters over `runs` drives with encoder errors of
/// `encoder_sigma` shared by the two lasers' samples.
fn shared_wheels_nees(runs: usize, seed: u64, encoder_sigma: f64) -> f64 {
    let (front, rear) = two_lasers();
    let truth = truth_vector(&[front, rear]);
    let mut r = rng(seed);
    let mut sum = 0.0;
    for _ in 0..runs {
        let (samples, laser_of) = drive_shared_wheels(&mut r, &[front, rear], 150, encoder_sigma);
        let cal = calibrate_lasers(&samples, &laser_of, &SolveOptions::default()).unwrap();
        let err = joint_error(&cal.params, &truth);
        sum += nees(&err, &DMatrix::from_fn(9, 9, |i, j| cal.covariance[i][j]));
    }
    sum / runs as f64
}

/// A realistic encoder error per wheel and interval: the difference of two readings
/// of a 2764.8-tick encoder (Khepera III; each floored: σ = tick/√6) plus 2 ms of
/// read-time jitter at 5 rad/s (uniform ±2 ms at each end: 5·0.002·√(2/3)).
const REALISTIC_ENCODER_SIGMA: f64 = 0.000_928 + 0.008_2;

/// The two lasers' samples share the wheel encoders' errors, which the joint model
/// takes as independent: at a realistic encoder error (9 mrad per wheel and interval,
/// i.e. 0.3 mm of wheel travel against 2 mm of matching noise) the joint NEES is
/// still χ²(9). Fast version of the Monte Carlo below.
#[test]
fn shared_encoder_noise_leaves_the_joint_nees_consistent() {
    let runs = 40;
    let nees = shared_wheels_nees(runs, 11, REALISTIC_ENCODER_SIGMA);
    let half9 = 3.5 * (18.0 / runs as f64).sqrt();
    assert!((nees - 9.0).abs() < half9, "mean NEES {nees}");
}

#[test]
#[ignore = "Monte Carlo, 300 runs per encoder error (about 1 s in release)"]
fn shared_encoder_noise_monte_carlo() {
    let runs = 300;
    let half9 = 3.5 * (18.0 / runs as f64).sqrt();
    let mut line = Vec::new();
    for factor in [0.0, 1.0, 3.0, 10.0] {
        let nees = shared_wheels_nees(runs, 12, factor * REALISTIC_ENCODER_SIGMA);
        line.push(format!("{factor}x: {nees:.2}"));
        if factor <= 1.0 {
            assert!((nees - 9.0).abs() < half9, "{factor}x: mean NEES {nees}");
        }
    }
    println!(
        "mean NEES (9 expected) by encoder error: {}",
        line.join(", ")
    );
    // Ten times the realistic error is visible: the test can tell.
    let big = shared_wheels_nees(runs, 12, 10.0 * REALISTIC_ENCODER_SIGMA);
    assert!(big > 9.0 + half9, "10x: mean NEES {big}");
}
