//! The systematic term of a scan-matching bias common to every sample
//! (`SolveOptions::matcher_bias`): each sample's `ŝ` moved by `β·θ` moves the
//! estimate by `H⁻¹ Q β`, and the term adds exactly that, squared, to the
//! covariance — checked against the estimate's actual response to such a bias.

mod common;

use common::{add_noise, exact_samples, rng};
use odocal_geom::Pose2;
use odocal_solver::{calibrate, Sample, SolveOptions, Trim};

fn options(matcher_bias: [f64; 3]) -> SolveOptions {
    SolveOptions {
        trim: Trim::None,
        matcher_bias,
        ..SolveOptions::default()
    }
}

/// `samples` with every `ŝ` moved by `β·θ` (θ its rotation).
fn biased(samples: &[Sample], beta: [f64; 3]) -> Vec<Sample> {
    samples
        .iter()
        .map(|s| {
            let th = s.sm.theta;
            Sample {
                sm: Pose2::new(
                    s.sm.x + beta[0] * th,
                    s.sm.y + beta[1] * th,
                    s.sm.theta + beta[2] * th,
                ),
                ..s.clone()
            }
        })
        .collect()
}

#[test]
fn the_term_is_the_estimates_response_to_the_bias() {
    let truth = common::test_robot();
    let mut r = rng(11);
    let mut samples = exact_samples(&mut r, &truth, 600, 1);
    add_noise(&mut r, &mut samples, [2e-4, 2e-4, 2e-4]);
    let plain = calibrate(&samples, &options([0.0; 3])).unwrap();
    for beta in [[3e-4, 0.0, 0.0], [0.0, 3e-4, 0.0], [0.0, 0.0, 2e-3]] {
        let moved = calibrate(&biased(&samples, beta), &options([0.0; 3])).unwrap();
        let with_term = calibrate(&samples, &options(beta)).unwrap();
        let (p0, p1) = (plain.params.to_vector(), moved.params.to_vector());
        for i in 0..6 {
            let shift = (p1[i] - p0[i]).abs();
            let term = (with_term.covariance[i][i] - plain.covariance[i][i]).sqrt();
            let sigma = plain.covariance[i][i].sqrt();
            assert!(
                (term - shift).abs() <= 0.05 * term + 1e-3 * sigma,
                "β {beta:?}, parameter {i}: shift {shift:.3e}, term {term:.3e} (σ {sigma:.3e})"
            );
        }
        // The bias matters: it moves some parameter by more than a tenth of its σ.
        assert!((0..6).any(|i| (p1[i] - p0[i]).abs() > 0.1 * plain.covariance[i][i].sqrt()));
    }
    // No term, no change.
    let none = calibrate(&samples, &options([0.0; 3])).unwrap();
    assert_eq!(none.covariance, plain.covariance);
}
