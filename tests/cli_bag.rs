//! The command line on bags: `info --json` carries the topics and the same keys as for
//! logs; odometry-only mode without `--nominal` is refused with the flag to give; bag
//! flags on a Carmen log are refused.

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
fn bag_flags_on_a_carmen_log_are_refused() {
    let out = odocal(&["info", "fixtures/demo.log", "--scan-topic", "/scan"]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("apply to ROS bags"), "{err}");
}
