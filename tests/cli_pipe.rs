//! Output into a pipe whose reader has gone (`odocal … | head -1`) ends the process
//! quietly, as it does `cat`: no panic message, no backtrace.

use std::process::{Command, Stdio};

/// Runs odocal with `args`, closes the reading end of its stdout at once (before it
/// has printed anything) and returns what it wrote to stderr.
fn stderr_with_stdout_closed(args: &[&str]) -> String {
    let mut child = Command::new(env!("CARGO_BIN_EXE_odocal"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("odocal starts");
    drop(child.stdout.take());
    let out = child.wait_with_output().expect("odocal ends");
    String::from_utf8_lossy(&out.stderr).into_owned()
}

#[test]
fn a_closed_pipe_is_not_a_panic() {
    for args in [
        &["calibrate", "fixtures/demo.log", "--json"][..],
        &["calibrate", "fixtures/demo.log"][..],
        &["info", "fixtures/demo.log"][..],
    ] {
        let err = stderr_with_stdout_closed(args);
        assert!(
            !err.contains("panicked") && !err.contains("Broken pipe"),
            "odocal {args:?} wrote on a closed pipe:\n{err}"
        );
    }
}
