//! Hostile data (issue 22): numbers no real robot produces are refused quickly, in
//! bounded memory, with the value and the fix named — never an abort, never confident
//! wrong numbers. Each run of the binary is bounded: 2 GB of address space (`prlimit`,
//! when the machine has it) and 20 s of wall time.

mod common;

use common::{cleanup, temp_dir};
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

const ADDRESS_SPACE_BYTES: &str = "2000000000";
const WALL_LIMIT: Duration = Duration::from_secs(20);

/// Runs the binary with `args` under the memory and time bounds; panics when it
/// overruns them (a killed run is a failure, as an abort is).
fn bounded(args: &[&str]) -> Output {
    let bin = env!("CARGO_BIN_EXE_odocal");
    let prlimit = Path::new("/usr/bin/prlimit").exists();
    let mut cmd = if prlimit {
        let mut c = Command::new("/usr/bin/prlimit");
        c.arg(format!("--as={ADDRESS_SPACE_BYTES}")).arg(bin);
        c
    } else {
        eprintln!("notice: prlimit not found, the memory bound is not enforced");
        Command::new(bin)
    };
    let mut child = cmd
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the binary runs");
    let start = Instant::now();
    while child.try_wait().expect("wait").is_none() {
        if start.elapsed() > WALL_LIMIT {
            let _ = child.kill();
            panic!("odocal {args:?} ran longer than {WALL_LIMIT:?}");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    let out = child.wait_with_output().expect("output");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !err.contains("panicked") && !err.contains("memory allocation"),
        "odocal {args:?} crashed: {err}"
    );
    out
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

const DEMO: &str = "fixtures/demo.log";

/// The demo log with every record line rewritten by `edit` (its fields), written into
/// a fresh directory.
fn edited_demo(name: &str, edit: impl Fn(&mut Vec<String>)) -> PathBuf {
    let text = std::fs::read_to_string(DEMO).expect("the demo log");
    let mut out = String::with_capacity(text.len() + text.len() / 4);
    for line in text.lines() {
        let mut f: Vec<String> = line.split_whitespace().map(str::to_string).collect();
        if matches!(f.first().map(String::as_str), Some("ENCODER" | "RAWLASER1")) {
            edit(&mut f);
            out.push_str(&f.join(" "));
        } else {
            out.push_str(line);
        }
        out.push('\n');
    }
    let path = temp_dir(name).join(format!("{name}.log"));
    std::fs::write(&path, out).expect("write the log");
    path
}

/// Timestamps multiplied by `scale` (both of each record).
fn scaled_times(name: &str, scale: f64) -> PathBuf {
    edited_demo(name, |f| {
        let n = f.len();
        for k in [n - 3, n - 1] {
            let t: f64 = f[k].parse().expect("a timestamp");
            f[k] = format!("{:e}", t * scale);
        }
    })
}

/// Encoder counts mapped by `map`.
fn mapped_counts(name: &str, map: impl Fn(i64) -> i64) -> PathBuf {
    edited_demo(name, |f| {
        if f[0] == "ENCODER" {
            for k in [1, 2] {
                f[k] = map(f[k].parse().expect("a count")).to_string();
            }
        }
    })
}

fn calibrate_json(path: &Path) -> serde_json::Value {
    let o = bounded(&["calibrate", path.to_str().unwrap(), "--json"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    serde_json::from_slice(&o.stdout).expect("JSON")
}

#[test]
fn timestamps_in_another_unit_are_refused_quickly_naming_it() {
    // Before: 4.6 GiB allocated and an abort (the profile cut 10⁸ s spans into 25 ms
    // pieces); now a refusal in milliseconds.
    for (scale, unit) in [
        (1e6, "microseconds"),
        (1e9, "nanoseconds"),
        (1e290, "not seconds"),
    ] {
        let path = scaled_times(&format!("units-{scale:e}"), scale);
        let samples = path.with_extension("tuple");
        for command in ["calibrate", "match"] {
            let mut args = vec![command, path.to_str().unwrap()];
            if command == "match" {
                args.extend(["--out", samples.to_str().unwrap()]);
            }
            let o = bounded(&args);
            let err = text(&o.stderr);
            assert!(!o.status.success(), "{command} ×{scale:e}: {err}");
            assert!(err.contains(unit), "{command} ×{scale:e}: {err}");
            assert!(err.contains("write the timestamps in seconds"), "{err}");
        }
        cleanup(&path);
    }
}

#[test]
fn encoder_counts_no_wheel_can_make_are_refused() {
    // Before: r_L = 0 "well determined".
    let path = mapped_counts("counts-1e12", |c| c * 1_000_000_000_000);
    let o = bounded(&["calibrate", path.to_str().unwrap()]);
    let err = text(&o.stderr);
    assert!(!o.status.success(), "{}", text(&o.stdout));
    assert!(
        err.contains("revolutions per second") && err.contains("--ticks-per-rev"),
        "{err}"
    );
    cleanup(&path);
}

#[test]
fn counts_above_2_pow_53_give_the_same_calibration() {
    // Before: b off by 0.34 mm at 2^56 (the counts lost their last 4 bits as f64).
    let plain = calibrate_json(Path::new(DEMO));
    let path = mapped_counts("counts-2p56", |c| c + (1 << 56));
    let shifted = calibrate_json(&path);
    for key in ["r_l", "r_r", "b", "l_x", "l_y", "l_theta"] {
        let (a, b) = (plain[key].as_f64().unwrap(), shifted[key].as_f64().unwrap());
        assert!((a - b).abs() < 1e-9, "{key}: {a} vs {b}");
    }
    cleanup(&path);
}

#[test]
fn a_time_offset_range_beyond_the_log_is_refused_and_a_wide_one_is_bounded() {
    // Before: 1e9 asked for 3.2 TB, 1e6 ran for minutes.
    for range in ["1e9", "1e6", "31"] {
        let o = bounded(&["calibrate", DEMO, "--time-offset-range", range]);
        let err = text(&o.stderr);
        assert!(!o.status.success());
        assert!(
            err.contains(&format!(
                "--time-offset-range {}",
                range.parse::<f64>().unwrap()
            )) && err.contains("use at most --time-offset-range 29.9"),
            "{err}"
        );
    }
    for bad in ["inf", "NaN", "-1", "0"] {
        let o = bounded(&["calibrate", DEMO, &format!("--time-offset-range={bad}")]);
        assert!(!o.status.success());
        assert!(text(&o.stderr).contains("positive number of seconds"));
    }
    // The widest range the 60 s log supports: the grid is capped, the run bounded.
    let o = bounded(&["calibrate", DEMO, "--time-offset-range", "29"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
}

/// The demo log with its RAWLASER1 scans written as FLASER lines (no geometry on the
/// line), after `params` PARAM lines.
fn flaser_demo(name: &str, params: &[&str]) -> PathBuf {
    let text = std::fs::read_to_string(DEMO).expect("the demo log");
    let mut out = String::with_capacity(text.len());
    for p in params {
        out.push_str(p);
        out.push('\n');
    }
    for line in text.lines() {
        let f: Vec<&str> = line.split_whitespace().collect();
        if f.first() == Some(&"RAWLASER1") {
            // RAWLASER1 type start fov res max acc mode n r… m remissions… t host t
            let n: usize = f[8].parse().expect("num_readings");
            let ranges = &f[9..9 + n];
            let tail = &f[f.len() - 3..];
            out.push_str(&format!(
                "FLASER {n} {} 0 0 0 0 0 0 {}\n",
                ranges.join(" "),
                tail.join(" ")
            ));
        } else {
            out.push_str(line);
            out.push('\n');
        }
    }
    let path = temp_dir(name).join(format!("{name}.log"));
    std::fs::write(&path, out).expect("write the log");
    path
}

#[test]
fn flaser_without_its_field_of_view_is_refused_with_the_param_to_add() {
    // Before: π assumed for a 239° laser, and r_L −12σ off, "well determined".
    let bare = flaser_demo("flaser-bare", &[]);
    let o = bounded(&["calibrate", bare.to_str().unwrap()]);
    let err = text(&o.stderr);
    assert!(!o.status.success(), "{}", text(&o.stdout));
    assert!(
        err.contains("PARAM laser_front_laser_fov") && err.contains("line "),
        "{err}"
    );
    // With the PARAM the message names, the same numbers as the RAWLASER1 log.
    let fixed = flaser_demo(
        "flaser-fov",
        &["PARAM laser_front_laser_fov 4.172427743048944"],
    );
    let (plain, with_fov) = (calibrate_json(Path::new(DEMO)), calibrate_json(&fixed));
    for key in ["r_l", "r_r", "b"] {
        let (a, b) = (
            plain[key].as_f64().unwrap(),
            with_fov[key].as_f64().unwrap(),
        );
        assert!((a - b).abs() < 1e-6, "{key}: {a} vs {b}");
    }
    cleanup(&bare);
    cleanup(&fixed);
}
