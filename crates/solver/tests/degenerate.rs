//! Degenerate and broken inputs give errors that name the problem: motions that do
//! not excite some parameters, too few samples, non-finite values; reversed or
//! swapped encoders are detected.

mod common;

use common::{add_noise, exact_samples, make_sample, rng, Motion};
use odocal_geom::Pose2;
use odocal_solver::{calibrate, Params, Predictor, Sample, SolveError, SolveOptions, Trim};
use rand::rngs::StdRng;
use rand::Rng;

fn truth() -> Params {
    common::test_robot()
}

/// `n` samples of one motion kind, `ŝ` exact, optionally with small noise on `ŝ`
/// and on the wheel rotations (as real encoders would have).
fn only(motion: Motion, n: usize, noisy: bool, r: &mut StdRng) -> Vec<Sample> {
    let p = truth();
    let pred = Predictor::new(&p, true);
    let mut samples: Vec<Sample> = (0..n)
        .map(|_| {
            let mut s = make_sample(r, &p, motion, 1);
            s.sm = Pose2::from_array(pred.predict(&s));
            if noisy {
                s.dphi_l *= 1.0 + 1e-3 * r.random_range(-1.0..1.0);
                s.dphi_r *= 1.0 + 1e-3 * r.random_range(-1.0..1.0);
            }
            s
        })
        .collect();
    if noisy {
        add_noise(r, &mut samples, [0.001, 0.001, 0.002]);
    }
    samples
}

fn not_excited(samples: &[Sample]) -> (Vec<String>, String) {
    for trim in [Trim::None, Trim::TRO] {
        let options = SolveOptions {
            trim,
            ..SolveOptions::default()
        };
        match calibrate(samples, &options) {
            Err(SolveError::NotExcited {
                parameters,
                sentence,
            }) => {
                if trim == Trim::TRO {
                    return (parameters, sentence);
                }
            }
            other => panic!("expected NotExcited, got {other:?}"),
        }
    }
    unreachable!()
}

fn assert_names(names: &[String], want: &[&str], sentence: &str) {
    for w in want {
        assert!(
            names.iter().any(|n| n == w),
            "{w} not named in {names:?} ({sentence})"
        );
    }
    println!("{names:?}: {sentence}");
}

#[test]
fn straight_runs_only() {
    let mut r = rng(20);
    for noisy in [false, true] {
        let (names, sentence) = not_excited(&only(Motion::Straight, 200, noisy, &mut r));
        assert_names(&names, &["b", "l_x", "l_y"], &sentence);
        assert!(!names.iter().any(|n| n == "l_theta"), "{names:?}");
    }
}

#[test]
fn spins_only() {
    let mut r = rng(21);
    for noisy in [false, true] {
        let (names, sentence) = not_excited(&only(Motion::Spin, 200, noisy, &mut r));
        assert_names(&names, &["r_L", "r_R", "b"], &sentence);
    }
}

#[test]
fn identical_turns() {
    let mut r = rng(22);
    // A clear arc: 0.2 m forward while turning 0.6 rad.
    let p = truth();
    let a_l = (0.2 - 0.3 * p.b) / p.r_l;
    let a_r = (0.2 + 0.3 * p.b) / p.r_r;
    let mut base = Sample::from_rotations(0.5, a_l, a_r, Pose2::IDENTITY);
    base.sm = Pose2::from_array(Predictor::new(&p, true).predict(&base));
    let exact: Vec<Sample> = (0..100).map(|_| base.clone()).collect();
    let (names, sentence) = not_excited(&exact);
    assert_names(&names, &["r_L", "r_R", "b"], &sentence);
    let mut noisy = exact.clone();
    add_noise(&mut r, &mut noisy, [0.001, 0.001, 0.002]);
    for s in &mut noisy {
        s.dphi_l *= 1.0 + 1e-4 * r.random_range(-1.0..1.0);
        s.dphi_r *= 1.0 + 1e-4 * r.random_range(-1.0..1.0);
    }
    let (names, sentence) = not_excited(&noisy);
    assert_names(&names, &["r_L", "r_R", "b"], &sentence);
}

