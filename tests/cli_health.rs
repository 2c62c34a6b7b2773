//! The binary on issue 14's command-line rows: `--threads` capped with a message, a
//! failed `--out` still prints the results, `/dev/zero` fails fast, `solve` agrees with
//! `calibrate` on calibrate's own samples, every command that reads a log takes the
//! reading options, and a clock offset beyond the search range names the fix.

mod common;

use common::{cleanup, simulated_log};
use std::process::{Command, Output};

fn odocal(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_odocal"))
        .args(args)
        .output()
        .expect("the binary runs")
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

#[test]
fn threads_capped_and_an_impossible_out_refused_before_the_work() {
    let (path, _) = simulated_log("cli-health-out", "khepera-displaced", 60.0, 61, |_| {});
    let log = path.to_str().unwrap();
    // A directory inside a regular file can never be created (even as root).
    let blocked = path.join("results");
    let o = odocal(&[
        "calibrate",
        log,
        "--threads",
        "100000",
        "--out",
        blocked.to_str().unwrap(),
    ]);
    let (out, err) = (text(&o.stdout), text(&o.stderr));
    assert!(!o.status.success(), "{err}");
    assert!(err.contains("--threads 100000 capped at"), "{err}");
    // The output is checked before the log is read and calibrated: nothing is
    // computed for results that could not be written.
    assert!(
        out.is_empty(),
        "no summary for a run refused up front: {out}"
    );
    assert!(err.contains("cannot write the results into"), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    cleanup(&path);
}

#[test]
fn solve_agrees_with_calibrate_on_its_samples() {
    let (path, _) = simulated_log("cli-health-solve", "khepera-displaced", 60.0, 62, |_| {});
    let dir = path.parent().unwrap().join("out");
    // `solve` has no sideways slide: calibrate without it (on this log its evidence
    // weighs it in at 0.7 %, which moves r_L by 1e-7 of itself).
    let c = odocal(&[
        "calibrate",
        path.to_str().unwrap(),
        "--json",
        "--threads",
        "2",
        "--no-lateral-slip",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(c.status.success(), "{}", text(&c.stderr));
    let tuples = dir.join("samples.tuple");
    let cj: serde_json::Value = serde_json::from_slice(&c.stdout).unwrap();
    // calibrate's σ hold the matcher's bias on rotations, from the log's lines' tilt
    // noise (or range noise and ray spacing), which a tuple file does not carry:
    // stated to solve.
    let check = &cj["match_self_check"];
    let bias = odocal_pipeline::matcher_bias::matcher_bias_sd(
        check["range_noise_m"].as_f64().unwrap(),
        check["ray_spacing_rad"].as_f64().unwrap(),
        check["tilt_sigma_rad"].as_f64(),
    );
    assert!(bias[2] > 0.0, "{check}");
    let bias = format!("{},{},{}", bias[0], bias[1], bias[2]);
    let s = odocal(&[
        "solve",
        tuples.to_str().unwrap(),
        "--json",
        "--matcher-bias",
        &bias,
    ]);
    assert!(s.status.success(), "{}", text(&s.stderr));
    let sj: serde_json::Value = serde_json::from_slice(&s.stdout).unwrap();
    for key in ["r_l", "r_r", "b", "l_x", "l_y", "l_theta"] {
        let (a, b) = (cj[key].as_f64().unwrap(), sj[key].as_f64().unwrap());
        assert!(
            (a - b).abs() <= 1e-9 * a.abs().max(1e-3),
            "{key}: calibrate {a}, solve {b}"
        );
    }
    for i in 0..6 {
        let (a, b) = (
            cj["covariance"][i][i].as_f64().unwrap(),
            sj["covariance"][i][i].as_f64().unwrap(),
        );
        assert!(
            (a / b - 1.0).abs() < 1e-6,
            "variance {i}: calibrate {a}, solve {b}"
        );
    }
    // The sm_cov weighting is an explicit option of both, and changes the answer.
    let w = odocal(&[
        "solve",
        tuples.to_str().unwrap(),
        "--json",
        "--icp-covariance",
    ]);
    assert!(w.status.success(), "{}", text(&w.stderr));
    let wj: serde_json::Value = serde_json::from_slice(&w.stdout).unwrap();
    assert_eq!(wj["noise_source"], "sample_covariance");
    assert_ne!(wj["r_l"], sj["r_l"]);
    cleanup(&path);
}

#[test]
fn dev_zero_fails_fast_on_every_reading_command() {
    if !std::path::Path::new("/dev/zero").exists() {
        println!("skipped: no /dev/zero");
        return;
    }
    for cmd in ["info", "calibrate", "match"] {
        let out =
            std::env::temp_dir().join(format!("odocal-dev-zero-{}.tuple", std::process::id()));
        let mut args = vec![cmd, "/dev/zero"];
        if cmd == "match" {
            args.extend(["--out", out.to_str().unwrap()]);
        }
        let o = odocal(&args);
        let err = text(&o.stderr);
        assert!(!o.status.success() && o.stdout.is_empty(), "{cmd}: {err}");
        assert!(err.contains("/dev/zero:1: not a text log"), "{cmd}: {err}");
    }
}

#[test]
fn every_reading_command_takes_the_reading_options() {
    for cmd in ["calibrate", "match", "info"] {
        let help = text(&odocal(&[cmd, "--help"]).stdout);
        for opt in [
            "--ticks-per-rev",
            "--encoder-modulus",
            "--min-range",
            "--time-increment",
            "--lenient",
        ] {
            assert!(help.contains(opt), "{cmd} lacks {opt}");
        }
    }
}

#[test]
fn an_offset_beyond_the_search_range_names_the_wider_range() {
    let (path, _) = simulated_log("cli-health-offset", "khepera-displaced", 60.0, 63, |c| {
        c.faults.clock_offset = 1.2;
    });
    let log = path.to_str().unwrap();
    let o = odocal(&["calibrate", log, "--estimate-time-offset", "--accept-weak"]);
    let all = text(&o.stdout) + &text(&o.stderr);
    assert!(all.contains("edge of the search range"), "{all}");
    let wider: String = all
        .split("--time-offset-range ")
        .nth(1)
        .expect("a wider range is suggested")
        .chars()
        .take_while(|c| c.is_ascii_digit() || *c == '.')
        .collect();
    let w: f64 = wider.parse().expect("a number");
    assert!((1.3..=3.0).contains(&w), "suggested {w}");
    // Widened as suggested, the offset is found and the warning is gone.
    let o = odocal(&["calibrate", log, "--time-offset-range", &wider, "--json"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let est = v["time_offset_s"].as_f64().unwrap();
    assert!((est - 1.2).abs() < 0.005, "estimated {est}");
    assert!(v["health"]
        .as_array()
        .unwrap()
        .iter()
        .all(|f| f["kind"] != "clock_offset"));
    cleanup(&path);
}

#[test]
fn terminal_escapes_in_a_log_are_never_echoed_raw() {
    let dir = common::temp_dir("cli-health-escape");
    let path = dir.join("esc.log");
    std::fs::write(
        &path,
        "\x1b]0;pwned\x07FAKE 1 2\nENCODER 1 \x1b[2J 3.0 h 3.0\n",
    )
    .unwrap();
    let o = odocal(&["info", path.to_str().unwrap(), "--lenient"]);
    let out = text(&o.stdout) + &text(&o.stderr);
    assert!(o.status.success(), "{out}");
    assert!(!out.contains('\x1b') && !out.contains('\x07'), "{out:?}");
    assert!(out.contains("\\x1b]0;pwned\\x07FAKE"), "{out}");
    let o = odocal(&["info", path.to_str().unwrap()]);
    let err = text(&o.stderr);
    assert!(!o.status.success() && !err.contains('\x1b'), "{err:?}");
    assert!(err.contains("\\x1b[2J"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn info_names_the_faults_it_can_see_without_matching() {
    let (path, _) = simulated_log("cli-health-info", "khepera", 20.0, 64, |_| {});
    let text_log = std::fs::read_to_string(&path).unwrap();
    let doubled: String = text_log
        .lines()
        .flat_map(|l| {
            let n = if l.starts_with("ENCODER") { 2 } else { 1 };
            std::iter::repeat_n(format!("{l}\n"), n)
        })
        .collect();
    std::fs::write(&path, doubled).unwrap();
    let o = odocal(&["info", path.to_str().unwrap(), "--json"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let h = v["health"].as_array().expect("a health list");
    assert_eq!(h.len(), 1, "{h:?}");
    assert_eq!(h[0]["kind"], "duplicate");
    assert_eq!(h[0]["count"], 1000);
    cleanup(&path);
}
