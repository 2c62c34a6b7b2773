//! Partial calibration: parameters held at known values are kept exactly and the
//! others recovered (exactly on noise-free data, for every subset of held
//! parameters); held rows of the covariance are zero; priors combine with the data
//! as Gaussian information; data that do not determine some parameters become
//! solvable once those are held; `accept_weak` returns the numbers the verdicts
//! would refuse.

#![allow(clippy::needless_range_loop)]

mod common;

use common::{add_noise, exact_samples, make_sample, rng, Motion};
use odocal_geom::Pose2;
use odocal_solver::{
    calibrate, Constraint, Constraints, Params, Predictor, Sample, SolveError, SolveOptions, Trim,
    Verdict,
};
use rand::Rng;

fn truth() -> Params {
    common::test_robot()
}

fn options(constraints: Constraints) -> SolveOptions {
    SolveOptions {
        trim: Trim::None,
        constraints,
        ..SolveOptions::default()
    }
}

fn held(mask: u32, values: &[f64; 6]) -> Constraints {
    let mut c = Constraints::default();
    for i in 0..6 {
        if mask & (1 << i) != 0 {
            c.0[i] = Constraint::Held(values[i]);
        }
    }
    c
}

#[test]
fn every_subset_held_at_the_truth_recovers_the_rest_exactly() {
    let t = truth();
    let tv = t.to_vector();
    let samples = exact_samples(&mut rng(3), &t, 120, 3);
    // Every subset except "all six held".
    for mask in 0..63u32 {
        for refine in [false, true] {
            let opts = SolveOptions {
                refine,
                ..options(held(mask, &tv))
            };
            let cal = calibrate(&samples, &opts)
                .unwrap_or_else(|e| panic!("mask {mask:06b} refine {refine}: {e}"));
            let d = cal.params.difference(&t);
            // The closed form with held radii but a free b (or the reverse) is only
            // consistent up to the refinement.
            let tol = if refine { 1e-9 } else { 1e-6 };
            for i in 0..6 {
                assert!(
                    d[i].abs() < tol * tv[i].abs().max(0.1),
                    "mask {mask:06b} refine {refine}: parameter {i} off by {:e}",
                    d[i]
                );
            }
        }
    }
}

#[test]
fn held_values_are_kept_and_their_covariance_rows_are_zero() {
    let t = truth();
    let mut samples = exact_samples(&mut rng(4), &t, 300, 1);
    add_noise(&mut rng(5), &mut samples, [0.002, 0.002, 0.004]);
    let mut c = Constraints::default();
    c.0[2] = Constraint::Held(0.321);
    c.0[5] = Constraint::Held(0.59);
    let cal = calibrate(&samples, &options(c)).expect("solves");
    assert_eq!(cal.params.b, 0.321);
    assert_eq!(cal.params.laser.theta, 0.59);
    for i in [2, 5] {
        for j in 0..6 {
            assert_eq!(cal.covariance[i][j], 0.0);
            assert_eq!(cal.covariance[j][i], 0.0);
        }
        assert_eq!(cal.observability.parameters[i].constraint, c.0[i]);
    }
    for i in [0, 1, 3, 4] {
        assert!(cal.covariance[i][i] > 0.0);
        assert_eq!(cal.observability.parameters[i].constraint, Constraint::Free);
    }
    // Holding b at a wrong value moves the radii with it (r/b is what the data fix).
    let free = calibrate(&samples, &options(Constraints::default())).expect("solves");
    let ratio_held = cal.params.r_l / cal.params.b;
    let ratio_free = free.params.r_l / free.params.b;
    assert!((ratio_held / ratio_free - 1.0).abs() < 2e-3);
}

