//! The original package's published results (T-RO 2013 supplemental material) are
//! reproduced by the closed form with the T-RO trimming rule and no refinement.

#![allow(clippy::needless_range_loop)]

mod common;

use odocal_solver::{calibrate, SigmaEstimate, SolveOptions, Trim};

#[test]
fn reproduces_published_results() {
    let Some(dir) = common::reference_dir() else {
        return;
    };
    for name in ["lstraight", "l90", "lmov"] {
        let samples = common::read_reference_tuples(&dir.join(format!("{name}.tuple")));
        let (want, want_cov) =
            common::read_reference_results(&dir.join(format!("{name}_results.json")));
        let options = SolveOptions {
            trim: Trim::TRO,
            refine: false,
            ..SolveOptions::default()
        };
        let cal = calibrate(&samples, &options).expect("calibration succeeds");
        let got = cal.params.to_vector();
        let want_v = want.to_vector();
        let mut worst = 0.0_f64;
        for i in 0..6 {
            let rel = ((got[i] - want_v[i]) / want_v[i]).abs();
            worst = worst.max(rel);
            println!(
                "{name} param {i}: got {:.9e} want {:.9e} rel {rel:.2e}",
                got[i], want_v[i]
            );
        }
        let mut worst_cov = 0.0_f64;
        for i in 0..6 {
            let rel = (cal.covariance[i][i] / want_cov[i][i] - 1.0).abs();
            worst_cov = worst_cov.max(rel);
            println!(
                "{name} cov[{i}][{i}]: got {:.6e} want {:.6e} rel {rel:.3}",
                cal.covariance[i][i], want_cov[i][i]
            );
        }
        println!(
            "{name}: {} of {} samples used, rounds {:?}, max rel param error {worst:.2e}, max rel \
             variance error {worst_cov:.3}; {}",
            cal.samples_used,
            samples.len(),
            cal.samples_per_round,
            cal.observability.sentence
        );
        assert!(
            worst < 1e-5,
            "{name}: parameters differ by {worst:.2e} (relative)"
        );
        assert!(
            worst_cov < 0.05,
            "{name}: covariance diagonal differs by {worst_cov:.3}"
        );

        // The maximum-likelihood refinement lowers the cost and moves each parameter
        // by well under one standard deviation of the closed form.
        let refined = calibrate(
            &samples,
            &SolveOptions {
                trim: Trim::TRO,
                ..SolveOptions::default()
            },
        )
        .expect("refined calibration succeeds");
        assert!(refined.cost_after <= refined.cost_before);
        let d = refined.params.difference(&cal.params);
        let moves: Vec<f64> = (0..6)
            .map(|i| d[i].abs() / cal.covariance[i][i].sqrt())
            .collect();
        println!(
            "{name}: refinement cost {:.6e} → {:.6e}, moves in σ {moves:.3?}",
            refined.cost_before, refined.cost_after
        );
        assert!(
            moves.iter().all(|&m| m < 0.5),
            "{name}: refinement moved too far"
        );

        // With σ's from the final samples, the noise model fits them (reduced χ² ≈ 1);
        // the original's first-round σ's are larger (conservative covariance).
        let final_set = calibrate(
            &samples,
            &SolveOptions {
                trim: Trim::TRO,
                sigma_from: SigmaEstimate::FinalSet,
                ..SolveOptions::default()
            },
        )
        .expect("calibration with final-set σ");
        println!(
            "{name}: reduced χ² {:.3} (first-round σ {:?}) vs {:.3} (final-set σ {:?})",
            refined.reduced_chi2, refined.sm_sigma, final_set.reduced_chi2, final_set.sm_sigma
        );
        assert!((final_set.reduced_chi2 - 1.0).abs() < 0.05);
        assert!(refined.reduced_chi2 <= final_set.reduced_chi2);
    }
}
