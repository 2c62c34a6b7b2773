//! Streams of JSON objects (the original package's raw logs and tuple files): objects
//! follow each other with optional whitespace, and several may share one line.

use crate::error::LogError;
use crate::line_reader::MAX_LINE_BYTES;
use serde::de::DeserializeOwned;
use std::cell::RefCell;
use std::io::Read;
use std::rc::Rc;

/// A reader that remembers where each `\n` is, so that a byte offset reported by the
/// JSON stream can be turned into a 1-based line number. It also bounds memory as the
/// text reader does: a NUL byte (binary data) or a line longer than
/// [`MAX_LINE_BYTES`] stops the stream with an error.
struct NewlineTracker<R> {
    inner: R,
    consumed: u64,
    newlines: Rc<RefCell<Vec<u64>>>,
}

impl<R: Read> Read for NewlineTracker<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        let mut newlines = self.newlines.borrow_mut();
        for (i, &b) in buf[..n].iter().enumerate() {
            let at = self.consumed + i as u64;
            if b == b'\n' {
                newlines.push(at);
                continue;
            }
            if b == 0 {
                return Err(std::io::Error::other(format!(
                    "line {}: not a text log: a NUL byte (binary data)",
                    newlines.len() + 1
                )));
            }
            let line_start = newlines.last().map_or(0, |&nl| nl + 1);
            if at - line_start >= MAX_LINE_BYTES as u64 {
                return Err(std::io::Error::other(format!(
                    "line {}: expected a line of at most {MAX_LINE_BYTES} bytes",
                    newlines.len() + 1
                )));
            }
        }
        self.consumed += n as u64;
        Ok(n)
    }
}

/// The 1-based line holding byte `offset`, given the sorted offsets of every `\n`.
fn line_of(newlines: &[u64], offset: u64) -> u64 {
    newlines.partition_point(|&nl| nl < offset) as u64 + 1
}

/// Turns a serde_json error into a [`LogError`] naming the file and line.
fn json_error(name: &str, message: &str, what: &str, e: serde_json::Error) -> LogError {
    if e.classify() == serde_json::error::Category::Io {
        return LogError::io(name, std::io::Error::other(e.to_string()));
    }
    let text = e.to_string();
    let reason = match text.rfind(" at line ") {
        Some(i) => &text[..i],
        None => &text[..],
    };
    LogError::parse(
        name,
        e.line() as u64,
        message,
        format!("expected {what} ({reason}, column {})", e.column()),
    )
}

/// Reads every object of a JSON stream, calling `each(object, line)` where `line` is the
/// 1-based line on which the object ends. Stops at the first error (malformed JSON,
/// a missing or ill-typed field, or an error returned by `each`).
pub(crate) fn for_each_object<T, R, F>(
    reader: R,
    name: &str,
    message: &str,
    what: &str,
    mut each: F,
) -> Result<(), LogError>
where
    T: DeserializeOwned,
    R: Read,
    F: FnMut(T, u64) -> Result<(), LogError>,
{
    let newlines = Rc::new(RefCell::new(Vec::new()));
    let tracker = NewlineTracker {
        inner: reader,
        consumed: 0,
        newlines: Rc::clone(&newlines),
    };
    let mut stream = serde_json::Deserializer::from_reader(tracker).into_iter::<T>();
    while let Some(item) = stream.next() {
        let value = item.map_err(|e| json_error(name, message, what, e))?;
        let last_byte = (stream.byte_offset() as u64).saturating_sub(1);
        let line = line_of(&newlines.borrow(), last_byte);
        each(value, line)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nul_bytes_and_endless_lines_stop_the_stream() {
        let r = for_each_object::<serde_json::Value, _, _>(
            &b"{\"a\": 1}\n{\"b\": \0}"[..],
            "j",
            "JSON",
            "an object",
            |_, _| Ok(()),
        );
        let e = r.unwrap_err().to_string();
        assert!(e.contains("line 2: not a text log"), "{e}");
        let mut long = b"[".to_vec();
        long.extend(std::iter::repeat_n(b' ', MAX_LINE_BYTES + 10));
        let r = for_each_object::<serde_json::Value, _, _>(
            &long[..],
            "j",
            "JSON",
            "an object",
            |_, _| Ok(()),
        );
        assert!(r.unwrap_err().to_string().contains("at most"));
    }

    #[test]
    fn line_of_counts_newlines_before_the_offset() {
        let nl = [3, 7];
        assert_eq!(line_of(&nl, 0), 1);
        assert_eq!(line_of(&nl, 3), 1);
        assert_eq!(line_of(&nl, 4), 2);
        assert_eq!(line_of(&nl, 8), 3);
    }
}
