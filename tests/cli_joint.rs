//! `odocal calibrate LOG LOG …` and `odocal match LOG LOG …`: several logs of one
//! robot (a Carmen log and bags) calibrated jointly, with a row per log in
//! results.json and a clear error naming a log that fails.

mod common;

use common::{cleanup, odocal, simulated_log, stderr, temp_dir};

#[test]
fn a_carmen_log_and_bags_calibrate_jointly() {
    let (path, truth) = simulated_log("joint-a", "khepera", 60.0, 51, |_| {});
    let bag = "fixtures/bags/khepera_ros1_lz4.bag";
    let mcap = "fixtures/bags/khepera_mcap.mcap";
    let logs = [path.to_str().unwrap(), bag, mcap];
    let o = odocal(&["calibrate", logs[0], logs[1], logs[2], "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).expect("one JSON object");
    let rows = v["logs"].as_array().expect("a row per log");
    assert_eq!(rows.len(), 3);
    let mut samples = 0;
    for (row, log) in rows.iter().zip(logs) {
        assert_eq!(row["path"], log);
        assert_eq!(row["sha256"].as_str().map(str::len), Some(64));
        samples += row["samples"].as_u64().unwrap();
        let share = row["information_share"][2].as_f64().unwrap();
        assert!(share > 0.0 && share < 1.0, "{row}");
    }
    assert_eq!(v["samples_synchronized"].as_u64(), Some(samples));
    // One robot: every log that is compared agrees, and the joint estimate is near
    // the truth (the bounds).
    assert!(rows.iter().all(|r| r["agree"] != false), "{rows:?}");
    let checks = v["checks"].as_array().unwrap();
    assert_eq!(checks.len(), 3);
    assert!(checks.iter().all(|c| c["kind"] == "log_agreement"));
    let bounds = common::bounds(&truth);
    for (i, name) in ["r_l", "r_r", "b", "l_x", "l_y", "l_theta"]
        .iter()
        .enumerate()
    {
        let e = v[name].as_f64().unwrap() - truth[i];
        assert!(e.abs() < bounds[i], "{name}: error {e}");
    }
    // The same logs through `match`: the tuples of every log in one file.
    let tuples = path.parent().unwrap().join("all.tuple");
    let m = odocal(&[
        "match",
        logs[0],
        logs[1],
        logs[2],
        "--out",
        tuples.to_str().unwrap(),
    ]);
    assert!(m.status.success(), "{}", stderr(&m));
    let lines = std::fs::read_to_string(&tuples).unwrap().lines().count() as u64;
    assert_eq!(lines, samples);
    cleanup(&path);
}

#[test]
fn a_log_that_fails_is_named() {
    let dir = temp_dir("joint-bad");
    let bad = dir.join("empty.log");
    std::fs::write(&bad, "# nothing\n").unwrap();
    let o = odocal(&["calibrate", "fixtures/demo.log", bad.to_str().unwrap()]);
    let err = stderr(&o);
    assert!(!o.status.success(), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    assert!(err.contains("empty.log"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
    // A log too short to calibrate: named, its reason said once (it was said twice:
    // by the error and again by its source).
    let short = "fixtures/bags/khepera_db3_zstd_file";
    for extra in [None, Some("--all-pairs")] {
        let mut args = vec!["calibrate", "fixtures/demo.log", short];
        args.extend(extra);
        let o = odocal(&args);
        let err = stderr(&o);
        assert!(!o.status.success(), "{err}");
        assert!(err.contains(&format!("error: {short}")), "{err}");
        assert_eq!(err.matches("usable sample(s)").count(), 1, "{err}");
    }
}

#[test]
fn logs_of_two_robots_are_refused_with_their_names() {
    // A Khepera III and a TurtleBot-class robot: one model fits neither.
    let o = odocal(&[
        "calibrate",
        "fixtures/demo.log",
        "fixtures/bags/turtlebot_lds.bag",
    ]);
    let err = stderr(&o);
    assert!(!o.status.success(), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    assert!(err.contains("do not describe one robot"), "{err}");
    // Two logs are one comparison, each against the other: said once, naming both.
    assert!(
        err.contains("fixtures/demo.log and fixtures/bags/turtlebot_lds.bag disagree"),
        "{err}"
    );
    assert_eq!(err.matches("disagree beyond 3σ").count(), 1, "{err}");
    assert!(err.contains("likely one of the two logs"), "{err}");
    assert!(err.contains("calibrate them separately"), "{err}");
}
