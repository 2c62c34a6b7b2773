//! Noise-free samples: the closed form and the refinement recover the parameters
//! exactly (to 1e-9), for random robots, sensor headings near ±π, and
//! non-constant wheel speeds.

#![allow(clippy::needless_range_loop)]

mod common;

use common::{exact_samples, random_params, rng};
use odocal_solver::{calibrate, Params, SolveOptions, Trim};
use std::f64::consts::PI;

/// Largest error, relative to the parameter's size (radii, b: own value; offsets: b;
/// ℓθ: absolute radians).
fn worst_error(got: &Params, truth: &Params) -> f64 {
    let d = got.difference(truth);
    let scale = [
        truth.r_l.abs(),
        truth.r_r.abs(),
        truth.b,
        truth.b,
        truth.b,
        1.0,
    ];
    (0..6).map(|i| d[i].abs() / scale[i]).fold(0.0, f64::max)
}

fn check(truth: &Params, pieces: usize, seed: u64) {
    let mut r = rng(seed);
    let samples = exact_samples(&mut r, truth, 90, pieces);
    for trim in [Trim::None, Trim::TRO, Trim::ICRA] {
        for refine in [false, true] {
            let options = SolveOptions {
                trim,
                refine,
                ..SolveOptions::default()
            };
            let cal = calibrate(&samples, &options)
                .unwrap_or_else(|e| panic!("seed {seed}, {trim:?}, refine {refine}: {e}"));
            let err = worst_error(&cal.params, truth);
            assert!(
                err < 1e-9,
                "seed {seed} pieces {pieces} {trim:?} refine {refine}: error {err:.2e}\n got {:?}\n want {truth:?}",
                cal.params
            );
            assert!(cal.observability.wheel_signs.is_none());
        }
    }
}

#[test]
fn random_robots_constant_speed() {
    let mut r = rng(1);
    for seed in 0..40 {
        let truth = random_params(&mut r, None);
        check(&truth, 1, 100 + seed);
    }
}

#[test]
fn random_robots_with_speed_profiles() {
    let mut r = rng(2);
    for seed in 0..40 {
        let truth = random_params(&mut r, None);
        check(&truth, 5, 200 + seed);
    }
}

#[test]
fn sensor_heading_near_plus_minus_pi() {
    let mut r = rng(3);
    let headings = [PI, -PI + 1e-12, PI - 1e-9, -PI + 1e-6, PI - 1e-3, 3.1, -3.1];
    for (k, &h) in headings.iter().enumerate() {
        let truth = random_params(&mut r, Some(h));
        check(&truth, 1, 300 + k as u64);
        check(&truth, 4, 400 + k as u64);
    }
}

#[test]
fn ignoring_the_profile_biases_the_estimate() {
    // The profile matters: with non-constant speeds, the constant-speed formulas
    // are wrong by much more than rounding.
    let mut r = rng(4);
    let truth = random_params(&mut r, None);
    let samples = exact_samples(&mut r, &truth, 90, 5);
    let options = SolveOptions {
        trim: Trim::None,
        refine: false,
        use_profile: false,
        ..SolveOptions::default()
    };
    // Either the fit is visibly wrong, or the model error is so large that the
    // solver refuses (the residuals swamp the information).
    if let Ok(cal) = calibrate(&samples, &options) {
        assert!(worst_error(&cal.params, &truth) > 1e-6);
    }
    let with_profile = SolveOptions {
        use_profile: true,
        ..options
    };
    let cal = calibrate(&samples, &with_profile).unwrap();
    assert!(worst_error(&cal.params, &truth) < 1e-9);
}
