//! Hostile inputs and terminals (issue 22): a text log is read once, so a pipe, a FIFO,
//! process substitution (a pipe at a path: `/dev/stdin` here) and `-` give what the
//! file gives; a bag through a pipe is refused with the fix; a failed write to stdout
//! is an error, not a panic; text from the file is escaped before the terminal.

#![cfg(target_os = "linux")]

mod common;

use common::{stderr, temp_dir};
use std::io::Write;
use std::path::Path;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

/// A path under the repository root.
fn fixture(rel: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join(rel)
        .to_string_lossy()
        .into_owned()
}

/// Runs odocal with `args`, `input` written to its standard input.
fn with_stdin(args: &[&str], input: &[u8]) -> Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_odocal"))
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("odocal starts");
    let mut stdin = child.stdin.take().unwrap();
    let input = input.to_vec();
    // A reader that refuses early closes the pipe: ignore the write error then.
    let writer = std::thread::spawn(move || {
        let _ = stdin.write_all(&input);
    });
    let out = child.wait_with_output().expect("odocal ends");
    writer.join().unwrap();
    out
}

/// `info`'s text after the `log:` line (the name), which must not depend on how the
/// log arrived.
fn body(o: &Output) -> String {
    let text = String::from_utf8_lossy(&o.stdout).into_owned();
    text.lines().skip(1).collect::<Vec<_>>().join("\n")
}

fn odocal(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_odocal"))
        .args(args)
        .output()
        .expect("odocal runs")
}

#[test]
fn a_piped_log_reads_as_the_file() {
    let demo = fixture("fixtures/demo.log");
    let bytes = std::fs::read(&demo).unwrap();
    let from_file = odocal(&["info", &demo]);
    assert!(from_file.status.success(), "{}", stderr(&from_file));
    for path in ["/dev/stdin", "-"] {
        let piped = with_stdin(&["info", path], &bytes);
        assert!(piped.status.success(), "{path}: {}", stderr(&piped));
        assert_eq!(
            body(&piped),
            body(&from_file),
            "info {path} differs from the file's"
        );
    }
    let sha = |o: &Output| {
        let v: serde_json::Value = serde_json::from_slice(&o.stdout).expect("JSON");
        v["provenance"]["input_sha256"]
            .as_str()
            .unwrap()
            .to_string()
    };
    let file = odocal(&["calibrate", &demo, "--json", "--threads", "1"]);
    let piped = with_stdin(&["calibrate", "-", "--json", "--threads", "1"], &bytes);
    assert!(piped.status.success(), "{}", stderr(&piped));
    assert_eq!(sha(&piped), sha(&file));
}

#[test]
fn a_fifo_with_a_writer_is_read_not_waited_on() {
    let dir = temp_dir("fifo");
    let fifo = dir.join("log.fifo");
    let made = Command::new("mkfifo").arg(&fifo).status().expect("mkfifo");
    assert!(made.success());
    let bytes = std::fs::read(fixture("fixtures/demo.log")).unwrap();
    let path = fifo.clone();
    let writer = std::thread::spawn(move || {
        // Opening blocks until odocal opens the other end.
        if let Ok(mut f) = std::fs::OpenOptions::new().write(true).open(&path) {
            let _ = f.write_all(&bytes);
        }
    });
    let mut child = Command::new(env!("CARGO_BIN_EXE_odocal"))
        .args(["info", fifo.to_str().unwrap()])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > Duration::from_secs(20) {
            let _ = child.kill();
            // The writer thread may be left blocked; the test process ends anyway.
            panic!("odocal info on a FIFO did not finish in 20 s");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    let out = child.wait_with_output().unwrap();
    writer.join().unwrap();
    assert!(out.status.success(), "{}", stderr(&out));
    let from_file = odocal(&["info", &fixture("fixtures/demo.log")]);
    assert_eq!(
        body(&out),
        body(&from_file),
        "the FIFO read differs from the file"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_bag_through_a_pipe_is_refused_with_the_fix() {
    let bytes = std::fs::read(fixture("fixtures/bags/turtlebot_lds.bag")).unwrap();
    let out = with_stdin(&["info", "-"], &bytes);
    let err = stderr(&out);
    assert!(!out.status.success(), "{err}");
    assert!(
        err.contains("ROS bag") && err.contains("save it to a file"),
        "{err}"
    );
}

#[test]
fn a_full_stdout_is_an_error_not_a_panic() {
    for args in [
        &["info", "fixtures/demo.log"][..],
        &["info", "fixtures/demo.log", "--json"][..],
    ] {
        let full = std::fs::OpenOptions::new()
            .write(true)
            .open("/dev/full")
            .unwrap();
        let out = Command::new(env!("CARGO_BIN_EXE_odocal"))
            .args(args)
            .current_dir(env!("CARGO_MANIFEST_DIR"))
            .stdout(full)
            .stderr(Stdio::piped())
            .output()
            .unwrap();
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{err}");
        assert!(err.contains("cannot write to standard output"), "{err}");
    }
}

#[test]
fn text_from_the_log_is_escaped_on_the_terminal() {
    let dir = temp_dir("escape");
    let log = dir.join("evil.log");
    let mut text = std::fs::read(fixture("fixtures/demo.log")).unwrap();
    text.extend_from_slice("EVIL\x1b]0;pwned\x07\u{202e}X 1 2\n".as_bytes());
    std::fs::write(&log, &text).unwrap();
    let log = log.to_str().unwrap();
    for args in [&["info", log][..], &["info", log, "--json"][..]] {
        let out = odocal(args);
        assert!(out.status.success(), "{}", stderr(&out));
        let shown = String::from_utf8_lossy(&out.stdout).into_owned() + &stderr(&out);
        assert!(
            shown.contains("EVIL"),
            "{args:?}: the name is shown\n{shown}"
        );
        for raw in ['\x1b', '\x07', '\u{202e}'] {
            assert!(
                !shown.contains(raw),
                "{args:?}: {raw:?} printed raw\n{shown}"
            );
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bag_topic_and_joint_names_are_escaped_on_the_terminal() {
    let bag = fixture("fixtures/bags/hostile_names.bag");
    let evil = "\x1b]0;pwned\x07\x1b[2J\u{202e}";
    for args in [
        &["info", &bag][..],
        &["info", &bag, "--json"][..],
        &["calibrate", &bag][..],
    ] {
        let out = odocal(args);
        let shown = String::from_utf8_lossy(&out.stdout).into_owned() + &stderr(&out);
        assert!(!shown.contains("panicked"), "{shown}");
        assert!(
            shown.contains("wheel_left_joint"),
            "{args:?}: names shown\n{shown}"
        );
        for raw in ['\x1b', '\x07', '\u{202e}'] {
            assert!(
                !shown.contains(raw),
                "{args:?}: {raw:?} printed raw\n{shown}"
            );
        }
    }
    // JSON escapes keep the names as they are in the bag.
    let out = odocal(&["info", &bag, "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON");
    let topic = format!("/scan{evil}");
    assert!(v["topics"].get(&topic).is_some(), "{v}");
}
