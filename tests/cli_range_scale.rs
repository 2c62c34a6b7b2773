//! `--laser-range-scale` and the range finders recognised from the scans (issue 20
//! item 5): the scale's σ is reported beside the data's, `sigma`/`covariance` keep
//! meaning the data's alone, and an unrecognised laser is named as such with the
//! option to state its scale.

mod common;

use common::{calibrate_json, cleanup, odocal, simulated_log, stderr};
use serde_json::Value;

fn array(v: &Value, key: &str) -> Vec<f64> {
    v.pointer(key)
        .and_then(Value::as_array)
        .unwrap_or_else(|| panic!("{key} missing"))
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

#[test]
fn urg_04lx_is_recognised_and_its_scale_reported_beside_the_data_sigma() {
    let v = calibrate_json(&["fixtures/demo.log"]);
    assert_eq!(v["range_scale"]["sensor"], "Hokuyo URG-04LX");
    assert_eq!(v["range_scale"]["source"], "data_sheet");
    assert_eq!(v["range_scale"]["sigma"], 0.01);
    assert!(v["range_scale"]["recognised_from"]
        .as_str()
        .unwrap()
        .starts_with("681 rays 0.352° apart"));
    let params: Vec<f64> = ["r_l", "r_r", "b", "l_x", "l_y", "l_theta"]
        .iter()
        .map(|k| v[k].as_f64().unwrap())
        .collect();
    let data = array(&v, "/sigma");
    let scale = array(&v, "/range_scale/sigma_from_scale");
    let total = array(&v, "/range_scale/sigma_total");
    for i in 0..5 {
        assert!((scale[i] - 0.01 * params[i].abs()).abs() < 1e-12, "{i}");
        let want = data[i].hypot(scale[i]);
        assert!(
            (total[i] - want).abs() < 1e-9 * want,
            "{i}: {} vs {want}",
            total[i]
        );
    }
    assert_eq!(scale[5], 0.0);
    assert_eq!(total[5], data[5]);

    // A stated scale replaces the sheet's; the data's σ do not move.
    let stated = calibrate_json(&["fixtures/demo.log", "--laser-range-scale", "0.5"]);
    assert_eq!(stated["range_scale"]["source"], "stated");
    assert_eq!(stated["range_scale"]["sigma"], 0.005);
    assert_eq!(array(&stated, "/sigma"), data);
    let exact = calibrate_json(&["fixtures/demo.log", "--laser-range-scale", "0"]);
    assert_eq!(array(&exact, "/range_scale/sigma_total"), data);

    // The summary: the data's σ, the scale's, together; what does not depend on it.
    let o = odocal(&["calibrate", "fixtures/demo.log"]);
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        text.contains("(data) ±") && text.contains("(laser range scale 1 %) = ±"),
        "{text}"
    );
    assert!(
        text.contains("laser recognised as a Hokuyo URG-04LX"),
        "{text}"
    );
    assert!(
        text.contains("(J21, J22) and l_theta do not depend on it"),
        "{text}"
    );
}

/// With a parameter held the scale does not move it (no scale term in its σ), and
/// the free ones get the share the data give them: with `b` held the rotations tie
/// the radii to it, so their scale term is below their whole share (1 % of the
/// value); in the summary ℓθ's σ shows the small term it then gets.
#[test]
fn a_held_parameter_carries_no_scale_term() {
    let free = calibrate_json(&["fixtures/demo.log"]);
    let b = free["b"].as_f64().unwrap();
    let held = calibrate_json(&["fixtures/demo.log", "--fix", &format!("b={b}")]);
    let scale = array(&held, "/range_scale/sigma_from_scale");
    assert_eq!(scale[2], 0.0);
    for i in [0, 1] {
        let value = held[["r_l", "r_r"][i]].as_f64().unwrap();
        assert!(
            scale[i] > 0.0 && scale[i] < 0.01 * value,
            "{i}: {} of {value}",
            scale[i]
        );
    }
    assert!(scale[5] > 0.0, "{scale:?}");
    let o = odocal(&["calibrate", "fixtures/demo.log", "--fix", &format!("b={b}")]);
    let text = String::from_utf8_lossy(&o.stdout);
    let line = |name: &str| {
        text.lines()
            .find(|l| l.trim_start().starts_with(name))
            .unwrap_or_else(|| panic!("no {name} line in {text}"))
            .to_string()
    };
    assert!(
        line("b ").contains("± 0.0000 mm (laser range scale 1 %)"),
        "{text}"
    );
    assert!(
        line("l_theta").contains("mrad (laser range scale 1 %)"),
        "{text}"
    );
}

