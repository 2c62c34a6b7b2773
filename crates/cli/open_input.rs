//! Opening the input: a ROS bag is read by path (its readers seek), a Carmen or JSON
//! log is read once from start to end, so it may come through a pipe, a FIFO, process
//! substitution (`<(zcat run.log.gz)`) or standard input (`-`), and its checksum is
//! computed on the same pass (read and hashed on another thread: [`HashedInput`]).

use crate::hashing_thread::{Checksum, HashedInput};
use anyhow::Context;
use odocal_bag::{bag_format_of_head, detect_bag};
use odocal_log::{read_log_from, Log, LogError, ReadOptions};
use std::fs::File;
use std::io::{self, Cursor, Read};
use std::path::Path;

/// Bytes read ahead to tell a bag from a text log, and all the log reader checks for
/// NUL bytes before parsing (its buffer: 256 kB).
const HEAD_BYTES: u64 = 1 << 18;

/// True when `path` is standard input.
pub fn is_stdin(path: &Path) -> bool {
    path == Path::new("-")
}

/// The name of the input in messages.
pub fn input_name(path: &Path) -> String {
    if is_stdin(path) {
        "standard input".to_string()
    } else {
        path.display().to_string()
    }
}

/// True when `path` is a bag that can be read by seeking: a regular file or a
/// directory. A stream (pipe, FIFO, device, `-`) is never opened here, since that
/// would consume it; [`read_text_log`] tells a bag in a stream apart.
pub fn is_bag_file(path: &Path) -> anyhow::Result<bool> {
    if is_stdin(path) {
        return Ok(false);
    }
    let meta =
        std::fs::metadata(path).with_context(|| format!("cannot open {}", path.display()))?;
    if !meta.is_file() && !meta.is_dir() {
        return Ok(false);
    }
    Ok(detect_bag(path)
        .with_context(|| format!("cannot open {}", path.display()))?
        .is_some())
}

/// Reads the Carmen or JSON log at `path` (`-`: standard input) in one pass; returns it
/// with the SHA-256 and size of the input when `checksum` asks for them.
pub fn read_text_log(
    path: &Path,
    opts: &ReadOptions,
    checksum: bool,
) -> anyhow::Result<(Log, Option<Checksum>)> {
    let name = input_name(path);
    let source: Box<dyn Read + Send> = if is_stdin(path) {
        Box::new(io::stdin())
    } else {
        Box::new(File::open(path).map_err(|e| LogError::io(&name, e))?)
    };
    let started = if checksum {
        HashedInput::new(source)
    } else {
        HashedInput::unhashed(source)
    };
    let mut hashing = started.map_err(|e| LogError::io(&name, e))?;
    let mut head = Vec::new();
    (&mut hashing)
        .take(HEAD_BYTES)
        .read_to_end(&mut head)
        .map_err(|e| LogError::io(&name, e))?;
    if let Some(format) = bag_format_of_head(&head) {
        anyhow::bail!(
            "{name} is a ROS bag ({format:?}) arriving as a stream (a pipe, FIFO or standard \
             input); bags are read by seeking: save it to a file first (e.g. `cat {name} > \
             run.bag`) and give that file"
        );
    }
    // Buffered already: the head, then the hashed input's chunks.
    let reader = Cursor::new(head).chain(&mut hashing);
    // The reader's message already says everything (file, line, cause).
    let log = read_log_from(reader, &name, opts).map_err(|e| anyhow::anyhow!("{e}"))?;
    let checksum = hashing
        .finish()
        .map_err(|e| anyhow::anyhow!("{}", LogError::io(&name, e)))?;
    Ok((log, checksum))
}
