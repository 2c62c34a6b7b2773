//! Opening a log file and choosing the reader: Carmen-style text, or the original
//! package's JSON log (first non-blank byte `{`).

use crate::carmen::read_carmen_from;
use crate::error::LogError;
use crate::json_log::read_json_log_from;
use crate::model::Log;
use crate::options::ReadOptions;
use std::fs::File;
use std::io::{BufRead, BufReader};
use std::path::Path;

/// The two log formats this crate reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LogFormat {
    /// Carmen-style text (PARAM, ENCODER, RAWLASER1, …).
    Carmen,
    /// The original package's stream of JSON objects.
    Json,
}

/// Guesses the format from the first non-blank byte in the reader's buffer, consuming
/// nothing: `{` means JSON, anything else (or a buffer of blanks) Carmen text.
pub fn detect_format<R: BufRead>(reader: &mut R) -> std::io::Result<LogFormat> {
    let buf = reader.fill_buf()?;
    Ok(match buf.iter().find(|b| !b.is_ascii_whitespace()) {
        Some(b'{') => LogFormat::Json,
        _ => LogFormat::Carmen,
    })
}

/// Fails fast, before any parsing, when the start of the input holds a NUL byte: a
/// binary file or `/dev/zero` is not a text log.
fn refuse_binary<R: BufRead>(reader: &mut R, name: &str) -> Result<(), LogError> {
    let buf = reader.fill_buf().map_err(|e| LogError::io(name, e))?;
    match buf.iter().position(|&b| b == 0) {
        None => Ok(()),
        Some(i) => Err(LogError::NotText {
            file: name.to_string(),
            line: buf[..i].iter().filter(|&&b| b == b'\n').count() as u64 + 1,
            detail: format!(
                "a NUL byte at byte {} (binary data; expected Carmen-style text or a JSON log)",
                i + 1
            ),
        }),
    }
}

/// Reads a log file, Carmen-style text or the original package's JSON log.
pub fn read_log(path: &Path, opts: &ReadOptions) -> Result<Log, LogError> {
    let name = path.display().to_string();
    let file = File::open(path).map_err(|e| LogError::io(&name, e))?;
    read_log_from(BufReader::with_capacity(1 << 18, file), &name, opts)
}

/// Reads a log, Carmen-style text or JSON, from `reader` (a file, a pipe, standard
/// input: it is read once, from start to end); `name` names it in messages.
pub fn read_log_from<R: BufRead>(
    mut reader: R,
    name: &str,
    opts: &ReadOptions,
) -> Result<Log, LogError> {
    let format = detect_format(&mut reader).map_err(|e| LogError::io(name, e))?;
    refuse_binary(&mut reader, name)?;
    match format {
        LogFormat::Carmen => read_carmen_from(reader, name, opts),
        LogFormat::Json => read_json_log_from(reader, name, opts),
    }
}