#[test]
fn a_prior_combines_with_the_data_as_gaussian_information() {
    let t = truth();
    let mut samples = exact_samples(&mut rng(6), &t, 300, 1);
    add_noise(&mut rng(7), &mut samples, [0.002, 0.002, 0.004]);
    let free = calibrate(&samples, &options(Constraints::default())).expect("solves");
    let sigma_data = free.covariance[4][4].sqrt();
    // A prior as informative as the data on ℓy, centred 3σ away from the truth.
    let prior_sigma = sigma_data;
    let mean = t.laser.y + 3.0 * sigma_data;
    let mut c = Constraints::default();
    c.0[4] = Constraint::Prior {
        mean,
        sigma: prior_sigma,
    };
    let cal = calibrate(&samples, &options(c)).expect("solves");
    let sigma_post = cal.covariance[4][4].sqrt();
    // Posterior σ: 1/σ² adds up (the other parameters' coupling changes it a little).
    let want = 1.0 / (1.0 / sigma_data.powi(2) + 1.0 / prior_sigma.powi(2)).sqrt();
    assert!(
        (sigma_post / want - 1.0).abs() < 0.05,
        "posterior σ {sigma_post:e}, expected about {want:e}"
    );
    // The estimate moves towards the prior mean, about half-way.
    let moved = (cal.params.laser.y - free.params.laser.y) / (mean - free.params.laser.y);
    assert!((0.3..0.7).contains(&moved), "moved {moved}");
    // A very tight prior acts like holding the value.
    c.0[4] = Constraint::Prior { mean, sigma: 1e-9 };
    let tight = calibrate(&samples, &options(c)).expect("solves");
    assert!((tight.params.laser.y - mean).abs() < 1e-8);
}

/// Straight runs only: b, ℓx, ℓy are not excited and the closed form cannot
/// separate r_L from r_R.
fn straight_only() -> Vec<Sample> {
    let t = truth();
    let pred = Predictor::new(&t, true);
    let mut r = rng(8);
    let mut samples: Vec<Sample> = (0..200)
        .map(|_| {
            let mut s = make_sample(&mut r, &t, Motion::Straight, 1);
            s.sm = Pose2::from_array(pred.predict(&s));
            // Encoder noise: the wheels never turn exactly equally.
            s.dphi_l *= 1.0 + 1e-3 * r.random_range(-1.0..1.0);
            s.dphi_r *= 1.0 + 1e-3 * r.random_range(-1.0..1.0);
            s
        })
        .collect();
    add_noise(&mut r, &mut samples, [0.001, 0.001, 0.002]);
    samples
}

#[test]
fn refusal_suggests_fix_and_holding_makes_it_solvable() {
    let samples = straight_only();
    let err = calibrate(&samples, &options(Constraints::default())).expect_err("refused");
    let SolveError::NotExcited { sentence, .. } = &err else {
        panic!("unexpected {err:?}")
    };
    assert!(
        sentence.contains("--fix") && sentence.contains("--prior"),
        "{sentence}"
    );
    let t = truth().to_vector();
    // r_L, b, ℓx, ℓy known: r_R and ℓθ come from the straight runs.
    let c = held(0b011101, &t);
    let cal = calibrate(&samples, &options(c)).expect("solvable with held values");
    assert!(
        (cal.params.r_r / t[1] - 1.0).abs() < 3e-3,
        "{:?}",
        cal.params
    );
    assert!(
        (cal.params.laser.theta - t[5]).abs() < 2e-2,
        "{:?}",
        cal.params
    );
    for i in [1, 5] {
        let z = (cal.params.to_vector()[i] - t[i]) / cal.covariance[i][i].sqrt();
        assert!(z.abs() < 4.0, "parameter {i}: {z}σ");
    }
}

#[test]
fn accept_weak_returns_what_the_verdicts_refuse() {
    // Few, short spins and arcs beside long straight runs: every parameter is
    // determined, but ℓx, ℓy only very poorly.
    let t = truth();
    let pred = Predictor::new(&t, true);
    let mut r = rng(9);
    let mut samples: Vec<Sample> = (0..300)
        .map(|k| {
            let motion = if k % 10 == 0 {
                Motion::Arc
            } else {
                Motion::Straight
            };
            let mut s = make_sample(&mut r, &t, motion, 1);
            if motion == Motion::Arc {
                s.dphi_l *= 0.02;
                s.dphi_r *= 0.02;
            }
            s.sm = Pose2::from_array(pred.predict(&s));
            s
        })
        .collect();
    add_noise(&mut r, &mut samples, [0.003, 0.003, 0.003]);
    let refused = calibrate(&samples, &options(Constraints::default()));
    let Err(SolveError::NotExcited { parameters, .. }) = refused else {
        panic!("expected a refusal, got {refused:?}")
    };
    let opts = SolveOptions {
        accept_weak: true,
        ..options(Constraints::default())
    };
    let cal = calibrate(&samples, &opts).expect("numbers with accept_weak");
    for name in &parameters {
        let rep = cal
            .observability
            .parameters
            .iter()
            .find(|p| &p.name == name)
            .unwrap();
        assert_eq!(rep.verdict, Verdict::NotExcited, "{name}");
    }
}

