//! Several lasers on one robot (issue 23): a bag with two lidars (`--scan-topic`
//! twice) and two logs whose laser was mounted differently (`--own-laser`): one
//! wheel calibration, one ℓ per laser with σ, the transform between the lasers with
//! its covariance, one URDF joint per laser.

mod common;

use common::{bounds, cleanup, odocal, simulated_log, stderr, temp_dir};
use odocal_geom::{wrap_angle, Pose2};
use serde_json::Value;

const TWO_LIDARS: &str = "fixtures/bags/turtlebot_two_lidars.bag";

fn json(o: &std::process::Output) -> Value {
    assert!(o.status.success(), "{}", stderr(o));
    serde_json::from_slice(&o.stdout).expect("one JSON object")
}

fn pose(v: &Value) -> Pose2 {
    let f = |k: &str| v[k].as_f64().unwrap_or_else(|| panic!("no {k} in {v}"));
    Pose2::new(f("l_x"), f("l_y"), f("l_theta"))
}

fn matrix3(v: &Value) -> nalgebra::Matrix3<f64> {
    nalgebra::Matrix3::from_fn(|i, j| v[i][j].as_f64().expect("a 3x3 covariance"))
}

/// Mahalanobis distance squared of `got − want` (x, y, θ) under `cov`.
fn chi2(got: &Pose2, want: &Pose2, cov: &nalgebra::Matrix3<f64>) -> f64 {
    let e = nalgebra::Vector3::new(
        got.x - want.x,
        got.y - want.y,
        wrap_angle(got.theta - want.theta),
    );
    (e.transpose() * cov.try_inverse().expect("covariance invertible") * e)[0]
}

/// χ²(3) at the 3σ level (0.27 % two-sided).
const CHI2_3_3SIGMA: f64 = 14.16;

#[test]
fn a_bag_with_two_lidars_gives_one_wheel_calibration_and_two_poses() {
    let truth: Value = serde_json::from_str(
        &std::fs::read_to_string("fixtures/bags/turtlebot_two_lidars.truth.json").unwrap(),
    )
    .unwrap();
    let o = odocal(&[
        "calibrate",
        TWO_LIDARS,
        "--scan-topic",
        "/scan_front",
        "--scan-topic",
        "/scan_rear",
        "--json",
    ]);
    let v = json(&o);
    let lasers = v["lasers"].as_array().expect("a row per laser");
    assert_eq!(lasers.len(), 2, "{v}");
    let want: Vec<Pose2> = (0..2).map(|k| pose(&truth["lasers"][k])).collect();
    for (k, row) in lasers.iter().enumerate() {
        assert_eq!(row["topic"], truth["lasers"][k]["topic"]);
        let got = pose(row);
        let c = chi2(&got, &want[k], &matrix3(&row["covariance"]));
        assert!(
            c < CHI2_3_3SIGMA,
            "laser {k}: {got:?} vs {:?}, χ² {c}",
            want[k]
        );
        for i in 0..3 {
            let sigma = row["sigma"][i].as_f64().unwrap();
            assert!(sigma > 0.0 && sigma < 1e-2, "laser {k} σ {i}: {sigma}");
        }
    }
    // The six-parameter fields are the first laser's, with the one set of wheels.
    assert_eq!(pose(&v), pose(&lasers[0]));
    let p = &truth["params"];
    let b = bounds(&[
        p["r_l"].as_f64().unwrap(),
        p["r_r"].as_f64().unwrap(),
        p["b"].as_f64().unwrap(),
    ]);
    for (i, name) in ["r_l", "r_r", "b"].iter().enumerate() {
        let e = v[name].as_f64().unwrap() - p[name].as_f64().unwrap();
        assert!(e.abs() < 2.0 * b[i], "{name}: error {e}");
    }
    // The rear laser in the front one's frame, within its σ of the truth.
    let between = &lasers[1]["from_first"];
    let got = Pose2::new(
        between["x"].as_f64().unwrap(),
        between["y"].as_f64().unwrap(),
        between["theta"].as_f64().unwrap(),
    );
    let want_between = want[0].inverse().compose(&want[1]);
    let c = chi2(&got, &want_between, &matrix3(&between["covariance"]));
    assert!(c < CHI2_3_3SIGMA, "{got:?} vs {want_between:?}: χ² {c}");
    // Both topics' samples are in the one solve; each log row is a topic.
    let rows = v["logs"].as_array().unwrap();
    assert_eq!(rows.len(), 2);
    // The shared wheels are known at least as well as from either laser alone.
    let joint_b = v["sigma"][2].as_f64().unwrap();
    for r in rows {
        let own_b = r["own_sigma"][2].as_f64().unwrap();
        assert!(
            joint_b <= own_b,
            "σ_b joint {joint_b} vs {} alone {own_b}",
            r["path"]
        );
    }
    assert!(rows[1]["path"].as_str().unwrap().ends_with("/scan_rear"));
    let samples: u64 = lasers.iter().map(|l| l["samples"].as_u64().unwrap()).sum();
    assert_eq!(v["samples_synchronized"].as_u64(), Some(samples));
}

