//! The range up to which scan matching uses a laser's readings (issue 20 item 2): the
//! data sheet's rated range of a recognised range finder, else the maximum its scans
//! declare; `--matching-range` states another; results.json records it.

mod common;

use common::{calibrate_json, cleanup, odocal, simulated_log, stderr};
use serde_json::Value;

/// The bag of one drive seen by a front LDS (3.5 m) and a rear SICK-like laser (8 m).
const TWO_LIDARS: &str = "fixtures/bags/turtlebot_two_lidars.bag";

fn matching_range(v: &Value) -> f64 {
    v["settings"]["matching_range_m"]
        .as_f64()
        .expect("settings.matching_range_m")
}

fn sigma_b(v: &Value) -> f64 {
    v["sigma"][2].as_f64().expect("σ of b")
}

#[test]
fn each_laser_is_matched_to_its_rated_range() {
    // The demo log's URG-04LX: 4 m, the range its data sheet states an accuracy for.
    let demo = calibrate_json(&["fixtures/demo.log"]);
    assert_eq!(demo["range_scale"]["sensor"], "Hokuyo URG-04LX");
    assert_eq!(matching_range(&demo), 4.0);
    // It declares 4 m itself: nothing left out, nothing said.
    assert!(demo["settings"]["matching_range_statement"].is_null());
    // The front LDS-01 to its 3.5 m, the rear SICK LMS2xx-like laser to its 8 m (its
    // sheet states an absolute accuracy over the whole range).
    let front = calibrate_json(&[TWO_LIDARS, "--scan-topic", "/scan_front"]);
    assert_eq!(matching_range(&front), 3.5);
    let rear = calibrate_json(&[TWO_LIDARS, "--scan-topic", "/scan_rear"]);
    assert_eq!(rear["range_scale"]["sensor"], "SICK LMS2xx");
    assert!(
        (matching_range(&rear) - 8.0).abs() < 1e-6,
        "{}",
        rear["settings"]
    );
}

#[test]
fn far_readings_carry_information_and_a_stated_range_is_used() {
    // The rear laser's walls beyond 3 m are much of what fixes b: limited to 3 m
    // (`--matching-range`), its σ grows (0.16 mm with its 8 m, 0.60 mm with 4 m).
    let full = calibrate_json(&[TWO_LIDARS, "--scan-topic", "/scan_rear"]);
    let short = calibrate_json(&[
        TWO_LIDARS,
        "--scan-topic",
        "/scan_rear",
        "--matching-range",
        "3",
        "--accept-weak",
    ]);
    assert_eq!(matching_range(&short), 3.0);
    assert_eq!(
        short["settings"]["matching_range_statement"],
        "readings up to 3 m of the 8 m the scans declare (as stated by --matching-range)"
    );
    assert!(
        sigma_b(&short) > 1.5 * sigma_b(&full),
        "σ_b {} at 3 m vs {} at 8 m",
        sigma_b(&short),
        sigma_b(&full)
    );
    // Not a positive number of metres: refused by name.
    for bad in ["0", "-2", "inf", "4m"] {
        let o = odocal(&["calibrate", "fixtures/demo.log", "--matching-range", bad]);
        assert!(!o.status.success(), "{bad}");
        let err = stderr(&o);
        assert!(err.contains("positive number of metres"), "{bad}: {err}");
    }
}

#[test]
fn readings_beyond_the_rated_range_are_said_to_be_left_out() {
    // A simulated MinesRover-class URG-04LX reporting to 5.6 m: matched to 4 m, and the
    // summary says so with the option to use more.
    let (log, _) = simulated_log("matching-range-urg", "mines-rover", 30.0, 5, |_| {});
    let path = log.to_str().unwrap();
    let o = odocal(&["calibrate", path, "--accept-weak"]);
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        out.contains(
            "scan matching used readings up to 4 m of the 5.6 m the scans declare (the Hokuyo \
             URG-04LX's rated range; --matching-range METRES to use more)"
        ),
        "{out}"
    );
    cleanup(&log);
}
