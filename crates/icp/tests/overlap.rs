//! The overlap test's share: of the current scan's points the reference could have
//! matched, how many it did. Where the reference has no local line (clutter, mixed
//! pixels, scattered readings), current points landing there are not held against a
//! right match; current points landing where the reference saw nothing
//! within the correspondence gate still are.

mod common;

use common::{exact, urg_angles, World};
use odocal_geom::Pose2;
use odocal_icp::{IcpError, IcpParams, Matcher, PreparedScan};

fn room_scan(pose: &Pose2) -> Vec<f32> {
    exact(&World::room().scan(pose, &urg_angles()))
}

#[test]
fn stretches_without_reference_lines_do_not_refuse_a_right_match() {
    let angles = urg_angles();
    let params = IcpParams::default();
    let mut lossy = room_scan(&Pose2::IDENTITY);
    // Stretches where the reference has no local line (readings scattered ±3 cm, as
    // on clutter or mixed pixels): 12 rays of every 30.
    for (i, r) in lossy.iter_mut().enumerate() {
        if i % 30 < 12 {
            *r += if i % 2 == 0 { 0.03 } else { -0.03 };
        }
    }
    let truth = Pose2::new(0.04, -0.02, 0.01);
    let reference = PreparedScan::new(&lossy, &angles, 0.02, 4.0, &params).expect("reference");
    let current =
        PreparedScan::new(&room_scan(&truth), &angles, 0.02, 4.0, &params).expect("current");
    let r = Matcher::new(params)
        .match_scans(&reference, &current, Pose2::new(0.03, -0.01, 0.0))
        .expect("a right match is accepted");
    let e = truth.inverse().compose(&r.pose);
    println!(
        "{} points used, share {:.2}, error {e}",
        r.correspondences, r.matched_share
    );
    assert!(r.matched_share >= 0.7, "{}", r.matched_share);
    assert!(e.translation_norm() < 1e-4 && e.theta.abs() < 1e-4, "{e}");
}

#[test]
fn points_in_space_the_reference_never_saw_still_count() {
    // The reference sees only part of the room; the current scan all of it: its
    // points beyond what the reference saw find no reference point within the gate
    // and count against the share, which falls below 70 %.
    let angles = urg_angles();
    let params = IcpParams::default();
    let mut part = room_scan(&Pose2::IDENTITY);
    for r in part.iter_mut().skip(420) {
        *r = 0.0;
    }
    let reference = PreparedScan::new(&part, &angles, 0.02, 4.0, &params).expect("reference");
    let current = PreparedScan::new(&room_scan(&Pose2::IDENTITY), &angles, 0.02, 4.0, &params)
        .expect("current");
    let err = Matcher::new(params)
        .match_scans(&reference, &current, Pose2::IDENTITY)
        .unwrap_err();
    println!("{err}");
    assert!(matches!(err, IcpError::SmallOverlap { .. }), "{err}");
}
