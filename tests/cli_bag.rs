//! The command line on bags: `info --json` carries the topics and the same keys as for
//! logs; odometry-only mode without `--nominal` is refused with the flag to give, by
//! `calibrate` and by `match`, and with it `match` writes samples that `solve`
//! calibrates; bag flags on a Carmen log are refused; a ROS 2 bag directory calibrates
//! from the command line with its files' checksum in the provenance.

mod common;

use std::process::Command;

fn odocal(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_odocal"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("odocal runs")
}

#[test]
fn info_json_has_topics_and_the_log_keys() {
    let out = odocal(&["info", "fixtures/bags/turtlebot_lds.bag", "--json"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["topics"]["/scan"]["type"], "sensor_msgs/LaserScan");
    assert_eq!(v["topics"]["/scan"]["count"], 299);
    assert_eq!(v["topics"]["/joint_states"]["count"], 3001);
    assert_eq!(v["scans"], 299);
    assert_eq!(v["encoder_records"], 3001);
    assert_eq!(v["rays_per_scan"], 360);
    assert!(v["duration_s"].as_f64().unwrap() > 59.0);
    assert_eq!(v["calibration_uses"]["wheels"]["left"], "wheel_left_joint");
}

#[test]
fn a_ros2_bag_directory_calibrates_with_its_checksum() {
    let dir = "fixtures/bags/khepera_ros2_dir";
    let out = odocal(&["calibrate", dir, "--json"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let sha = v["provenance"]["input_sha256"].as_str().unwrap();
    assert!(
        sha.len() == 64 && sha.bytes().all(|c| c.is_ascii_hexdigit()),
        "{sha}"
    );
    let files: u64 = std::fs::read_dir(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(dir))
        .unwrap()
        .map(|e| e.unwrap().metadata().unwrap().len())
        .sum();
    assert_eq!(v["provenance"]["input_bytes"].as_u64(), Some(files));
}

#[test]
fn odometry_only_needs_the_nominal_parameters() {
    let out = odocal(&["calibrate", "fixtures/bags/khepera_ros1_bz2_odom.bag"]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("--nominal r_L,r_R,b") && err.contains("khepera_ros1_bz2_odom.bag"),
        "{err}"
    );
}

#[test]
fn nominal_values_in_millimetres_are_refused_and_odometry_only_states_its_caveat() {
    let bag = "fixtures/bags/khepera_ros1_bz2_odom.bag";
    let out = odocal(&["calibrate", bag, "--nominal", "21,21,88.4"]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("metres") && err.contains("--nominal 0.021,0.021,0.0884"),
        "{err}"
    );
    let out = odocal(&[
        "calibrate",
        bag,
        "--nominal",
        "0.021,0.021,0.0884",
        "--json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let note = v["odometry_only"]["note"].as_str().unwrap_or_default();
    assert!(note.contains("only as good as --nominal"), "{v}");
}

#[test]
fn match_takes_the_nominal_parameters_of_odometry_only_input() {
    let bag = "fixtures/bags/khepera_ros1_bz2_odom.bag";
    let dir = common::temp_dir("match-nominal");
    let tuples = dir.join("odom.tuple");
    let tuples = tuples.to_str().unwrap();
    let out = odocal(&["match", bag, "--out", tuples]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("--nominal r_L,r_R,b") && err.contains(bag),
        "{err}"
    );

    let out = odocal(&[
        "match",
        bag,
        "--out",
        tuples,
        "--nominal",
        "0.021,0.021,0.0884",
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(err.contains("odometry-only mode"), "{err}");
    let out = odocal(&["solve", tuples, "--json"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let truth_json = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("fixtures/bags/khepera_ros1_bz2_odom.truth.json"),
    )
    .unwrap();
    let truth: odocal_geom::FlatParams = serde_json::from_value(
        serde_json::from_str::<serde_json::Value>(&truth_json).unwrap()["params"].clone(),
    )
    .unwrap();
    let truth = truth.to_array();
    let bounds = common::bounds(&truth);
    for (i, name) in ["r_l", "r_r", "b", "l_x", "l_y", "l_theta"]
        .iter()
        .enumerate()
    {
        let err = v[name].as_f64().unwrap() - truth[i];
        assert!(err.abs() < bounds[i], "{name}: error {err:.3e}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bag_flags_on_a_carmen_log_are_refused() {
    let out = odocal(&["info", "fixtures/demo.log", "--scan-topic", "/scan"]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("apply to ROS bags"), "{err}");
}

#[test]
fn calibrate_skips_a_malformed_scan_and_says_so() {
    // The first scan of the bag declares 36 ranges where its angles make more (issue
    // 21's 36-for-361): it is skipped and counted, and `calibrate` shows the warning
    // that `info` shows. Before: the whole bag was refused, with --lenient too.
    let src = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("fixtures/bags/khepera_ros1_plain_cw.bag");
    let mut bytes = std::fs::read(src).unwrap();
    let frame = b"\x05\x00\x00\x00laser";
    let at = bytes.windows(frame.len()).position(|w| w == frame).unwrap();
    let count = at + frame.len() + 7 * 4;
    bytes[count..count + 4].copy_from_slice(&36u32.to_le_bytes());
    let path = std::env::temp_dir().join(format!("odocal-cli-36-rays-{}.bag", std::process::id()));
    std::fs::write(&path, &bytes).unwrap();
    let out = odocal(&["calibrate", path.to_str().unwrap()]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(
        stderr.contains(
            "warning: topic /scan: 1 malformed scan message(s) skipped, the first (message 0"
        ),
        "{stderr}"
    );
    std::fs::remove_file(path).unwrap();
}

#[test]
fn info_findings_on_a_bag_name_the_topic_message_and_stamp() {
    // turtlebot_tf.bag records one /joint_states message twice. Before: "1 ENCODER
    // record(s) repeat … first at line 302" — a bag has no lines, and its user looks
    // for a topic, a message and a stamp.
    for (flags, clock) in [
        (&[][..], "header stamp 1190000"),
        (&["--use-receive-time"][..], "receive time 1190000"),
    ] {
        let mut args = vec!["info", "fixtures/bags/turtlebot_tf.bag"];
        args.extend_from_slice(flags);
        let out = odocal(&args);
        let text = String::from_utf8_lossy(&out.stdout).into_owned();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let finding = text
            .lines()
            .find(|l| l.contains("[duplicate]"))
            .unwrap_or_else(|| panic!("no duplicate finding: {text}"));
        assert!(
            finding.contains("/joint_states messages repeat an earlier one")
                && finding.contains("first at /joint_states message ")
                && finding.contains(clock),
            "{finding}"
        );
        for carmen_word in ["line ", "ENCODER", "record(s)"] {
            assert!(
                !finding.contains(carmen_word),
                "{carmen_word:?} in {finding}"
            );
        }
        // A LaserScan has no Carmen laser type.
        assert!(!text.contains("laser type"), "{text}");
    }
}

#[test]
fn the_calibration_summary_of_a_bag_counts_messages_not_encoder_records() {
    // Before: "200 scans, 1001 encoder records" for a bag's joint states.
    let out = odocal(&["calibrate", "fixtures/bags/khepera_ros1_lz4.bag"]);
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        text.contains("200 scans, 1001 /joint_states messages"),
        "{text}"
    );
    assert!(!text.contains("encoder records"), "{text}");
}

#[test]
fn the_nominal_laser_pose_comes_from_robot_description_when_tf_static_lacks_it() {
    // urdf_only.bag: /tf_static has base_footprint -> base_link only; the URDF in
    // robot_description has base_link -> laser_mount (x 0.1 m, z 0.05 m, yaw π/2) ->
    // base_scan (x 0.02 m), so the laser is at (0.1, 0.02) m, yaw π/2 in base_link.
    // Before: no nominal_laser (the URDF was not read).
    let out = odocal(&["info", "fixtures/bags/urdf_only.bag", "--json"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let l = &v["nominal_laser"];
    assert_eq!(l["source"], "robot_description", "{l}");
    assert_eq!(l["base_frame"], "base_link", "{l}");
    assert_eq!(l["laser_frame"], "base_scan", "{l}");
    let near = |key: &str, expected: f64| {
        let x = l[key].as_f64().unwrap_or(f64::NAN);
        assert!((x - expected).abs() < 1e-9, "{key}: {x} vs {expected}");
    };
    near("x", 0.1);
    near("y", 0.02);
    near("theta", std::f64::consts::FRAC_PI_2);
    near("z", 0.05);
    // Where the bag has both, the transforms the robot published win.
    let out = odocal(&["info", "fixtures/bags/turtlebot_tf.bag", "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["nominal_laser"]["source"], "/tf_static");
}
