//! End to end on simulated 10-minute logs (≈ 1,500 samples): the parameters are
//! recovered within the bounds (0.35 % for r_L, r_R, b; 1.5 mm for ℓx, ℓy;
//! 0.2° for ℓθ) and within 3σ of the reported covariance — with the Khepera's
//! parameters, with the displaced laser, with wheel slip, and with a clock offset.

mod common;

use common::accuracy::{calibrate, check as check_within};
use common::{cleanup, simulated_log, Truth};
use odocal_pipeline::Options;
use odocal_report::Report;

/// Asserts the bounds and the 3σ consistency; prints the errors in σ.
fn check(label: &str, report: &Report, truth: &Truth) {
    check_within(label, report, truth, 3.0, 1000);
}

#[test]
fn khepera_parameters_are_recovered() {
    let (path, truth) = simulated_log("khepera", "khepera", 600.0, 11, |_| {});
    let report = calibrate(&path, &Options::default());
    check("khepera", &report, &truth);
    cleanup(&path);
}

#[test]
fn displaced_laser_is_recovered() {
    let (path, truth) = simulated_log("displaced", "khepera-displaced", 600.0, 12, |_| {});
    assert!((truth[3] - 0.024).abs() < 1e-9 && (truth[5] - 0.36).abs() < 1e-9);
    let report = calibrate(&path, &Options::default());
    check("khepera-displaced", &report, &truth);
    cleanup(&path);
}

#[test]
fn wheel_slip_is_trimmed() {
    let (path, truth) = simulated_log("slip", "khepera-displaced", 600.0, 13, |c| {
        c.faults.slip_per_minute = 2.0;
    });
    let report = calibrate(&path, &Options::default());
    check("khepera-displaced + slip", &report, &truth);
    assert!(report.samples_trimmed > 0);
    // Without trimming the slip episodes bias the estimate: trimming is what works.
    let mut untrimmed = Options::default();
    untrimmed.solve.trim = odocal_pipeline::Trim::None;
    let raw = calibrate(&path, &untrimmed);
    let worst_trimmed = (0..6)
        .map(|i| ((report.values()[i] - truth[i]) / report.sigma[i]).abs())
        .fold(0.0, f64::max);
    let worst_raw = (0..6)
        .map(|i| ((raw.values()[i] - truth[i]) / raw.sigma[i]).abs())
        .fold(0.0, f64::max);
    println!("worst error in σ: trimmed {worst_trimmed:.2}, untrimmed {worst_raw:.2}");
    assert!(worst_raw > worst_trimmed);
    cleanup(&path);
}

#[test]
fn clock_offset_is_estimated() {
    let (path, truth) = simulated_log("offset", "khepera", 600.0, 14, |c| {
        c.faults.clock_offset = 0.05;
    });
    let opts = Options {
        estimate_time_offset: Some(0.5),
        ..Options::default()
    };
    let report = calibrate(&path, &opts);
    let offset = report.time_offset_s.expect("the offset is reported");
    println!("clock offset: estimated {offset:.4} s, true 0.0500 s");
    assert!((offset - 0.05).abs() < 0.005, "estimated {offset} s");
    check("khepera + 50 ms clock offset (estimated)", &report, &truth);
    cleanup(&path);
}
