//! The range readings of a batch of lines, parsed ahead on every thread of the current
//! rayon pool: most of a log's bytes are readings, and parsing them is most of the
//! reader's time. The lines are then handled one by one, in order, as before; a scan
//! line takes its readings from here instead of parsing them again.
//!
//! Nothing is decided here. Every line is still read whole by the in-order pass: a
//! line whose readings did not all parse here (or whose fields before them did not
//! tokenize) gets none, and the in-order pass parses it itself, so what is accepted,
//! the values and any error with its line and wording are the same as without it.

use crate::line_batch::LineBatch;
use crate::line_reader::Line;
use crate::tokens::{Fields, Tokens};
use rayon::prelude::*;
use std::ops::Range;

/// Tokens between the message name and `num_readings` in RAWLASER1 and ROBOTLASER1
/// lines (laser_type, start_angle, field_of_view, angular_resolution, maximum_range,
/// accuracy, remission_mode); FLASER lines have none.
const LASER_HEADER_TOKENS: usize = 7;

/// Pieces of a batch per thread: the thread that handles the lines in order takes
/// the pieces left when it is done, so the pieces must be small enough to share.
const PIECES_PER_THREAD: usize = 4;

/// One line's readings parsed ahead.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Ready<'a> {
    /// Byte offset in the line where the first reading's token search starts (just
    /// after `num_readings`).
    pub(crate) start: usize,
    /// Byte offset just after the last reading.
    pub(crate) end: usize,
    /// The readings, `num_readings` of them.
    pub(crate) values: &'a [f32],
}

/// Where a line's readings are: the byte offsets of [`Ready`] and the values' span.
#[derive(Debug, Clone)]
struct Span {
    start: usize,
    end: usize,
    values: Range<usize>,
}

/// The readings of a batch's scan lines, parsed ahead.
#[derive(Debug, Default)]
pub(crate) struct Prescan {
    values: Vec<f32>,
    /// One entry per line of the batch (none when the batch was not prescanned).
    lines: Vec<Option<Span>>,
}

impl Prescan {
    /// The readings of line `k` of the batch, when they were parsed ahead.
    pub(crate) fn get(&self, k: usize) -> Option<Ready<'_>> {
        let s = self.lines.get(k)?.as_ref()?;
        Some(Ready {
            start: s.start,
            end: s.end,
            values: &self.values[s.values.clone()],
        })
    }
}

/// Parses ahead the readings of the batch's scan lines, on the current rayon pool's
/// threads; nothing (every line parsed in order, as before) on a pool of one thread.
pub(crate) fn prescan(batch: &LineBatch) -> Prescan {
    let threads = rayon::current_num_threads();
    if threads < 2 || batch.lines.len() < 2 {
        return Prescan::default();
    }
    // Pieces of about equal bytes, a few per thread.
    let share = batch.text.len() / (PIECES_PER_THREAD * threads) + 1;
    let mut cuts = vec![0];
    for (k, (bytes, _)) in batch.lines.iter().enumerate() {
        if bytes.start >= share * cuts.len() {
            cuts.push(k);
        }
    }
    cuts.push(batch.lines.len());
    let pieces: Vec<Prescan> = cuts
        .par_windows(2)
        .map(|w| {
            let mut piece = Prescan::default();
            for k in w[0]..w[1] {
                let span = match batch.lines[k].1 {
                    Line::Text => readings(batch.line(k), &mut piece.values),
                    _ => None,
                };
                piece.lines.push(span);
            }
            piece
        })
        .collect();
    let mut all = Prescan {
        values: Vec::with_capacity(pieces.iter().map(|p| p.values.len()).sum()),
        lines: Vec::with_capacity(batch.lines.len()),
    };
    for piece in pieces {
        let offset = all.values.len();
        all.values.extend_from_slice(&piece.values);
        all.lines.extend(piece.lines.into_iter().map(|s| {
            s.map(|s| Span {
                values: s.values.start + offset..s.values.end + offset,
                ..s
            })
        }));
    }
    all
}

/// The readings of one RAWLASER1, ROBOTLASER1 or FLASER line, appended to `out`;
/// `None` (and `out` unchanged) for other lines and for lines whose readings, or
/// the tokens before them, do not parse.
fn readings(text: &[u8], out: &mut Vec<f32>) -> Option<Span> {
    let mut tokens = Tokens::new(text);
    let header = match tokens.next()? {
        b"RAWLASER1" | b"ROBOTLASER1" => LASER_HEADER_TOKENS,
        b"FLASER" => 0,
        _ => return None,
    };
    for _ in 0..header {
        tokens.next()?;
    }
    let mut f = Fields { tokens };
    let n = f.count("num_readings").ok()?;
    let start = f.tokens.position();
    let first = out.len();
    for _ in 0..n {
        match f.f32("range reading") {
            Ok(r) => out.push(r),
            Err(_) => {
                out.truncate(first);
                return None;
            }
        }
    }
    Some(Span {
        start,
        end: f.tokens.position(),
        values: first..out.len(),
    })
}
