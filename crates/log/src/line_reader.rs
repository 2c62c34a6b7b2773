//! Reading a text log line by line with bounded memory: a line longer than
//! [`MAX_LINE_BYTES`] is not buffered whole, and NUL bytes (binary data, `/dev/zero`)
//! are refused at once.

use std::io::{self, BufRead};

/// The longest line read (bytes). A 681-ray scan line is about 5 kB, a 10,000-ray scan
/// with remissions under 200 kB.
pub const MAX_LINE_BYTES: usize = 1 << 20;

/// What reading one line gave.
#[derive(Debug, PartialEq, Eq)]
pub(crate) enum Line {
    /// The end of the input.
    End,
    /// A line (in the buffer, with its `\n` if any).
    Text,
    /// A line longer than [`MAX_LINE_BYTES`]; its bytes were skipped up to and
    /// including its `\n`, and the buffer holds only its beginning.
    TooLong,
    /// A NUL byte at this 0-based position of the line; the rest of the line skipped.
    Nul(usize),
}

/// Reads one line into `buf` (cleared first), keeping at most [`MAX_LINE_BYTES`].
#[cfg(test)]
pub(crate) fn read_line<R: BufRead>(reader: &mut R, buf: &mut Vec<u8>) -> io::Result<Line> {
    buf.clear();
    append_line(reader, buf)
}

/// Reads one line onto the end of `buf`, keeping at most [`MAX_LINE_BYTES`] of it:
/// the line is `buf[len before..]` (its beginning only, when [`Line::TooLong`]).
pub(crate) fn append_line<R: BufRead>(reader: &mut R, buf: &mut Vec<u8>) -> io::Result<Line> {
    let start = buf.len();
    let mut too_long = false;
    let mut nul: Option<usize> = None;
    let mut seen = 0usize;
    loop {
        let chunk = match reader.fill_buf() {
            Ok(c) => c,
            Err(e) if e.kind() == io::ErrorKind::Interrupted => continue,
            Err(e) => return Err(e),
        };
        if chunk.is_empty() {
            break;
        }
        let (take, done) = match memchr::memchr(b'\n', chunk) {
            Some(i) => (i + 1, true),
            None => (chunk.len(), false),
        };
        if nul.is_none() {
            if let Some(i) = memchr::memchr(0, &chunk[..take]) {
                nul = Some(seen + i);
            }
        }
        if !too_long && nul.is_none() {
            let room = MAX_LINE_BYTES - (buf.len() - start);
            if take > room {
                buf.extend_from_slice(&chunk[..room]);
                too_long = true;
            } else {
                buf.extend_from_slice(&chunk[..take]);
            }
        }
        seen += take;
        reader.consume(take);
        if done {
            break;
        }
        if let Some(i) = nul {
            // Binary data: do not scan on for a line end that may never come.
            return Ok(Line::Nul(i));
        }
    }
    Ok(match (nul, too_long) {
        (Some(i), _) => Line::Nul(i),
        (None, true) => Line::TooLong,
        (None, false) if seen == 0 => Line::End,
        _ => Line::Text,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_nul_and_long_lines() {
        let mut buf = Vec::new();
        let mut r = &b"ab\ncd"[..];
        assert_eq!(read_line(&mut r, &mut buf).unwrap(), Line::Text);
        assert_eq!(buf, b"ab\n");
        assert_eq!(read_line(&mut r, &mut buf).unwrap(), Line::Text);
        assert_eq!(buf, b"cd");
        assert_eq!(read_line(&mut r, &mut buf).unwrap(), Line::End);

        let mut r = &b"a\0b\nnext\n"[..];
        assert_eq!(read_line(&mut r, &mut buf).unwrap(), Line::Nul(1));

        let long = vec![b'x'; MAX_LINE_BYTES + 10];
        let mut text = long.clone();
        text.extend_from_slice(b"\nok\n");
        let mut r = io::BufReader::with_capacity(4096, &text[..]);
        assert_eq!(read_line(&mut r, &mut buf).unwrap(), Line::TooLong);
        assert_eq!(buf.len(), MAX_LINE_BYTES);
        assert_eq!(read_line(&mut r, &mut buf).unwrap(), Line::Text);
        assert_eq!(buf, b"ok\n");
    }
}
