//! Calibrating a simulated log end to end and checking the result against the truth
//! with the bounds (0.35 % for r_L, r_R, b; 1.5 mm for ℓx, ℓy; 0.2° for ℓθ).

use super::Truth;
use odocal_log::{read_log, ReadOptions};
use odocal_pipeline::{calibrate_log, NoProgress, Options};
use odocal_report::{build_report, Report};

/// The parameter names, in [`Truth`] order.
pub const NAMES: [&str; 6] = ["r_L", "r_R", "b", "l_x", "l_y", "l_theta"];

/// Reads `path` with `read` and calibrates it on two threads.
pub fn calibrate_with(path: &std::path::Path, read: &ReadOptions, opts: &Options) -> Report {
    let log = read_log(path, read).expect("the simulated log reads");
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap();
    let outcome = pool
        .install(|| calibrate_log(&log, opts, &NoProgress))
        .expect("calibration succeeds");
    build_report(path, &log, opts, &outcome)
}

/// Calibrates `path` as read by default.
pub fn calibrate(path: &std::path::Path, opts: &Options) -> Report {
    calibrate_with(path, &ReadOptions::default(), opts)
}

/// Where the result misses the bounds or lies beyond `max_sigmas` of the
/// reported σ (empty when it does not), and a line with the errors in σ.
pub fn misses(
    label: &str,
    report: &Report,
    truth: &Truth,
    max_sigmas: f64,
) -> (Vec<String>, String) {
    let est = report.values();
    let bounds = super::bounds(truth);
    let mut failures = Vec::new();
    let mut line = format!("{label}: {} samples;", report.samples_used);
    for i in 0..6 {
        let err = est[i] - truth[i];
        let sigma = report.sigma[i];
        line += &format!(" {} {:+.2e} ({:+.2}σ)", NAMES[i], err, err / sigma);
        if err.abs() > bounds[i] {
            failures.push(format!(
                "{}: error {err:.3e} above the bound {:.3e}",
                NAMES[i], bounds[i]
            ));
        }
        if err.is_nan() || err.abs() > max_sigmas * sigma {
            failures.push(format!(
                "{}: error {err:.3e} beyond {max_sigmas}σ = {:.3e}",
                NAMES[i],
                max_sigmas * sigma
            ));
        }
    }
    (failures, line)
}

/// Asserts the bounds, at least `min_samples` samples and errors within
/// `max_sigmas` σ; prints the errors in σ.
pub fn check(label: &str, report: &Report, truth: &Truth, max_sigmas: f64, min_samples: usize) {
    let (failures, line) = misses(label, report, truth, max_sigmas);
    println!("{line}");
    assert!(
        report.samples_used > min_samples,
        "{label}: only {} samples used",
        report.samples_used
    );
    assert!(failures.is_empty(), "{label}: {}", failures.join("; "));
}