#[test]
fn lds_of_a_bag_is_recognised() {
    let v = calibrate_json(&["fixtures/bags/turtlebot_lds.bag"]);
    assert_eq!(v["range_scale"]["sensor"], "ROBOTIS LDS-01 (HLS-LFCD2)");
    assert_eq!(v["range_scale"]["sigma"], 0.05);
    let total = array(&v, "/range_scale/sigma_total");
    assert!(total[0] > 0.04 * v["r_l"].as_f64().unwrap());
}

#[test]
fn an_unrecognised_laser_says_the_distances_assume_an_exact_scale() {
    // URG spacing with a 30 m range: no range finder of the table.
    let (path, _) = simulated_log("range-scale-unknown", "khepera", 30.0, 3, |c| {
        c.laser.max_range = 30.0;
    });
    let p = path.to_str().unwrap();
    let v = calibrate_json(&[p]);
    assert_eq!(v["range_scale"]["source"], "unknown");
    assert!(v["range_scale"].get("sensor").is_none());
    assert_eq!(array(&v, "/range_scale/sigma_total"), array(&v, "/sigma"));
    let o = odocal(&["calibrate", p]);
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        text.contains("laser not recognised")
            && text.contains("assume an exact laser range scale")
            && text.contains("--laser-range-scale 1"),
        "{text}"
    );
    cleanup(&path);
}

#[test]
fn a_bad_scale_is_refused_with_what_is_expected() {
    for bad in ["-1", "80", "abc", "NaN"] {
        let o = odocal(&["calibrate", "fixtures/demo.log", "--laser-range-scale", bad]);
        assert!(!o.status.success(), "{bad}");
        let e = stderr(&o);
        assert!(
            e.contains("range-scale uncertainty in per cent"),
            "{bad}: {e}"
        );
    }
}

#[test]
fn each_laser_of_a_bag_with_two_is_recognised_on_its_own() {
    let v = calibrate_json(&[
        "fixtures/bags/turtlebot_two_lidars.bag",
        "--scan-topic",
        "/scan_front",
        "--scan-topic",
        "/scan_rear",
    ]);
    let lasers = v["lasers"].as_array().expect("a row per laser");
    assert_eq!(
        lasers[0]["range_scale"]["sensor"],
        "ROBOTIS LDS-01 (HLS-LFCD2)"
    );
    assert_eq!(lasers[1]["range_scale"]["sensor"], "SICK LMS2xx");
    // The front LDS's ℓx carries its 5 %; the rear SICK's σ are the data's.
    let front_x = lasers[0]["l_x"].as_f64().unwrap();
    let want = lasers[0]["sigma"][0]
        .as_f64()
        .unwrap()
        .hypot(0.05 * front_x);
    assert!((lasers[0]["sigma_total"][0].as_f64().unwrap() - want).abs() < 1e-12);
    assert_eq!(lasers[1]["sigma_total"], lasers[1]["sigma"]);
}

#[test]
fn info_names_the_range_finder_calibrate_would_recognise() {
    let o = odocal(&["info", "fixtures/bags/turtlebot_lds.bag", "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["range_scale"]["sensor"], "ROBOTIS LDS-01 (HLS-LFCD2)");
    let o = odocal(&["info", "fixtures/demo.log"]);
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        text.contains("laser range scale: laser recognised as a Hokuyo URG-04LX"),
        "{text}"
    );
}
