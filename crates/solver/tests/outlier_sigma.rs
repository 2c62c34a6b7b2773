//! One huge outlier (a 10 m scan-matching failure) is trimmed and leaves the noise
//! estimate — hence every reported σ — as it is without it.

mod common;

use common::{add_noise, exact_samples, rng};
use odocal_geom::Pose2;
use odocal_solver::{calibrate, SolveOptions, Trim};

#[test]
fn one_huge_outlier_does_not_inflate_sigma() {
    let t = common::test_robot();
    let mut r = rng(22);
    let mut clean = exact_samples(&mut r, &t, 300, 1);
    add_noise(&mut r, &mut clean, [0.001, 0.001, 0.002]);
    let mut hostile = clean.clone();
    let s = &mut hostile[150];
    s.sm = Pose2::new(s.sm.x + 10.0, s.sm.y, s.sm.theta);
    for trim in [Trim::CHI2, Trim::TRO, Trim::ICRA] {
        let options = SolveOptions {
            trim,
            ..SolveOptions::default()
        };
        let a = calibrate(&clean, &options).expect("clean calibration");
        let b = calibrate(&hostile, &options).expect("calibration with the outlier");
        assert!(!b.used[150], "{trim:?}: the outlier was kept");
        for c in 0..3 {
            let ratio = b.sm_sigma[c] / a.sm_sigma[c];
            assert!(
                (0.8..1.25).contains(&ratio),
                "{trim:?}: noise σ[{c}] {:.3e} with the outlier, {:.3e} without (×{ratio:.1})",
                b.sm_sigma[c],
                a.sm_sigma[c]
            );
        }
        for k in 0..6 {
            let ratio = (b.covariance[k][k] / a.covariance[k][k]).sqrt();
            assert!(
                (0.8..1.25).contains(&ratio),
                "{trim:?}: parameter σ[{k}] ×{ratio:.2} with the outlier"
            );
        }
    }
}
