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

/// Reads a log file, Carmen-style text or the original package's JSON log.
pub fn read_log(path: &Path, opts: &ReadOptions) -> Result<Log, LogError> {
    let name = path.display().to_string();
    let file = File::open(path).map_err(|e| LogError::io(&name, e))?;
    let mut reader = BufReader::with_capacity(1 << 18, file);
    let format = detect_format(&mut reader).map_err(|e| LogError::io(&name, e))?;
    match format {
        LogFormat::Carmen => read_carmen_from(reader, &name, opts),
        LogFormat::Json => read_json_log_from(reader, &name, opts),
    }
}