#[test]
fn robot_standing_still() {
    let samples: Vec<Sample> = (0..50)
        .map(|_| Sample::from_rotations(0.1, 0.0, 0.0, Pose2::IDENTITY))
        .collect();
    let (names, _) = not_excited(&samples);
    assert_eq!(names.len(), 6);
}

#[test]
fn too_few_samples() {
    let mut r = rng(23);
    let samples = exact_samples(&mut r, &truth(), 5, 1);
    match calibrate(&samples, &SolveOptions::default()) {
        Err(SolveError::TooFewSamples { got: 5, .. }) => {}
        other => panic!("expected TooFewSamples, got {other:?}"),
    }
}

#[test]
fn non_finite_sample_is_named() {
    let mut r = rng(24);
    let mut samples = exact_samples(&mut r, &truth(), 60, 1);
    samples[17].sm.theta = f64::NAN;
    match calibrate(&samples, &SolveOptions::default()) {
        Err(e @ SolveError::NonFinite { index: 17, .. }) => {
            assert!(e.to_string().contains("sample 17"), "{e}");
            assert!(e.to_string().contains("sm.theta"), "{e}");
        }
        other => panic!("expected NonFinite, got {other:?}"),
    }
    samples[17].sm.theta = 0.0;
    samples[33].dphi_r = f64::INFINITY;
    assert!(matches!(
        calibrate(&samples, &SolveOptions::default()),
        Err(SolveError::NonFinite { index: 33, .. })
    ));
}

#[test]
fn reversed_left_encoder_is_detected() {
    let mut r = rng(25);
    let mut samples = exact_samples(&mut r, &truth(), 90, 1);
    for s in &mut samples {
        s.dphi_l = -s.dphi_l;
    }
    let cal = calibrate(&samples, &SolveOptions::default()).expect("calibration");
    assert!(cal.params.r_l < 0.0 && cal.params.r_r > 0.0);
    assert!((cal.params.r_l + truth().r_l).abs() < 1e-9);
    let note = cal.observability.wheel_signs.expect("a note");
    assert!(note.contains("left encoder"), "{note}");
}

#[test]
fn swapped_wheels_are_detected() {
    let t = truth();
    let mut r = rng(26);
    let mut samples = exact_samples(&mut r, &t, 90, 1);
    for s in &mut samples {
        std::mem::swap(&mut s.dphi_l, &mut s.dphi_r);
    }
    let cal = calibrate(&samples, &SolveOptions::default()).expect("calibration");
    let p = cal.params;
    assert!(p.r_l < 0.0 && p.r_r < 0.0);
    // The magnitudes are the true radii, exchanged; ℓ is rotated by π.
    assert!((p.r_l + t.r_r).abs() < 1e-9 && (p.r_r + t.r_l).abs() < 1e-9);
    assert!((p.b - t.b).abs() < 1e-9);
    let note = cal.observability.wheel_signs.expect("a note");
    assert!(note.contains("swapped"), "{note}");
}

#[test]
fn trimming_removes_gross_outliers() {
    let t = truth();
    let mut r = rng(27);
    let mut samples = exact_samples(&mut r, &t, 1000, 1);
    add_noise(&mut r, &mut samples, [0.001, 0.001, 0.002]);
    // 2 % gross outliers (scan matching failures).
    for s in samples.iter_mut().step_by(50) {
        s.sm = Pose2::new(s.sm.x + 0.2, s.sm.y - 0.15, s.sm.theta + 0.5);
    }
    let err = |trim: Trim| {
        let options = SolveOptions {
            trim,
            ..SolveOptions::default()
        };
        let cal = calibrate(&samples, &options).expect("calibration");
        let d = cal.params.difference(&t);
        (d[2].abs() / t.b, cal)
    };
    let (none, _) = err(Trim::None);
    let (tro, cal) = err(Trim::TRO);
    let (icra, _) = err(Trim::ICRA);
    println!("relative b error: none {none:.2e}, tro {tro:.2e}, icra {icra:.2e}");
    assert!(tro < 0.01 && icra < 0.01);
    assert!(none > 3.0 * tro.max(icra));
    // Every outlier was dropped by the T-RO rule.
    assert!(cal.used.iter().step_by(50).all(|&u| !u));
}
