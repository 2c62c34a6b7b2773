//! Everything the CLI prints goes through here, so that (1) text that came from a file
//! (topic and joint names, Carmen lines in messages, file names) reaches the terminal
//! escaped — control characters, ANSI escapes, bidirectional overrides — and (2) a
//! failed write to standard output (`> /dev/full`) is an error and exit status 1, not
//! a panic. A closed pipe still ends the process quietly (SIGPIPE, see `main.rs`).

use anyhow::Context;
use odocal_log::{json_text, terminal_text};
use std::io::Write;

/// Writes `text`, escaped by [`terminal_text`], to standard output.
pub fn write_stdout(text: &str) -> anyhow::Result<()> {
    let mut out = std::io::stdout().lock();
    out.write_all(terminal_text(text).as_bytes())
        .and_then(|()| out.flush())
        .context("cannot write to standard output")
}

/// Writes the JSON document `json` and a line break, its C1 controls and bidirectional
/// overrides written as JSON escapes by [`json_text`], to standard output.
pub fn write_json_stdout(json: &str) -> anyhow::Result<()> {
    let mut out = std::io::stdout().lock();
    out.write_all(json_text(json).as_bytes())
        .and_then(|()| out.write_all(b"\n"))
        .and_then(|()| out.flush())
        .context("cannot write to standard output")
}

/// Writes `text`, escaped by [`terminal_text`], to standard error; a failure to do so
/// has nowhere to be reported and is ignored.
pub fn write_stderr(text: &str) {
    let _ = std::io::stderr()
        .lock()
        .write_all(terminal_text(text).as_bytes());
}

/// `print!` through [`write_stdout`]: an `anyhow::Result`.
macro_rules! out {
    ($($arg:tt)*) => {
        $crate::terminal::write_stdout(&format!($($arg)*))
    };
}

/// `println!` through [`write_stdout`]: an `anyhow::Result`.
macro_rules! outln {
    () => {
        $crate::terminal::write_stdout("\n")
    };
    ($($arg:tt)*) => {
        $crate::terminal::write_stdout(&format!("{}\n", format_args!($($arg)*)))
    };
}

/// `eprintln!` through [`write_stderr`].
macro_rules! errln {
    ($($arg:tt)*) => {
        $crate::terminal::write_stderr(&format!("{}\n", format_args!($($arg)*)))
    };
}

pub(crate) use {errln, out, outln};
