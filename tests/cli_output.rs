//! Hostile output paths (issue 22): `--report`, `--out` and `match --out` never replace
//! anything but a regular file they may replace — not a device, not the input (by any
//! name), not a file a planted symlink points to — and `--out` is written as a whole,
//! also by two runs at once.

#![cfg(unix)]

mod common;

use common::{odocal, stderr, temp_dir};
use std::fs;
use std::os::unix::fs::FileTypeExt;
use std::path::{Path, PathBuf};
use std::process::Output;

/// The bundled demo log, by absolute path.
fn demo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/demo.log")
}

/// A copy of the demo log in `dir`, named `name`.
fn demo_copy(dir: &Path, name: &str) -> PathBuf {
    let p = dir.join(name);
    fs::copy(demo(), &p).expect("copy the demo log");
    p
}

fn s(p: &Path) -> &str {
    p.to_str().expect("UTF-8 path")
}

/// A refusal: non-zero exit, "error:" and `needle` on stderr, no panic.
fn assert_refused(o: &Output, needle: &str) {
    let err = stderr(o);
    assert!(!o.status.success(), "expected a refusal: {err}");
    assert!(!err.contains("panicked"), "{err}");
    assert!(err.contains("error:") && err.contains(needle), "{err}");
}

/// Devices and FIFOs are refused. The devices are reached through symlinks in a
/// temporary directory: a writer that wrongly renames over its target then replaces
/// the link, not the machine's /dev/full (as the writer before this test did when run
/// as root).
#[test]
fn devices_and_fifos_are_not_replaced() {
    let dir = temp_dir("out-devices");
    let fifo = dir.join("report.fifo");
    let made = std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .expect("mkfifo");
    assert!(made.success());
    let mut targets = vec![(fifo.clone(), "FIFO")];
    for dev in ["/dev/full", "/dev/null"] {
        let link = dir.join(format!("{}.html", &dev[5..]));
        std::os::unix::fs::symlink(dev, &link).unwrap();
        targets.push((link, "a device"));
    }
    for (target, kind) in &targets {
        let o = odocal(&["calibrate", s(&demo()), "--report", s(target)]);
        assert_refused(&o, kind);
        let t = fs::metadata(target).unwrap().file_type();
        assert!(t.is_char_device() || t.is_fifo(), "{target:?} was replaced");
    }
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn the_input_is_never_an_output() {
    let dir = temp_dir("out-input");
    let log = demo_copy(&dir, "victim.log");
    let link = dir.join("link.log");
    std::os::unix::fs::symlink(&log, &link).unwrap();
    let hard = dir.join("hard.log");
    fs::hard_link(&log, &hard).unwrap();
    let before = fs::read(&log).unwrap();
    for out in [&log, &link, &hard] {
        let o = odocal(&["calibrate", s(&log), "--report", s(out)]);
        assert_refused(&o, "is the input");
        let o = odocal(&["match", s(&link), "--out", s(out)]);
        assert_refused(&o, "is the input");
    }
    // The input as a file of the --out directory.
    let out = dir.join("res");
    fs::create_dir(&out).unwrap();
    let samples = demo_copy(&out, "samples.tuple");
    let o = odocal(&["calibrate", s(&samples), "--out", s(&out)]);
    assert_refused(&o, "holds the input");
    assert_eq!(fs::read(&log).unwrap(), before);
    assert_eq!(fs::read(&samples).unwrap(), before);
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn a_planted_temporary_symlink_is_not_followed() {
    let dir = temp_dir("out-symlink");
    let victim = dir.join("victim.txt");
    fs::write(&victim, "precious").unwrap();
    std::os::unix::fs::symlink(&victim, dir.join(".r.html.tmp")).unwrap();
    let report = dir.join("r.html");
    let o = odocal(&["calibrate", s(&demo()), "--report", s(&report)]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(fs::read_to_string(&victim).unwrap(), "precious");
    assert!(fs::read_to_string(&report).unwrap().contains("<html"));
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn an_out_directory_of_other_files_is_refused() {
    let dir = temp_dir("out-other");
    fs::write(dir.join("notes.txt"), "mine").unwrap();
    let o = odocal(&["calibrate", s(&demo()), "--out", s(&dir)]);
    assert_refused(&o, "notes.txt");
    assert_eq!(fs::read_to_string(dir.join("notes.txt")).unwrap(), "mine");
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn two_runs_into_one_out_directory_leave_one_whole_set() {
    let dir = temp_dir("out-race");
    let out = dir.join("res");
    let logs = [demo_copy(&dir, "a.log"), demo_copy(&dir, "b.log")];
    for round in 0..3 {
        let spawned: Vec<_> = logs
            .iter()
            .map(|log| {
                std::process::Command::new(env!("CARGO_BIN_EXE_odocal"))
                    .args(["calibrate", s(log), "--threads", "1", "--out", s(&out)])
                    .stdout(std::process::Stdio::null())
                    .stderr(std::process::Stdio::piped())
                    .spawn()
                    .expect("odocal starts")
            })
            .collect();
        for child in spawned {
            let o = child.wait_with_output().unwrap();
            assert!(o.status.success(), "round {round}: {}", stderr(&o));
        }
        let json: serde_json::Value =
            serde_json::from_slice(&fs::read(out.join("results.json")).unwrap()).unwrap();
        let log = json["log"].as_str().unwrap();
        let html = fs::read_to_string(out.join("results.html")).unwrap();
        let other = if log.ends_with("a.log") {
            "b.log"
        } else {
            "a.log"
        };
        assert!(
            html.contains(log),
            "round {round}: results.html is not {log}'s"
        );
        assert!(
            !html.contains(other),
            "round {round}: results.html is {other}'s"
        );
        let mut names: Vec<_> = fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .collect();
        names.sort();
        assert_eq!(names, ["a.log", "b.log", "res"], "no temporary left");
    }
    let _ = fs::remove_dir_all(&dir);
}
