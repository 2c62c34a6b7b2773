//! The clock offset comes with a σ (from the curvature of the offset search's cost),
//! and on a swept laser it is estimated again once the sweep is compensated at it: a
//! TurtleBot-class log (LDS-like laser sweeping over each scan) with an 80 ms offset
//! gives the offset within 4σ, the parameters' σ holding their move when the offset
//! moves by its σ, and no false slip episodes.

mod common;

use common::{cleanup, odocal, simulated_log, stderr};

#[test]
fn swept_log_with_an_offset_gets_it_within_its_sigma_and_no_false_slip() {
    let truth_offset = 0.08;
    let (path, _) = simulated_log("offset-sigma", "turtlebot", 60.0, 6, |c| {
        c.faults.clock_offset = truth_offset;
    });
    let o = odocal(&["calibrate", path.to_str().unwrap(), "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).expect("JSON");
    let offset = v["time_offset_s"].as_f64().expect("offset estimated");
    let sigma = v["time_offset_sigma_s"].as_f64().expect("offset σ");
    assert!((5e-5..5e-3).contains(&sigma), "σ {sigma}");
    assert!(
        (offset - truth_offset).abs() < 4.0 * sigma,
        "offset {offset} ± {sigma}, truth {truth_offset}"
    );
    // Not knowing the offset exactly is in the parameters' σ: each σ holds at least
    // the parameter's move when the offset moves by its σ.
    let shift = v["time_offset_parameter_shift"]
        .as_array()
        .expect("the parameters' move per σ of the offset");
    let sigmas = v["sigma"].as_array().expect("σ");
    assert_eq!(shift.len(), 6);
    for (d, s) in shift.iter().zip(sigmas) {
        let (d, s) = (d.as_f64().expect("finite"), s.as_f64().expect("σ"));
        assert!(d.is_finite() && d.abs() <= s, "move {d}, σ {s}");
    }
    let slips: Vec<_> = v["health"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|h| h["kind"] == "slip")
        .collect();
    assert!(slips.is_empty(), "{slips:?}");
    cleanup(&path);
}
