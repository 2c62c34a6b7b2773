//! A bag whose scans were recorded 5–45 ms after their header stamps (a USB lidar
//! driver delivering late, exponential with bursts: fixtures/bags/khepera_late_scans,
//! written by make_bags.py). With the header stamps it calibrates, every parameter
//! within 3σ of the simulator's truth; with `--use-receive-time` the laser's timing is
//! the recorder's jitter, and no parameter may come out "well determined" without the
//! jitter being named: the refusal names it once, as its cause, with the command
//! without `--use-receive-time`; `--accept-weak` gives weak verdicts and the finding.

mod common;

use common::{odocal, stderr};
use serde_json::Value;
use std::path::Path;

const BAG: &str = "fixtures/bags/khepera_late_scans.bag";
const KEYS: [&str; 6] = ["r_l", "r_r", "b", "l_x", "l_y", "l_theta"];

fn bag() -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join(BAG)
        .to_string_lossy()
        .into_owned()
}

fn json_of(out: &std::process::Output) -> Value {
    serde_json::from_slice(&out.stdout).unwrap_or_else(|e| {
        panic!(
            "stdout is not JSON ({e}): {}\n{}",
            String::from_utf8_lossy(&out.stdout),
            stderr(out)
        )
    })
}

#[test]
fn with_header_stamps_the_late_scans_calibrate_near_the_truth() {
    let out = odocal(&["calibrate", &bag(), "--json"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let v = json_of(&out);
    let truth: Value = serde_json::from_str(
        &std::fs::read_to_string(bag().replace(".bag", ".truth.json")).unwrap(),
    )
    .unwrap();
    for (i, k) in KEYS.iter().enumerate() {
        let (x, t, s) = (
            v[k].as_f64().unwrap(),
            truth["params"][k].as_f64().unwrap(),
            v["sigma"][i].as_f64().unwrap(),
        );
        assert!((x - t).abs() < 3.0 * s, "{k}: {x} vs truth {t} (σ {s})");
        assert_eq!(
            v["observability"]["parameters"][i]["verdict"], "well_determined",
            "{k}"
        );
    }
    let jitter = v["health"]
        .as_array()
        .into_iter()
        .flatten()
        .any(|f| f["kind"] == "read_jitter");
    assert!(!jitter, "{}", v["health"]);
}

#[test]
fn receive_times_are_refused_naming_the_jitter_once_with_the_command_to_run() {
    let bag = bag();
    let out = odocal(&["calibrate", &bag, "--use-receive-time"]);
    let err = stderr(&out);
    assert!(!out.status.success(), "not refused: {err}");
    assert!(err.contains("because the laser timestamps jitter"), "{err}");
    assert!(err.contains("leave out --use-receive-time"), "{err}");
    // Holding known parameters cannot repair the timing: no --fix/--prior advice.
    assert!(!err.contains("--fix NAME=VALUE"), "{err}");
    // Named once (before: three times, the third as "not the cause").
    assert_eq!(err.matches("timestamps jitter by").count(), 1, "{err}");
    // The motion's own verdict only as what it would give.
    if let Some(at) = err.find("are well determined") {
        assert!(err[..at].contains("would give"), "{err}");
    }
    let out = odocal(&["calibrate", &bag, "--use-receive-time", "--json"]);
    let v = json_of(&out);
    let command = v["suggested_command"].as_str().unwrap_or_default();
    assert!(
        command.contains(&bag)
            && !command.contains("--use-receive-time")
            && !command.contains("--accept-weak"),
        "{v}"
    );
}

#[test]
fn receive_times_with_accept_weak_are_weak_and_say_why() {
    let out = odocal(&[
        "calibrate",
        &bag(),
        "--use-receive-time",
        "--accept-weak",
        "--json",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let v = json_of(&out);
    let params = v["observability"]["parameters"].as_array().unwrap();
    assert!(
        params.iter().all(|p| p["verdict"] != "well_determined"),
        "{params:?}"
    );
    let sentence = v["observability"]["sentence"].as_str().unwrap();
    assert!(sentence.contains("laser timestamps jitter"), "{sentence}");
    let finding = v["health"]
        .as_array()
        .into_iter()
        .flatten()
        .find(|f| f["kind"] == "read_jitter")
        .unwrap_or_else(|| panic!("no jitter finding: {}", v["health"]));
    assert_eq!(finding["severity"], "warning");
}
