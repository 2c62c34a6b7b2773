//! `inflate_sigma`: scaling a calibration's σ when a measurement outside the solver
//! (the scan matcher's self-check) says its noise model is too small — the covariance,
//! the σ, the verdicts and the sentence follow; factors of 1 or below change nothing.
//! `widen_along`: a quantity the estimate was computed at, known to σ, adds the
//! parameters' one-σ move to the covariance, and the verdicts follow;
//! `widen_lasers_along` does it to the joint covariance of several lasers.

mod common;

use common::{add_noise, exact_samples, rng, test_robot};
use odocal_geom::Pose2;
use odocal_solver::{
    calibrate, calibrate_lasers, inflate_sigma, widen_along, widen_lasers_along, Calibration,
    Params, SolveOptions, Verdict,
};

/// A calibration of 300 samples of the test robot with 2 mm / 2 mrad noise.
fn noisy_calibration(seed: u64) -> Calibration {
    let mut r = rng(seed);
    let mut samples = exact_samples(&mut r, &test_robot(), 300, 4);
    add_noise(&mut r, &mut samples, [0.002, 0.002, 0.002]);
    calibrate(&samples, &SolveOptions::default()).expect("calibrates")
}

#[test]
fn inflating_scales_every_sigma_and_judges_again() {
    let c = noisy_calibration(11);
    assert!(
        c.observability
            .parameters
            .iter()
            .all(|p| p.verdict == Verdict::WellDetermined),
        "{:?}",
        c.observability
    );

    for factor in [1.0, 0.5, f64::NAN, f64::INFINITY] {
        let mut same = c.clone();
        inflate_sigma(&mut same, factor);
        assert_eq!(same, c, "factor {factor}");
    }

    let mut wider = c.clone();
    inflate_sigma(&mut wider, 3.0);
    for i in 0..6 {
        for j in 0..6 {
            let expected = 9.0 * c.covariance[i][j];
            assert!(
                (wider.covariance[i][j] - expected).abs() <= 1e-12 * expected.abs(),
                "({i}, {j})"
            );
        }
        let (a, b) = (
            &c.observability.parameters[i],
            &wider.observability.parameters[i],
        );
        assert!(
            (b.sigma - 3.0 * a.sigma).abs() <= 1e-12 * a.sigma,
            "{}",
            a.name
        );
    }
    assert_eq!(wider.params, c.params);

    // σ a thousand times larger: nothing is well determined any more, and the
    // sentence says so.
    let mut far = c.clone();
    inflate_sigma(&mut far, 1e3);
    assert!(
        far.observability
            .parameters
            .iter()
            .all(|p| p.verdict != Verdict::WellDetermined),
        "{:?}",
        far.observability
    );
    assert!(
        !far.observability.sentence.starts_with("all six"),
        "{}",
        far.observability.sentence
    );
}

#[test]
fn widening_adds_the_shift_as_a_rank_one_term_and_judges_again() {
    let c = noisy_calibration(12);

    for nothing in [[0.0; 6], [f64::NAN; 6]] {
        let mut same = c.clone();
        widen_along(&mut same, &nothing);
        assert_eq!(same, c);
    }

    // b moves by 3 of its σ and ℓx along with it: b's variance grows tenfold, ℓx's
    // by its shift squared, and their covariance by the product; r_L is untouched.
    let sigma_b = c.covariance[2][2].sqrt();
    let shift = [0.0, 0.0, 3.0 * sigma_b, -0.001, 0.0, f64::INFINITY];
    let mut wider = c.clone();
    widen_along(&mut wider, &shift);
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * b.abs().max(1e-30);
    assert!(close(wider.covariance[2][2], 10.0 * c.covariance[2][2]));
    assert!(close(wider.covariance[3][3], c.covariance[3][3] + 1e-6));
    assert!(close(
        wider.covariance[2][3],
        c.covariance[2][3] - 3e-3 * sigma_b
    ));
    assert_eq!(wider.covariance[3][2], wider.covariance[2][3]);
    assert_eq!(wider.covariance[0], c.covariance[0]);
    assert_eq!(wider.covariance[5], c.covariance[5]);
    assert!(close(
        wider.observability.parameters[2].sigma,
        10f64.sqrt() * sigma_b
    ));
    assert_eq!(wider.params, c.params);

    // A shift of b by a tenth of it: b is no longer well determined.
    let mut far = c.clone();
    widen_along(&mut far, &[0.0, 0.0, 0.1 * c.params.b, 0.0, 0.0, 0.0]);
    assert_ne!(
        far.observability.parameters[2].verdict,
        Verdict::WellDetermined
    );
    assert_eq!(
        far.observability.parameters[0].verdict,
        Verdict::WellDetermined
    );
}

#[test]
fn widening_several_lasers_adds_the_shift_to_the_joint_covariance_and_its_views() {
    let mut r = rng(13);
    let front = test_robot();
    let rear = Params {
        laser: Pose2::new(-0.12, 0.02, 3.0),
        ..front
    };
    let (mut samples, mut laser_of) = (Vec::new(), Vec::new());
    for (k, p) in [front, rear].iter().enumerate() {
        let mut s = exact_samples(&mut r, p, 150, 1);
        add_noise(&mut r, &mut s, [0.002, 0.002, 0.002]);
        laser_of.extend(std::iter::repeat_n(k, s.len()));
        samples.extend(s);
    }
    let c = calibrate_lasers(&samples, &laser_of, &SolveOptions::default()).expect("solves");

    let mut same = c.clone();
    widen_lasers_along(&mut same, &[f64::NAN; 9]);
    assert_eq!(same, c);

    // b and the second laser's ℓx move together; an infinite entry counts as 0.
    let shift = [0.0, 0.0, 2e-3, 0.0, 0.0, f64::INFINITY, 1e-3, 0.0, 0.0];
    let mut wider = c.clone();
    widen_lasers_along(&mut wider, &shift);
    for i in 0..9 {
        for j in 0..9 {
            let s = |k: usize| if shift[k].is_finite() { shift[k] } else { 0.0 };
            let want = c.covariance[i][j] + s(i) * s(j);
            assert!(
                (wider.covariance[i][j] - want).abs() <= 1e-15 * want.abs().max(1e-12),
                "({i}, {j})"
            );
        }
    }
    // The views read it: the second laser's ℓx and its pose from the first laser
    // widen, the first laser's ℓ does not.
    assert!(wider.covariance_of(1)[3][3] > c.covariance_of(1)[3][3]);
    assert_eq!(wider.covariance_of(0)[3], c.covariance_of(0)[3]);
    assert!(wider.from_first(1).1[0][0] > c.from_first(1).1[0][0]);
    assert!(
        wider.view(1).observability.parameters[3].sigma
            > c.view(1).observability.parameters[3].sigma
    );
    // A shorter shift widens the leading parameters only.
    let mut wheels = c.clone();
    widen_lasers_along(&mut wheels, &[0.0, 0.0, 2e-3]);
    assert!(wheels.covariance[2][2] > c.covariance[2][2]);
    assert_eq!(wheels.covariance[6], c.covariance[6]);
}
