//! Reading a text log a batch of lines at a time, with bounded memory, so that the
//! readings of a batch's scan lines can be parsed on several threads
//! ([`crate::range_prescan`]) before the lines are handled one by one, in order.

use crate::line_reader::{append_line, Line};
use std::io::{self, BufRead};
use std::ops::Range;

/// Bytes of text after which a batch is closed: a batch holds at most this plus one
/// line (itself at most [`crate::MAX_LINE_BYTES`]).
pub(crate) const BATCH_BYTES: usize = 1 << 20;

/// Consecutive lines of the input, each with what reading it gave.
pub(crate) struct LineBatch {
    /// The lines' bytes, one after the other (each with its `\n`, if any).
    pub(crate) text: Vec<u8>,
    /// Each line's bytes in `text` and what reading it gave: [`Line::Text`],
    /// [`Line::TooLong`] (its beginning only) or [`Line::Nul`].
    pub(crate) lines: Vec<(Range<usize>, Line)>,
    /// Nothing is to be read after these lines: the input ended, or the last line
    /// held a NUL byte (binary data, never read on).
    pub(crate) last: bool,
    /// The read error met after these lines, to report once they are handled.
    pub(crate) error: Option<io::Error>,
}

impl LineBatch {
    /// An empty batch.
    pub(crate) fn new() -> Self {
        LineBatch {
            text: Vec::with_capacity(BATCH_BYTES + (1 << 16)),
            lines: Vec::new(),
            last: false,
            error: None,
        }
    }

    /// Replaces the batch with the next lines of `reader`: up to [`BATCH_BYTES`], the
    /// end of the input, a line with a NUL byte, or a read error.
    pub(crate) fn fill<R: BufRead>(&mut self, reader: &mut R) {
        self.text.clear();
        self.lines.clear();
        while self.text.len() < BATCH_BYTES {
            let start = self.text.len();
            match append_line(reader, &mut self.text) {
                Ok(Line::End) => {
                    self.last = true;
                    return;
                }
                Ok(kind) => {
                    let binary = matches!(kind, Line::Nul(_));
                    self.lines.push((start..self.text.len(), kind));
                    if binary {
                        self.last = true;
                        return;
                    }
                }
                Err(e) => {
                    self.error = Some(e);
                    self.last = true;
                    return;
                }
            }
        }
    }

    /// The text of line `k` of the batch.
    pub(crate) fn line(&self, k: usize) -> &[u8] {
        &self.text[self.lines[k].0.clone()]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn batches_split_at_line_ends_and_stop_at_binary_data() {
        let mut text = Vec::new();
        for i in 0..3000 {
            text.extend_from_slice(format!("line {i} {}\n", "x".repeat(900)).as_bytes());
        }
        text.extend_from_slice(b"last without end");
        let mut reader = io::BufReader::with_capacity(4096, &text[..]);
        let mut batch = LineBatch::new();
        let mut lines: Vec<Vec<u8>> = Vec::new();
        let mut batches = 0;
        while !batch.last {
            batch.fill(&mut reader);
            batches += 1;
            assert!(batch.text.len() < BATCH_BYTES + 1000);
            for k in 0..batch.lines.len() {
                assert_eq!(batch.lines[k].1, Line::Text);
                lines.push(batch.line(k).to_vec());
            }
        }
        assert!(batches >= 3, "{batches} batches");
        assert_eq!(lines.concat(), text);
        assert_eq!(lines.len(), 3001);

        let mut reader = &b"a\nb\0c\nnot read\n"[..];
        let mut batch = LineBatch::new();
        batch.fill(&mut reader);
        assert!(batch.last);
        assert_eq!(batch.lines.len(), 2);
        assert_eq!(batch.lines[1].1, Line::Nul(1));
    }
}
