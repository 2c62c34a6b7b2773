//! Odometry-only mode on `/odom` whose heading comes from a gyro (kobuki_node's
//! default, TurtleBot3, iRobot Create 3): refused by name, with the command that
//! calibrates from the bag's wheel joint states — which then agrees with the truth —
//! and, with `--accept-weak`, a `gyro_heading` finding and no parameter "well
//! determined". The same run's `/odom` with the heading from the wheels still
//! calibrates, to the truth and to exactly what the wheel joints give. Fixtures:
//! fixtures/bags/turtlebot_odom_{gyro,wheel}_heading.bag (make_bags.py), one simulated
//! 30 s TurtleBot run with true wheels 0.0331 / 0.0329 m and b 0.1614 m against the
//! nominal 0.033, 0.033, 0.16.

use serde_json::Value;
use std::process::{Command, Output};

const GYRO: &str = "fixtures/bags/turtlebot_odom_gyro_heading.bag";
const WHEEL: &str = "fixtures/bags/turtlebot_odom_wheel_heading.bag";
const NOMINAL: &str = "0.033,0.033,0.16";

fn odocal(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_odocal"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("odocal runs")
}

fn json(out: &Output) -> Value {
    serde_json::from_slice(&out.stdout).unwrap_or_else(|e| {
        panic!(
            "{e}: {}\n{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        )
    })
}

/// r_L, r_R, b, l_x, l_y, l_theta of a fixture's truth file.
fn truth(bag: &str) -> [f64; 6] {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(bag.replace(".bag", ".truth.json"));
    let v: Value = serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    ["r_l", "r_r", "b", "l_x", "l_y", "l_theta"].map(|k| v["params"][k].as_f64().unwrap())
}

/// The six values and σ of a calibrate --json result.
fn values(v: &Value) -> ([f64; 6], [f64; 6]) {
    let value = ["r_l", "r_r", "b", "l_x", "l_y", "l_theta"].map(|k| v[k].as_f64().unwrap());
    let sigma = std::array::from_fn(|i| v["sigma"][i].as_f64().unwrap());
    (value, sigma)
}

/// Every parameter within 4σ of the truth.
fn assert_agrees_with_truth(v: &Value, bag: &str) {
    let (value, sigma) = values(v);
    let truth = truth(bag);
    for i in 0..6 {
        let err = value[i] - truth[i];
        assert!(
            err.abs() < 4.0 * sigma[i],
            "{bag}: parameter {i}: {} against truth {} (σ {})",
            value[i],
            truth[i],
            sigma[i]
        );
    }
}

fn finding_kinds(v: &Value) -> Vec<String> {
    v["health"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f["kind"].as_str().unwrap().to_string())
        .collect()
}

#[test]
fn gyro_heading_odometry_is_refused_by_name_with_the_joint_states_command() {
    let out = odocal(&[
        "calibrate",
        GYRO,
        "--odom-topic",
        "/odom",
        "--nominal",
        NOMINAL,
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{stderr}");
    assert!(
        stderr.contains("heading appears to come from a gyro/IMU, not from the wheels"),
        "{stderr}"
    );
    assert!(stderr.contains("use_imu_heading false"), "{stderr}");
    assert!(stderr.contains("the bag has IMU data (/imu)"), "{stderr}");
    // Holding known parameters cannot repair a gyro heading: no --fix/--prior advice.
    assert!(!stderr.contains("--fix NAME=VALUE"), "{stderr}");
    assert!(
        stderr.contains(&format!(
            "odocal calibrate {GYRO} --nominal {NOMINAL} --joint-states-topic /joint_states"
        )),
        "{stderr}"
    );
}

#[test]
fn the_refusal_in_json_suggests_the_joint_states_which_calibrate_to_the_truth() {
    let out = odocal(&[
        "calibrate",
        GYRO,
        "--odom-topic",
        "/odom",
        "--nominal",
        NOMINAL,
        "--json",
    ]);
    assert!(!out.status.success());
    let v = json(&out);
    assert_eq!(v["kind"], "not_determined", "{v}");
    assert!(v["error"].as_str().unwrap().contains("gyro/IMU"), "{v}");
    let command = v["suggested_command"].as_str().unwrap();
    assert!(
        command.ends_with("--json --joint-states-topic /joint_states"),
        "{command}"
    );
    assert!(!command.contains("--odom-topic"), "{command}");
    // The suggested command, run as given (the fixture path has no spaces).
    let words: Vec<&str> = command.split_whitespace().skip(1).collect();
    let out = odocal(&words);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v = json(&out);
    assert_agrees_with_truth(&v, GYRO);
    assert!(!finding_kinds(&v).contains(&"gyro_heading".to_string()));
}

#[test]
fn with_accept_weak_the_numbers_come_with_the_finding_and_no_parameter_well_determined() {
    let out = odocal(&[
        "calibrate",
        GYRO,
        "--odom-topic",
        "/odom",
        "--nominal",
        NOMINAL,
        "--accept-weak",
        "--json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v = json(&out);
    assert!(
        finding_kinds(&v).contains(&"gyro_heading".to_string()),
        "{v}"
    );
    for p in v["observability"]["parameters"].as_array().unwrap() {
        assert_ne!(p["verdict"], "well_determined", "{p}");
    }
}

#[test]
fn wheel_heading_odometry_calibrates_to_the_truth_and_to_what_the_wheel_joints_give() {
    let out = odocal(&[
        "calibrate",
        WHEEL,
        "--odom-topic",
        "/odom",
        "--nominal",
        NOMINAL,
        "--json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let odometry = json(&out);
    assert!(
        !finding_kinds(&odometry).contains(&"gyro_heading".to_string()),
        "{odometry}"
    );
    for p in odometry["observability"]["parameters"].as_array().unwrap() {
        assert_eq!(p["verdict"], "well_determined", "{p}");
    }
    assert_agrees_with_truth(&odometry, WHEEL);
    // The same run's wheel joints (in the gyro bag): the wheel rotations recovered from
    // wheel-heading odometry are the wheels', so the results are the same.
    let out = odocal(&[
        "calibrate",
        GYRO,
        "--joint-states-topic",
        "/joint_states",
        "--nominal",
        NOMINAL,
        "--json",
    ]);
    let joints = json(&out);
    let (a, _) = values(&odometry);
    let (b, sigma) = values(&joints);
    for i in 0..6 {
        assert!(
            (a[i] - b[i]).abs() < 0.01 * sigma[i],
            "parameter {i}: {} from the odometry, {} from the joints",
            a[i],
            b[i]
        );
    }
}