#[test]
fn the_summary_export_and_report_show_every_laser() {
    let dir = temp_dir("two-lidars-out");
    let out = dir.join("out");
    let o = odocal(&[
        "calibrate",
        TWO_LIDARS,
        "--scan-topic",
        "/scan_front",
        "--scan-topic",
        "/scan_rear",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let summary = String::from_utf8_lossy(&o.stdout);
    assert!(summary.contains("laser 2 /scan_rear: ℓx"), "{summary}");
    assert!(summary.contains("from laser 1: x"), "{summary}");
    let urdf = std::fs::read_to_string(out.join("laser_joint.urdf.xml")).unwrap();
    assert_eq!(urdf.matches("<origin ").count(), 2, "{urdf}");
    let e = odocal(&[
        "export",
        out.join("results.json").to_str().unwrap(),
        "--format",
        "urdf",
    ]);
    assert!(e.status.success(), "{}", stderr(&e));
    assert_eq!(String::from_utf8_lossy(&e.stdout), urdf);
    let page = std::fs::read_to_string(out.join("results.html")).unwrap();
    assert!(page.contains("id=\"lasers\""), "no lasers section");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn two_logs_with_different_laser_mountings_share_the_wheels() {
    let moved = Pose2::new(-0.02, 0.012, 0.35);
    let (a, truth_a) = simulated_log("own-laser-a", "khepera", 60.0, 61, |_| {});
    let (b, truth_b) = simulated_log("own-laser-b", "khepera", 60.0, 62, |c| {
        c.robot.laser = moved;
    });
    assert_eq!(truth_a[..3], truth_b[..3]);
    let (pa, pb) = (a.to_str().unwrap(), b.to_str().unwrap());

    // One laser for both: the second log disagrees, and the warning or the refusal
    // names the option that gives it its own ℓ.
    let o = odocal(&["calibrate", pa, pb]);
    let all = format!("{}{}", String::from_utf8_lossy(&o.stdout), stderr(&o));
    assert!(all.contains("--own-laser 2"), "{all}");

    let v = json(&odocal(&[
        "calibrate",
        pa,
        pb,
        "--own-laser",
        "2",
        "--json",
    ]));
    let lasers = v["lasers"].as_array().expect("a row per laser");
    assert_eq!(lasers.len(), 2);
    let bound = bounds(&truth_a);
    for (row, truth) in lasers.iter().zip([&truth_a, &truth_b]) {
        let got = pose(row);
        assert!((got.x - truth[3]).abs() < bound[3], "{got:?} vs {truth:?}");
        assert!((got.y - truth[4]).abs() < bound[4], "{got:?} vs {truth:?}");
        assert!(
            wrap_angle(got.theta - truth[5]).abs() < bound[5],
            "{got:?} vs {truth:?}"
        );
    }
    for (i, name) in ["r_l", "r_r", "b"].iter().enumerate() {
        let e = v[name].as_f64().unwrap() - truth_a[i];
        assert!(e.abs() < bound[i], "{name}: error {e}");
    }
    // Each log agrees with its own laser's view of the joint estimate.
    assert!(
        v["logs"]
            .as_array()
            .unwrap()
            .iter()
            .all(|r| r["agree"] != false),
        "{v}"
    );
    cleanup(&a);
    cleanup(&b);
}

#[test]
fn own_laser_out_of_range_is_refused_with_the_count() {
    let o = odocal(&["calibrate", "fixtures/demo.log", "--own-laser", "2"]);
    let err = stderr(&o);
    assert!(!o.status.success());
    assert!(!err.contains("panicked"), "{err}");
    assert!(
        err.contains("--own-laser 2") && err.contains("1 LOG"),
        "{err}"
    );
}

#[test]
fn several_scan_topics_are_for_calibrate_only() {
    let dir = temp_dir("two-lidars-match");
    let out = dir.join("s.tuple");
    let o = odocal(&[
        "match",
        TWO_LIDARS,
        "--scan-topic",
        "/scan_front",
        "--scan-topic",
        "/scan_rear",
        "--out",
        out.to_str().unwrap(),
    ]);
    let err = stderr(&o);
    assert!(!o.status.success(), "{err}");
    assert!(err.contains("odocal calibrate"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}
