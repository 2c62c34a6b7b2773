//! `inflate_sigma`: scaling a calibration's σ when a measurement outside the solver
//! (the scan matcher's self-check) says its noise model is too small — the covariance,
//! the σ, the verdicts and the sentence follow; factors of 1 or below change nothing.

mod common;

use common::{add_noise, exact_samples, rng, test_robot};
use odocal_solver::{calibrate, inflate_sigma, SolveOptions, Verdict};

#[test]
fn inflating_scales_every_sigma_and_judges_again() {
    let mut r = rng(11);
    let mut samples = exact_samples(&mut r, &test_robot(), 300, 4);
    add_noise(&mut r, &mut samples, [0.002, 0.002, 0.002]);
    let c = calibrate(&samples, &SolveOptions::default()).expect("calibrates");
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
