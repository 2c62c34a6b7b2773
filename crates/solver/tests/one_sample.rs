//! A parameter that one sample determines almost alone is not "well determined": a
//! straight drive with a single spin in place (the spin alone fixes ℓx, ℓy) is judged
//! weak on them, naming the sample; with a dozen spins it is not.

mod common;

use common::{add_noise, make_sample, rng, Motion};
use odocal_geom::Pose2;
use odocal_solver::{calibrate, Predictor, Sample, SolveOptions, Verdict, ONE_SAMPLE_SIGMA_RATIO};

/// `straight` straight runs with `spins` spins in place spread among them (the
/// indices of the spins returned too), `ŝ` with small noise; every interval is
/// stamped (scan times) so the finding can name it.
fn drive(straight: usize, spins: usize, seed: u64) -> (Vec<Sample>, Vec<usize>) {
    let p = common::test_robot();
    let pred = Predictor::new(&p, true);
    let mut r = rng(seed);
    let n = straight + spins;
    let spin_at: Vec<usize> = (0..spins).map(|i| (2 * i + 1) * n / (2 * spins)).collect();
    let mut samples: Vec<Sample> = (0..n)
        .map(|k| {
            let motion = if spin_at.contains(&k) {
                Motion::Spin
            } else {
                Motion::Straight
            };
            let mut s = make_sample(&mut r, &p, motion, 1);
            s.sm = Pose2::from_array(pred.predict(&s));
            s.scan_times = Some([k as f64, k as f64 + 0.4]);
            s
        })
        .collect();
    add_noise(&mut r, &mut samples, [0.001, 0.001, 0.002]);
    (samples, spin_at)
}

#[test]
fn one_spin_among_straight_runs_leaves_the_laser_offset_weak() {
    let (samples, spin_at) = drive(60, 1, 3);
    let options = SolveOptions {
        accept_weak: true,
        ..SolveOptions::default()
    };
    let c = calibrate(&samples, &options).expect("solves with --accept-weak");
    let obs = &c.observability;
    let names: Vec<&str> = obs
        .one_sample
        .iter()
        .map(|s| s.parameter.as_str())
        .collect();
    for want in ["l_x", "l_y"] {
        assert!(
            names.contains(&want),
            "{want} not found resting on the spin: {names:?}"
        );
    }
    for s in &obs.one_sample {
        assert_eq!(
            s.sample, spin_at[0],
            "{} rests on sample {}",
            s.parameter, s.sample
        );
        assert!(
            s.sigma_ratio.is_none_or(|r| r > ONE_SAMPLE_SIGMA_RATIO),
            "{s:?}"
        );
        let p = obs
            .parameters
            .iter()
            .find(|p| p.name == s.parameter)
            .expect("named");
        if s.decides_verdict {
            assert_ne!(p.verdict, Verdict::WellDetermined, "{}", p.name);
        }
    }
    // ℓx and ℓy: well determined with the spin's σ, but not without it.
    for name in ["l_x", "l_y"] {
        let s = obs
            .one_sample
            .iter()
            .find(|s| s.parameter == name)
            .expect("found");
        assert!(s.decides_verdict, "{s:?}");
    }
    assert!(
        obs.sentence.contains("on one sample (scans at"),
        "{}",
        obs.sentence
    );
}

#[test]
fn many_spins_share_the_information() {
    let (samples, _) = drive(60, 12, 4);
    let c = calibrate(&samples, &SolveOptions::default()).expect("all well determined");
    assert!(
        c.observability.one_sample.is_empty(),
        "{:?}",
        c.observability.one_sample
    );
}