/// The laser's range scale with held parameters or priors: `range_scale_direction`
/// is how the estimate moves when every scan-matched translation is longer by a
/// relative `s` — checked here by doing it: the samples' translations scaled by
/// `1 + s` and solved again. Free: the whole `(r_L, r_R, b, ℓx, ℓy, 0)`. With `b`
/// held, `b` does not move and the radii move by less than their share (the
/// rotations tie them to `b`); with a prior on `b` it moves by less than its share.
#[test]
fn range_scale_direction_is_how_the_estimate_moves_with_a_scaled_laser() {
    let t = truth();
    let tv = t.to_vector();
    let mut samples = exact_samples(&mut rng(21), &t, 150, 3);
    add_noise(&mut rng(22), &mut samples, [2e-3, 2e-3, 2e-3]);
    // Weights given, not estimated from the residuals: a longer laser would also
    // change the estimated σ (with held parameters the misfit grows), which moves a
    // constrained estimate by a first-order amount of its own, not the scale's.
    let v2 = 4e-6;
    let cov = [[v2, 0.0, 0.0], [0.0, v2, 0.0], [0.0, 0.0, v2]];
    let samples: Vec<Sample> = samples
        .into_iter()
        .map(|x| x.with_covariance(cov))
        .collect();
    let mut prior = Constraints::default();
    prior.0[2] = Constraint::Prior {
        mean: tv[2],
        sigma: 1e-3,
    };
    let s = 1e-4;
    for (name, constraints) in [
        ("free", Constraints::default()),
        ("b held", held(1 << 2, &tv)),
        ("b and l_x held", held((1 << 2) | (1 << 3), &tv)),
        ("b with a prior", prior),
    ] {
        let opts = options(constraints);
        let base = calibrate(&samples, &opts).unwrap();
        let scaled: Vec<Sample> = samples
            .iter()
            .map(|x| Sample {
                sm: Pose2::new(x.sm.x * (1.0 + s), x.sm.y * (1.0 + s), x.sm.theta),
                ..x.clone()
            })
            .collect();
        let moved = calibrate(&scaled, &opts).unwrap();
        let d = base.scale_direction();
        let v = base.params.to_vector();
        let diff = moved.params.difference(&base.params);
        eprintln!("{name}: direction {d:.4?}, parameters {v:.4?}");
        for i in 0..6 {
            let measured = diff[i] / s;
            // First order: within 1 % and 0.1 mm (or mrad) per unit of scale (free,
            // with the translations' weights not scaled along, ℓθ moves by 0.04 mrad).
            assert!(
                (measured - d[i]).abs() <= 0.01 * d[i].abs() + 1e-4,
                "{name} {i}: moved {measured:.6e}, direction {:.6e}",
                d[i]
            );
            if constraints.is_held(i) {
                assert_eq!(d[i], 0.0, "{name} {i}");
            }
        }
        match name {
            "free" => {
                for i in 0..5 {
                    assert!((d[i] - v[i]).abs() <= 1e-15 * v[i].abs().max(1.0), "{i}");
                }
                assert_eq!(d[5], 0.0);
            }
            "b held" => assert!(d[0].abs() < 0.9 * v[0] && d[1].abs() < 0.9 * v[1]),
            "b with a prior" => assert!(d[2].abs() < 0.9 * v[2]),
            _ => {}
        }
    }
}
