//! Samples whose ŝ leaves a direction free (`Sample::free_direction`, a match along
//! a corridor): whatever ŝ says along that direction carries no weight, and the σ
//! stay honest.

mod common;

use common::{add_noise, exact_samples, random_params, rng, test_robot};
use odocal_geom::Pose2;
use odocal_solver::{calibrate, Params, Sample, SolveOptions, Trim};
use rand::Rng;

/// Marks every straight sample (one in three) free along its direction of travel
/// and moves its ŝ along it by `shift(k)` (m).
fn free_along_travel(samples: &mut [Sample], shift: impl Fn(usize) -> f64) {
    for (k, s) in samples.iter_mut().enumerate().filter(|(k, _)| k % 3 == 0) {
        let norm = s.sm.x.hypot(s.sm.y);
        let d = [s.sm.x / norm, s.sm.y / norm, 0.0];
        let a = shift(k);
        s.sm = Pose2::new(s.sm.x + a * d[0], s.sm.y + a * d[1], s.sm.theta);
        s.free_direction = Some(d);
    }
}

/// Largest error relative to the parameter's size (radii, b: own value; offsets:
/// b; ℓθ: radians).
fn worst_error(got: &Params, truth: &Params) -> f64 {
    let d = got.difference(truth);
    let scale = [truth.r_l, truth.r_r, truth.b, truth.b, truth.b, 1.0];
    (0..6).map(|i| d[i].abs() / scale[i]).fold(0.0, f64::max)
}

/// Noise-free samples, a third of them moved 8 cm along their free direction: the
/// estimate is exact; the same samples without the direction marked free give a
/// wrong one, or none.
#[test]
fn what_a_sample_says_along_its_free_direction_carries_no_weight() {
    let mut r = rng(7);
    for seed in 0..10 {
        let truth = random_params(&mut r, None);
        let mut samples = exact_samples(&mut rng(300 + seed), &truth, 90, 1);
        free_along_travel(&mut samples, |k| if k % 2 == 0 { 0.08 } else { -0.08 });
        for trim in [Trim::None, SolveOptions::default().trim] {
            let options = SolveOptions {
                trim,
                ..SolveOptions::default()
            };
            let cal = calibrate(&samples, &options).unwrap();
            let err = worst_error(&cal.params, &truth);
            assert!(err < 1e-8, "seed {seed} {trim:?}: error {err:.2e}");
        }
        let marked_not: Vec<Sample> = samples
            .iter()
            .map(|s| Sample {
                free_direction: None,
                ..s.clone()
            })
            .collect();
        let options = SolveOptions {
            trim: Trim::None,
            ..SolveOptions::default()
        };
        // Unmarked, the shifted samples pull the estimate (or the log is refused).
        if let Ok(cal) = calibrate(&marked_not, &options) {
            assert!(worst_error(&cal.params, &truth) > 1e-3, "seed {seed}");
        }
    }
}

/// Noisy samples, a third of them free and moved up to 10 cm along their free
/// direction: over 300 logs, every parameter's RMS error/σ is within 0.85–1.15, and
/// the free samples' σ are wider than if they fixed every direction.
#[test]
fn sigma_stays_honest_with_free_directions() {
    let truth = test_robot();
    let sigma = [0.002, 0.002, 0.002];
    let mut r = rng(11);
    let (mut sum_sq, mut wider) = ([0.0; 6], 0);
    const LOGS: usize = 300;
    for _ in 0..LOGS {
        let mut samples = exact_samples(&mut r, &truth, 90, 1);
        add_noise(&mut r, &mut samples, sigma);
        let whole = calibrate(&samples, &SolveOptions::default()).unwrap();
        let shifts: Vec<f64> = (0..samples.len())
            .map(|_| r.random_range(-0.1..0.1))
            .collect();
        free_along_travel(&mut samples, |k| shifts[k]);
        let cal = calibrate(&samples, &SolveOptions::default()).unwrap();
        let d = cal.params.difference(&truth);
        for i in 0..6 {
            sum_sq[i] += d[i] * d[i] / cal.covariance[i][i];
        }
        wider += usize::from(cal.covariance[0][0] > whole.covariance[0][0]);
    }
    for (i, s) in sum_sq.iter().enumerate() {
        let rms = (s / LOGS as f64).sqrt();
        assert!(
            (0.85..1.15).contains(&rms),
            "parameter {i}: RMS error/σ {rms:.2}"
        );
    }
    assert!(wider > LOGS * 9 / 10, "{wider} of {LOGS}");
}
