//! Monte Carlo with known scan-matching noise: the estimate is unbiased (mean error
//! within 3σ/√N), its reported covariance is consistent (normalized estimation error
//! squared distributed as χ²(6)), and the maximum-likelihood refinement scatters no
//! more than the closed form.

#![allow(clippy::needless_range_loop)]

mod common;

use common::{add_noise, exact_samples, rng};
use nalgebra::{SMatrix, SVector};
use odocal_geom::Pose2;
use odocal_solver::{calibrate, Calibration, Params, SolveOptions, Trim};
use rand::Rng;
use rand_distr::{Distribution, Normal};

fn truth() -> Params {
    common::test_robot()
}

fn nees(cal: &Calibration, truth: &Params) -> f64 {
    let e = SVector::<f64, 6>::from(cal.params.difference(truth));
    let p = SMatrix::<f64, 6, 6>::from_fn(|i, j| cal.covariance[i][j]);
    let pinv = p.try_inverse().expect("covariance invertible");
    (e.transpose() * pinv * e)[0]
}

struct Stats {
    mean: [f64; 6],
    std: [f64; 6],
}

fn stats(errors: &[[f64; 6]]) -> Stats {
    let n = errors.len() as f64;
    let mut mean = [0.0; 6];
    let mut std = [0.0; 6];
    for i in 0..6 {
        mean[i] = errors.iter().map(|e| e[i]).sum::<f64>() / n;
        std[i] = (errors.iter().map(|e| (e[i] - mean[i]).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
    }
    Stats { mean, std }
}

/// Bounds of the mean of `runs` χ²(6) draws at about 3.3 standard deviations.
fn chi2_mean_bounds(runs: usize) -> (f64, f64) {
    let half = 3.3 * (12.0 / runs as f64).sqrt();
    (6.0 - half, 6.0 + half)
}

#[test]
fn shared_noise_unbiased_consistent_and_refinement_helps() {
    let truth = truth();
    let runs = 200;
    let sigma = [0.002, 0.002, 0.004];
    let mut r = rng(10);
    let (mut closed, mut refined, mut nees_sum) = (Vec::new(), Vec::new(), 0.0);
    let mut chi2_sum = 0.0;
    for _ in 0..runs {
        let mut samples = exact_samples(&mut r, &truth, 300, 1);
        add_noise(&mut r, &mut samples, sigma);
        let options = SolveOptions {
            trim: Trim::None,
            ..SolveOptions::default()
        };
        let cal = calibrate(&samples, &options).expect("calibration");
        assert!(cal.cost_after <= cal.cost_before * (1.0 + 1e-12));
        closed.push(cal.closed_form.difference(&truth));
        refined.push(cal.params.difference(&truth));
        nees_sum += nees(&cal, &truth);
        chi2_sum += cal.reduced_chi2;
        for c in 0..3 {
            assert!(
                (cal.sm_sigma[c] / sigma[c] - 1.0).abs() < 0.15,
                "σ estimate {:?}",
                cal.sm_sigma
            );
        }
    }
    let mean_chi2 = chi2_sum / runs as f64;
    println!("mean reduced χ² {mean_chi2:.4}");
    assert!((mean_chi2 - 1.0).abs() < 0.02);
    let c = stats(&closed);
    let f = stats(&refined);
    let mean_nees = nees_sum / runs as f64;
    for i in 0..6 {
        println!(
            "param {i}: refined mean {:+.3e} std {:.3e} | closed mean {:+.3e} std {:.3e}",
            f.mean[i], f.std[i], c.mean[i], c.std[i]
        );
        let bound = 3.0 * f.std[i] / (runs as f64).sqrt();
        assert!(
            f.mean[i].abs() < bound,
            "param {i}: mean error {:.3e} > {bound:.3e}",
            f.mean[i]
        );
        assert!(
            f.std[i] <= c.std[i] * 1.02,
            "param {i}: refined scatter larger than closed form"
        );
    }
    let (lo, hi) = chi2_mean_bounds(runs);
    println!("mean NEES {mean_nees:.3} (χ²(6) bounds {lo:.2}..{hi:.2})");
    assert!(mean_nees > lo && mean_nees < hi, "mean NEES {mean_nees}");
    let trace_c: f64 = c
        .std
        .iter()
        .zip(&f.std)
        .map(|(a, b)| (a / b).powi(2))
        .sum::<f64>()
        / 6.0;
    println!("mean closed/refined variance ratio {trace_c:.3}");
}

#[test]
fn per_sample_covariance_weighting() {
    // Heteroscedastic noise with each sample's covariance attached: the refinement
    // weights by it, the covariance stays consistent, and the closed form (which
    // cannot weight step 2) scatters clearly more.
    let truth = truth();
    let runs = 150;
    let mut r = rng(11);
    let (mut closed, mut refined, mut nees_sum) = (Vec::new(), Vec::new(), 0.0);
    for _ in 0..runs {
        let mut samples = exact_samples(&mut r, &truth, 300, 1);
        for s in &mut samples {
            let k: f64 = r.random_range(0.3..3.0);
            let sigma = [0.002 * k, 0.0015 * k, 0.004 * k];
            let cov = [
                [sigma[0] * sigma[0], 0.0, 0.0],
                [0.0, sigma[1] * sigma[1], 0.0],
                [0.0, 0.0, sigma[2] * sigma[2]],
            ];
            let noise: Vec<f64> = sigma
                .iter()
                .map(|&sd| Normal::new(0.0, sd).unwrap().sample(&mut r))
                .collect();
            s.sm = Pose2::new(s.sm.x + noise[0], s.sm.y + noise[1], s.sm.theta + noise[2]);
            s.sm_cov = Some(cov);
        }
        let options = SolveOptions {
            trim: Trim::None,
            ..SolveOptions::default()
        };
        let cal = calibrate(&samples, &options).expect("calibration");
        closed.push(cal.closed_form.difference(&truth));
        refined.push(cal.params.difference(&truth));
        nees_sum += nees(&cal, &truth);
    }
    let c = stats(&closed);
    let f = stats(&refined);
    let mean_nees = nees_sum / runs as f64;
    for i in 0..6 {
        println!(
            "param {i}: refined mean {:+.3e} std {:.3e} | closed std {:.3e}",
            f.mean[i], f.std[i], c.std[i]
        );
        let bound = 3.0 * f.std[i] / (runs as f64).sqrt();
        assert!(
            f.mean[i].abs() < bound,
            "param {i}: mean error {:.3e} > {bound:.3e}",
            f.mean[i]
        );
        assert!(
            f.std[i] <= c.std[i],
            "param {i}: refined scatter larger than closed form"
        );
    }
    let (lo, hi) = chi2_mean_bounds(runs);
    println!("mean NEES {mean_nees:.3} (χ²(6) bounds {lo:.2}..{hi:.2})");
    assert!(mean_nees > lo && mean_nees < hi, "mean NEES {mean_nees}");
}
