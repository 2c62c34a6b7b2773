//! The `odocal` binary end to end: `calibrate` (human and JSON output, `--out` with
//! figures), `match`, failure exits with one clear sentence, and thread-count
//! independence.

mod common;

use common::{cleanup, odocal, simulated_log, stderr, temp_dir};
use std::process::Output;

/// One line on stderr starting with "error:", non-zero exit, no panic.
fn assert_clean_failure(o: &Output) -> String {
    let err = stderr(o);
    assert!(
        !o.status.success(),
        "expected a failure, got success: {err}"
    );
    assert!(!err.contains("panicked"), "{err}");
    assert!(err.starts_with("error: "), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    err
}

#[test]
fn json_output_and_out_dir() {
    let (path, truth) = simulated_log("cli-json", "khepera-displaced", 120.0, 21, |_| {});
    let log = path.to_str().unwrap();
    let out_dir = path.parent().unwrap().join("results");
    let o = odocal(&[
        "calibrate",
        log,
        "--json",
        "--threads",
        "2",
        "--out",
        out_dir.to_str().unwrap(),
        "--plots",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value =
        serde_json::from_slice(&o.stdout).expect("stdout is one JSON object");
    for key in [
        "r_l",
        "r_r",
        "b",
        "l_x",
        "l_y",
        "l_theta",
        "covariance",
        "j",
        "samples_used",
        "discarded",
        "observability",
        "timing_s",
    ] {
        assert!(v.get(key).is_some(), "missing {key}");
    }
    assert!(v.get("time_offset_s").is_none());
    let cov = v["covariance"].as_array().unwrap();
    assert_eq!(cov.len(), 6);
    assert!(cov.iter().all(|row| row.as_array().unwrap().len() == 6));
    for reason in [
        "robot_still",
        "encoder_gap",
        "match_failed",
        "interval_too_long",
    ] {
        assert!(v["discarded"][reason].is_u64(), "discarded.{reason}");
    }
    for stage in ["parse", "match", "solve"] {
        assert!(v["timing_s"][stage].as_f64().unwrap() >= 0.0);
    }
    // Two minutes of driving already pin b down to a fraction of a percent.
    let b = v["b"].as_f64().unwrap();
    assert!((b - truth[2]).abs() < 0.005 * truth[2], "b = {b}");

    // results.json is the same report; the tuples read back with the log crate.
    let results: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out_dir.join("results.json")).unwrap())
            .unwrap();
    assert_eq!(results["b"], v["b"]);
    let tuples = odocal_log::read_tuples(&out_dir.join("samples.tuple")).unwrap();
    assert_eq!(
        tuples.len() as u64,
        v["samples_synchronized"].as_u64().unwrap()
    );
    let t = &tuples[0];
    assert!(t.t0.is_some() && t.t1.is_some() && t.sm_cov.is_some() && t.profile.is_some());
    assert!(t.extra.contains_key("icp_iterations") && t.extra.contains_key("icp_correspondences"));
    let profile = t.profile.as_ref().unwrap();
    let total: f64 = profile.iter().map(|p| p[0]).sum();
    assert!((total - t.t).abs() < 1e-9);
    for fig in [
        "trajectory.svg",
        "residuals_time.svg",
        "residual_histograms.svg",
        "motion_coverage.svg",
        "icp_quality.svg",
        "results.html",
    ] {
        let svg = std::fs::read_to_string(out_dir.join(fig)).unwrap();
        assert!(
            (svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"))
                || (svg.starts_with("<!DOCTYPE html>") && svg.trim_end().ends_with("</html>")),
            "{fig}"
        );
    }

    // Where the results came from: the input's SHA-256 and size, the command line.
    let p = &v["provenance"];
    let sha = p["input_sha256"].as_str().unwrap();
    assert!(
        sha.len() == 64 && sha.bytes().all(|c| c.is_ascii_hexdigit()),
        "{sha}"
    );
    assert_eq!(
        p["input_bytes"].as_u64().unwrap(),
        std::fs::metadata(&path).unwrap().len()
    );
    assert!(p["command_line"].as_str().unwrap().contains("--plots"));

    // Human summary, and the report page on its own, into a directory that does not
    // exist yet (created, as for --out).
    let page = out_dir.join("pages").join("page.html");
    let o = odocal(&[
        "calibrate",
        log,
        "--threads",
        "1",
        "--report",
        page.to_str().unwrap(),
    ]);
    assert!(o.status.success());
    let html = std::fs::read_to_string(&page).unwrap();
    assert!(html.contains("id=\"fig-motion_coverage\""));
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.contains("report written to"), "{text}");
    for needle in [
        "r_L",
        "l_theta",
        "J =",
        "discarded pairs",
        "observability",
        "timing",
    ] {
        assert!(text.contains(needle), "summary lacks {needle}:\n{text}");
    }
    cleanup(&path);
}

#[test]
fn match_writes_tuples_and_thread_count_does_not_matter() {
    let (path, _) = simulated_log("cli-match", "khepera", 60.0, 22, |_| {});
    let dir = path.parent().unwrap();
    let mut outputs = Vec::new();
    for threads in ["1", "2"] {
        let out = dir.join(format!("t{threads}.tuple"));
        let o = odocal(&[
            "match",
            path.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--threads",
            threads,
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        outputs.push(std::fs::read(&out).unwrap());
    }
    assert!(!outputs[0].is_empty());
    assert_eq!(
        outputs[0], outputs[1],
        "tuples differ between 1 and 2 threads"
    );
    let tuples = odocal_log::read_tuples(&dir.join("t1.tuple")).unwrap();
    assert!(tuples.len() > 100);
    // The tuples solve with `odocal solve`'s input reader: intervals near 0.4 s.
    let mean_t: f64 = tuples.iter().map(|t| t.t).sum::<f64>() / tuples.len() as f64;
    assert!((mean_t - 0.4).abs() < 0.05, "mean interval {mean_t}");
    cleanup(&path);
}

fn not_excited(preset: &str, must_name: &[&str]) {
    let (path, _) = simulated_log(preset, preset, 120.0, 23, |_| {});
    let o = odocal(&["calibrate", path.to_str().unwrap()]);
    let err = assert_clean_failure(&o);
    for name in must_name {
        assert!(
            err.contains(name),
            "{preset}: the error does not name {name}: {err}"
        );
    }
    assert!(err.contains("not") || err.contains("determine"), "{err}");
    cleanup(&path);
}

#[test]
fn straight_only_fails_naming_the_parameters() {
    not_excited("straight-only", &["b", "l_x", "l_y"]);
}

#[test]
fn spin_only_fails_naming_the_parameters() {
    not_excited("spin-only", &["r_L", "r_R", "b"]);
}

#[test]
fn bad_inputs_fail_with_one_sentence() {
    let dir = temp_dir("cli-errors");
    let missing = dir.join("missing.log");
    let err = assert_clean_failure(&odocal(&["calibrate", missing.to_str().unwrap()]));
    assert!(err.contains("missing.log"), "{err}");

    let junk = dir.join("junk.log");
    std::fs::write(&junk, "hello world\nthis is not a log\n").unwrap();
    assert_clean_failure(&odocal(&["calibrate", junk.to_str().unwrap()]));

    // A log without ticks per revolution: the error says how to supply it.
    let (path, _) = simulated_log("cli-noticks", "khepera", 60.0, 24, |_| {});
    let text = std::fs::read_to_string(&path).unwrap();
    let stripped: String = text
        .lines()
        .filter(|l| !l.starts_with("PARAM robot_wheel_ticks_per_revolution"))
        .map(|l| format!("{l}\n"))
        .collect();
    let noticks = dir.join("noticks.log");
    std::fs::write(&noticks, stripped).unwrap();
    let err = assert_clean_failure(&odocal(&["calibrate", noticks.to_str().unwrap()]));
    assert!(err.contains("--ticks-per-rev"), "{err}");
    // … and supplying it on the command line works.
    let o = odocal(&[
        "calibrate",
        noticks.to_str().unwrap(),
        "--ticks-per-rev",
        "2764.8",
        "--accept-weak",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));

    // Too short to give enough samples.
    let (short, _) = simulated_log("cli-short", "khepera", 3.0, 25, |_| {});
    let err = assert_clean_failure(&odocal(&["calibrate", short.to_str().unwrap()]));
    assert!(err.contains("sample"), "{err}");

    let _ = std::fs::remove_dir_all(&dir);
    cleanup(&path);
    cleanup(&short);
}
