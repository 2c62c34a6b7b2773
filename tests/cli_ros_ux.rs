//! The command line as a ROS user meets it: `--wheel-joints LEFT,RIGHT` as the help
//! gives it, a ROS 2 bag named by its `metadata.yaml`, `info` on a bag with the
//! data-health findings and bag vocabulary, advice that names only flags the command
//! takes, refusals under `--json` as a JSON object, and the results in ROS terms.

mod common;

use common::{odocal, stderr};
use std::path::Path;

fn root(path: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join(path)
        .to_string_lossy()
        .into_owned()
}

fn stdout(o: &std::process::Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

#[test]
fn wheel_joints_take_the_comma_form_the_help_gives_and_refuse_anything_else() {
    let bag = root("fixtures/bags/turtlebot_lds.bag");
    for form in [
        vec!["--wheel-joints", "wheel_left_joint,wheel_right_joint"],
        vec!["--wheel-joints", "wheel_left_joint", "wheel_right_joint"],
    ] {
        let mut args = vec!["info", bag.as_str(), "--json"];
        args.extend(form.iter().copied());
        let out = odocal(&args);
        assert!(out.status.success(), "{form:?}: {}", stderr(&out));
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(v["calibration_uses"]["wheels"]["left"], "wheel_left_joint");
        assert_eq!(
            v["calibration_uses"]["wheels"]["right"],
            "wheel_right_joint"
        );
    }
    for bad in [
        vec!["--wheel-joints", "a,b", "c,d"],
        vec!["--wheel-joints", "wheel_left_joint"],
        vec!["--wheel-joints", "a,b,c"],
    ] {
        let mut args = vec!["info", bag.as_str()];
        args.extend(bad.iter().copied());
        let out = odocal(&args);
        assert!(!out.status.success(), "{bad:?} accepted");
        let err = stderr(&out);
        assert!(err.contains("--wheel-joints"), "{bad:?}: {err}");
    }
}

#[test]
fn a_ros2_bag_named_by_its_metadata_yaml_is_read_as_its_directory() {
    let out = odocal(&[
        "info",
        &root("fixtures/bags/khepera_ros2_dir/metadata.yaml"),
        "--json",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let scan_type = v["topics"]["/scan"]["type"].as_str().unwrap_or("");
    assert!(scan_type.ends_with("LaserScan"), "{v}");
    assert!(v["scans"].as_u64().unwrap() > 50, "{v}");
}

#[test]
fn match_advises_only_flags_that_match_takes() {
    let (log, _) = common::simulated_log("advice", "khepera", 60.0, 1, |c| {
        c.faults.clock_offset = 0.3;
    });
    let tuples = log.with_extension("tuple");
    let out = odocal(&[
        "match",
        log.to_str().unwrap(),
        "--out",
        tuples.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let err = stderr(&out);
    assert!(err.contains("clock"), "no clock-offset finding: {err}");
    // Every `--flag` the advice names outside an `odocal calibrate …` suggestion is
    // one `match --help` lists.
    let help = stdout(&odocal(&["match", "--help"]));
    for line in err.lines() {
        let own = line.split("odocal calibrate").next().unwrap_or(line);
        for word in own.split(|c: char| c.is_whitespace() || c == '`') {
            if let Some(flag) = word.strip_prefix("--") {
                let flag: String = flag
                    .chars()
                    .take_while(|c| c.is_ascii_alphanumeric() || *c == '-')
                    .collect();
                assert!(
                    help.contains(&format!("--{flag}")),
                    "match advises --{flag}, which it does not take: {line}"
                );
            }
        }
    }
    common::cleanup(&log);
}

#[test]
fn info_on_a_bag_speaks_bag_shows_health_and_collapses_identical_geometries() {
    // turtlebot_tf: the laser writes its own, jittering, time_increment in every
    // message; one /joint_states message is recorded twice.
    let out = odocal(&["info", &root("fixtures/bags/turtlebot_tf.bag")]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = stdout(&out);
    let geometry: Vec<&str> = text
        .lines()
        .filter(|l| l.starts_with("scan geometry"))
        .collect();
    assert_eq!(geometry.len(), 1, "{text}");
    assert!(geometry[0].contains("59 scans"), "{text}");
    assert!(text.contains("data health"), "no health findings: {text}");
    assert!(text.contains("duplicate"), "{text}");
    for encoder_word in [
        "lines:",
        "ticks/rev",
        "skipped lines",
        "comments:",
        "/scan59",
    ] {
        assert!(!text.contains(encoder_word), "{encoder_word:?} in {text}");
    }
    // f32 fields printed with f32 precision.
    assert!(!text.contains("0.11999999"), "{text}");
    assert!(text.contains("0.12"), "{text}");
}

#[test]
fn a_refusal_under_json_is_a_json_object_with_the_message_kind_and_command() {
    let bag = root("fixtures/bags/khepera_ros1_bz2_odom.bag");
    let out = odocal(&["calibrate", &bag, "--json"]);
    assert!(!out.status.success());
    let v: serde_json::Value = serde_json::from_slice(&out.stdout)
        .unwrap_or_else(|e| panic!("stdout is not JSON ({e}): {:?}", stdout(&out)));
    let message = v["error"].as_str().unwrap();
    assert!(message.contains("--nominal"), "{v}");
    assert!(v["kind"].is_string(), "{v}");
    let command = v["suggested_command"].as_str().unwrap();
    assert!(
        command.contains(&bag) && command.contains("--nominal"),
        "{v}"
    );
    // Parameters the data do not determine: the refusal's kind, and its command holds
    // the parameters it proposes to hold.
    let short = root("fixtures/bags/turtlebot_tf.bag");
    let out = odocal(&["calibrate", &short, "--json"]);
    assert!(!out.status.success());
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["kind"], "not_determined", "{v}");
    assert!(
        v["suggested_command"]
            .as_str()
            .is_some_and(|c| c.contains(&short) && c.contains("--fix")),
        "{v}"
    );
    // info on a file that is not there.
    let out = odocal(&["info", "/nonexistent/odocal.log", "--json"]);
    assert!(!out.status.success());
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(v["error"]
        .as_str()
        .unwrap()
        .contains("/nonexistent/odocal.log"));
}

/// The value of `key:` in a YAML text of `key: value` lines.
fn yaml_value(text: &str, key: &str) -> f64 {
    let line = text
        .lines()
        .find(|l| l.trim_start().starts_with(&format!("{key}:")))
        .unwrap_or_else(|| panic!("no {key} in {text}"));
    line.split(':').nth(1).unwrap().trim().parse().unwrap()
}

#[test]
fn calibrate_out_and_export_write_the_results_in_ros_terms() {
    let dir = common::temp_dir("ros-terms");
    let out_dir = dir.join("out");
    let out = odocal(&[
        "calibrate",
        &root("fixtures/bags/khepera_ros1_lz4.bag"),
        "--out",
        out_dir.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let results: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out_dir.join("results.json")).unwrap()).unwrap();
    let p = |k: &str| results[k].as_f64().unwrap();
    let yaml = std::fs::read_to_string(out_dir.join("diff_drive_controller.yaml")).unwrap();
    let radius = yaml_value(&yaml, "wheel_radius");
    let left = radius * yaml_value(&yaml, "left_wheel_radius_multiplier");
    let right = radius * yaml_value(&yaml, "right_wheel_radius_multiplier");
    let b =
        yaml_value(&yaml, "wheel_separation") * yaml_value(&yaml, "wheel_separation_multiplier");
    assert!(
        (left - p("r_l")).abs() < 1e-15 && (right - p("r_r")).abs() < 1e-15,
        "{yaml}"
    );
    assert_eq!(b, p("b"), "{yaml}");
    let urdf = std::fs::read_to_string(out_dir.join("laser_joint.urdf.xml")).unwrap();
    let origin = format!(
        "<origin xyz=\"{:?} {:?} 0\" rpy=\"0 0 {:?}\"/>",
        p("l_x"),
        p("l_y"),
        p("l_theta")
    );
    assert!(urdf.contains(&origin), "{urdf} lacks {origin}");

    // `odocal export` gives the same from results.json.
    let results_path = out_dir.join("results.json");
    let results_path = results_path.to_str().unwrap();
    let printed = odocal(&["export", results_path, "--format", "urdf"]);
    assert!(printed.status.success(), "{}", stderr(&printed));
    assert_eq!(stdout(&printed), urdf);
    let again = dir.join("again");
    let written = odocal(&["export", results_path, "--out", again.to_str().unwrap()]);
    assert!(written.status.success(), "{}", stderr(&written));
    assert_eq!(
        std::fs::read_to_string(again.join("diff_drive_controller.yaml")).unwrap(),
        yaml
    );
    // Not a results.json: refused, naming the file and what was expected.
    let bogus = dir.join("bogus.json");
    std::fs::write(&bogus, "{\"r_l\": 0.02}").unwrap();
    let refused = odocal(&["export", bogus.to_str().unwrap()]);
    assert!(!refused.status.success());
    assert!(stderr(&refused).contains("bogus.json") && stderr(&refused).contains("l_theta"));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_nominal_laser_pose_comes_from_the_bags_static_transforms() {
    // turtlebot_tf.bag: /tf_static base_footprint -> base_link -> base_scan, the laser
    // at (-0.032, 0.004) m, 0.01 rad (make_bags.py: the truth rounded).
    let bag = root("fixtures/bags/turtlebot_tf.bag");
    let out = odocal(&["info", &bag, "--json"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let l = &v["nominal_laser"];
    assert_eq!(l["base_frame"], "base_link", "{v}");
    assert_eq!(l["laser_frame"], "base_scan");
    let close = |a: &serde_json::Value, b: f64| (a.as_f64().unwrap() - b).abs() < 1e-9;
    assert!(
        close(&l["x"], -0.032) && close(&l["y"], 0.004) && close(&l["theta"], 0.01),
        "{l}"
    );
    // --nominal with the wheels only takes the laser pose from the bag; results.json
    // records both.
    let out = odocal(&[
        "calibrate",
        &bag,
        "--nominal",
        "0.033,0.033,0.16",
        "--accept-weak",
        "--json",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let nominal: Vec<f64> = serde_json::from_value(v["nominal"].clone()).unwrap();
    assert_eq!(nominal, vec![0.033, 0.033, 0.16, -0.032, 0.004, 0.01]);
    assert_eq!(v["nominal_laser"]["base_frame"], "base_link");
    // Six values override the bag's pose.
    let out = odocal(&[
        "calibrate",
        &bag,
        "--nominal",
        "0.033,0.033,0.16,0,0,0",
        "--accept-weak",
        "--json",
    ]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let nominal: Vec<f64> = serde_json::from_value(v["nominal"].clone()).unwrap();
    assert_eq!(nominal, vec![0.033, 0.033, 0.16, 0.0, 0.0, 0.0]);
}
