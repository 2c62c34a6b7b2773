//! Bad input gives a clear error, never a panic.

mod common;

use common::{exact, urg_angles, World};
use odocal_geom::Pose2;
use odocal_icp::{IcpError, IcpParams, Matcher, PreparedScan};

fn room_scan(pose: &Pose2) -> Vec<f32> {
    exact(&World::room().scan(pose, &urg_angles()))
}

#[test]
fn all_invalid_scan_is_rejected() {
    let angles = urg_angles();
    let params = IcpParams::default();
    for bad in [0.0f32, f32::NAN, f32::INFINITY, -1.0, 10.0, 0.01] {
        let ranges = vec![bad; angles.len()];
        let err = PreparedScan::new(&ranges, &angles, 0.02, 4.0, &params).unwrap_err();
        assert_eq!(
            err,
            IcpError::TooFewValidPoints {
                valid: 0,
                total: 681,
                needed: params.min_valid_points
            }
        );
        println!("{bad}: {err}");
    }
}

#[test]
fn too_few_points_are_rejected() {
    let angles = urg_angles();
    let params = IcpParams::default();
    let mut ranges = room_scan(&Pose2::IDENTITY);
    for r in ranges.iter_mut().skip(10) {
        *r = 0.0;
    }
    let err = PreparedScan::new(&ranges, &angles, 0.02, 4.0, &params).unwrap_err();
    assert!(
        matches!(err, IcpError::TooFewValidPoints { valid: 10, .. }),
        "{err}"
    );
    assert!(err.to_string().contains("10 valid readings"), "{err}");
}

#[test]
fn nan_ranges_are_invalid_readings_not_a_crash() {
    let angles = urg_angles();
    let params = IcpParams::default();
    let clean = room_scan(&Pose2::IDENTITY);
    let mut dirty = clean.clone();
    for r in dirty.iter_mut().step_by(3) {
        *r = f32::NAN;
    }
    let reference = PreparedScan::new(&clean, &angles, 0.02, 4.0, &params).expect("reference");
    let current = PreparedScan::new(&dirty, &angles, 0.02, 4.0, &params).expect("current");
    assert_eq!(
        current.valid_count(),
        clean.iter().filter(|r| **r > 0.0).count() - 227
    );
    let r = Matcher::new(params)
        .match_scans(&reference, &current, Pose2::new(0.01, 0.0, 0.0))
        .expect("the remaining two thirds still match");
    assert!(
        r.pose.translation_norm() < 1e-6 && r.pose.theta.abs() < 1e-7,
        "{}",
        r.pose
    );
}

#[test]
fn mismatched_inputs_and_nan_guess_are_errors() {
    let angles = urg_angles();
    let params = IcpParams::default();
    let ranges = room_scan(&Pose2::IDENTITY);
    let err = PreparedScan::new(&ranges[..100], &angles, 0.02, 4.0, &params).unwrap_err();
    assert!(matches!(err, IcpError::InvalidScan(_)), "{err}");
    let mut bad_angles = angles.clone();
    bad_angles[5] = f64::NAN;
    let err = PreparedScan::new(&ranges, &bad_angles, 0.02, 4.0, &params).unwrap_err();
    assert!(err.to_string().contains("angle 5"), "{err}");

    let scan = PreparedScan::new(&ranges, &angles, 0.02, 4.0, &params).expect("scan");
    let err = Matcher::new(params.clone())
        .match_scans(&scan, &scan, Pose2::new(f64::NAN, 0.0, 0.0))
        .unwrap_err();
    assert!(matches!(err, IcpError::NonFiniteGuess(_)), "{err}");

    let bad = IcpParams {
        trim_fraction: 0.0,
        ..params.clone()
    };
    let err = Matcher::new(bad)
        .match_scans(&scan, &scan, Pose2::IDENTITY)
        .unwrap_err();
    assert!(matches!(err, IcpError::InvalidParams(_)), "{err}");

    for window in [(f64::NAN, 0.05, 0.2), (0.05, 0.0, 0.2), (0.05, 0.05, -1.0)] {
        let bad = IcpParams {
            guess_window: Some(odocal_icp::GuessWindow {
                xy: window.0,
                theta: window.1,
                share: window.2,
            }),
            ..params.clone()
        };
        let err = Matcher::new(bad)
            .match_scans(&scan, &scan, Pose2::IDENTITY)
            .unwrap_err();
        assert!(err.to_string().contains("guess_window"), "{err}");
    }
}

#[test]
fn far_jump_is_refused() {
    let angles = urg_angles();
    let params = IcpParams {
        max_linear_correction: 0.02,
        ..IcpParams::default()
    };
    let reference = PreparedScan::new(&room_scan(&Pose2::IDENTITY), &angles, 0.02, 4.0, &params)
        .expect("reference");
    let current = PreparedScan::new(
        &room_scan(&Pose2::new(0.05, 0.0, 0.0)),
        &angles,
        0.02,
        4.0,
        &params,
    )
    .expect("current");
    let err = Matcher::new(params)
        .match_scans(&reference, &current, Pose2::IDENTITY)
        .unwrap_err();
    assert!(matches!(err, IcpError::CorrectionTooLarge { .. }), "{err}");
    println!("{err}");
}

#[test]
fn disjoint_scans_have_too_few_correspondences() {
    // Reference sees only the left half, current only the right half.
    let angles = urg_angles();
    let params = IcpParams::default();
    let full = room_scan(&Pose2::IDENTITY);
    let mut left = full.clone();
    let mut right = full;
    for (i, (l, r)) in left.iter_mut().zip(right.iter_mut()).enumerate() {
        if i < 340 {
            *l = 0.0;
        } else {
            *r = 0.0;
        }
    }
    let reference = PreparedScan::new(&left, &angles, 0.02, 4.0, &params).expect("reference");
    let current = PreparedScan::new(&right, &angles, 0.02, 4.0, &params).expect("current");
    let err = Matcher::new(params)
        .match_scans(&reference, &current, Pose2::IDENTITY)
        .unwrap_err();
    println!("{err}");
    assert!(
        matches!(
            err,
            IcpError::TooFewCorrespondences { .. } | IcpError::CorrectionTooLarge { .. }
        ),
        "{err}"
    );
}
