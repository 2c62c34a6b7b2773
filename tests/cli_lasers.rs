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
    // The shared wheels are known at least as well as from either laser alone (to 1 %:
    // each solve scales its σ by the noise its own residuals show; with the rear
    // SICK-like laser's readings used to its 8 m, σ_b is 0.159 mm from it alone and
    // 1.8 mm from the front LDS alone, so the joint solve can add almost nothing).
    let joint_b = v["sigma"][2].as_f64().unwrap();
    for r in rows {
        let own_b = r["own_sigma"][2].as_f64().unwrap();
        assert!(
            joint_b <= 1.01 * own_b,
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
fn match_writes_each_lasers_samples_to_its_own_file() {
    let dir = temp_dir("two-lidars-match");
    let (front, rear) = (dir.join("front.tuple"), dir.join("rear.tuple"));
    let o = odocal(&[
        "match",
        TWO_LIDARS,
        "--scan-topic",
        "/scan_front",
        "--scan-topic",
        "/scan_rear",
        "--out",
        front.to_str().unwrap(),
        "--out",
        rear.to_str().unwrap(),
    ]);
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    // Each file holds its laser's samples: solved alone, each gives its own laser's
    // pose (front near ℓθ 0, rear turned by about π), as `calibrate` does per topic.
    for (file, topic, theta) in [(&front, "/scan_front", 0.012), (&rear, "/scan_rear", 3.1)] {
        let text = std::fs::read_to_string(file).unwrap();
        let samples = text.lines().filter(|l| !l.trim().is_empty()).count();
        assert!(samples > 30, "{topic}: {samples} samples\n{err}");
        assert!(
            err.contains(&format!("samples written to {}", file.display())),
            "{err}"
        );
        let v = json(&odocal(&[
            "solve",
            file.to_str().unwrap(),
            "--json",
            "--accept-weak",
        ]));
        let got = v["l_theta"].as_f64().expect("l_theta");
        assert!(wrap_angle(got - theta).abs() < 0.05, "{topic}: ℓθ {got}");
    }
    // One --out for two lasers: refused, with the command that works.
    let o = odocal(&[
        "match",
        TWO_LIDARS,
        "--scan-topic",
        "/scan_front",
        "--scan-topic",
        "/scan_rear",
        "--out",
        front.to_str().unwrap(),
    ]);
    let err = stderr(&o);
    assert!(!o.status.success(), "{err}");
    assert!(err.contains("--out front.tuple --out rear.tuple"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn fix_and_prior_name_a_laser_with_at() {
    let o = odocal(&[
        "calibrate",
        TWO_LIDARS,
        "--scan-topic",
        "/scan_front",
        "--scan-topic",
        "/scan_rear",
        "--fix",
        "l_x@2=-0.12",
        "--prior",
        "l_theta@2=3.1+-0.01",
        "--prior",
        "b=0.1614+-0.0001",
        "--json",
    ]);
    let v = json(&o);
    let rear = &v["lasers"][1];
    assert_eq!(rear["l_x"].as_f64(), Some(-0.12), "{rear}");
    assert_eq!(rear["sigma"][0].as_f64(), Some(0.0), "{rear}");
    // The first laser's ℓx is not held; the wheel prior shows on b.
    assert!(v["lasers"][0]["sigma"][0].as_f64().unwrap() > 0.0);
    let free = json(&odocal(&[
        "calibrate",
        TWO_LIDARS,
        "--scan-topic",
        "/scan_front",
        "--scan-topic",
        "/scan_rear",
        "--json",
    ]));
    let sigma_b = |v: &Value| v["sigma"][2].as_f64().expect("σ of b");
    assert!(
        sigma_b(&v) < 0.8 * sigma_b(&free),
        "{} vs {}",
        sigma_b(&v),
        sigma_b(&free)
    );
    // ℓθ of laser 2 with a 0.01 rad prior: its σ is at most the prior's.
    assert!(rear["sigma"][2].as_f64().unwrap() <= 0.01, "{rear}");
    // A laser that does not exist, a wheel with a laser number, a laser number with
    // one laser: each refused with what to give instead.
    for (args, want) in [
        (
            vec![
                "--scan-topic",
                "/scan_front",
                "--scan-topic",
                "/scan_rear",
                "--fix",
                "l_y@3=0",
            ],
            "this calibration has 2 laser(s)",
        ),
        (
            vec![
                "--scan-topic",
                "/scan_front",
                "--scan-topic",
                "/scan_rear",
                "--fix",
                "b@2=0.16",
            ],
            "give b without @2",
        ),
        (
            vec!["--scan-topic", "/scan_front", "--fix", "l_x@2=0.1"],
            "has 1 laser(s)",
        ),
        (
            vec!["--scan-topic", "/scan_front", "--fix", "l_x@two=0.1"],
            "the laser's number from 1",
        ),
    ] {
        let mut all = vec!["calibrate", TWO_LIDARS];
        all.extend(args);
        let o = odocal(&all);
        let err = stderr(&o);
        assert!(!o.status.success(), "{all:?}: {err}");
        assert!(!err.contains("panicked"), "{err}");
        assert!(err.contains(want), "{all:?}: {err}");
    }
}

#[test]
fn the_second_lasers_nominal_pose_comes_from_tf_static() {
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
        "--nominal",
        "0.033,0.033,0.16",
        "--json",
    ]);
    let err = stderr(&o);
    let v = json(&o);
    // The rear laser's frame is in /tf_static: its row names the source and the
    // pose (the truth rounded as a CAD model gives it), and stderr says it seeds
    // that laser's first guesses.
    let rear = &v["lasers"][1]["nominal"];
    assert_eq!(rear["source"], "/tf_static", "{v}");
    assert_eq!(rear["laser_frame"], "rear_laser", "{rear}");
    let want = pose(&truth["lasers"][1]);
    assert!((pose(rear).x - want.x).abs() < 1e-3 && (pose(rear).theta - want.theta).abs() < 0.01);
    assert_eq!(v["lasers"][0]["nominal"]["laser_frame"], "laser", "{v}");
    assert!(
        err.contains("laser 2: nominal pose from the bag's /tf_static (base_link -> rear_laser)"),
        "{err}"
    );
    // Seeded from the bag, the rear laser still lands on its truth.
    let got = pose(&v["lasers"][1]);
    assert!((got.x - want.x).abs() < 0.005 && wrap_angle(got.theta - want.theta).abs() < 0.02);
}
