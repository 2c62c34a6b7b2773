//! Splitting a log line into tokens and reading typed fields from them, without
//! allocating unless there is an error to report.

use crate::number::{f32_of_token, parse_f64, parse_i64, DecimalSplit};

/// The largest count of readings (or remissions) one line may announce.
pub const MAX_COUNT: usize = 200_000;

/// True for the bytes that separate tokens: space, tab, the line end, form feeds.
#[inline]
fn is_separator(b: u8) -> bool {
    matches!(b, b' ' | b'\t' | b'\n' | b'\r' | 0x0b | 0x0c)
}

/// The common token of [`Tokens::next_decimal`] in one tight pass: from `body` (after
/// any sign), `digits[.digits]` with 1 to 19 digits in all, ending at a separator or
/// the line's end. Returns the token's end, its mantissa and its digits after the point
/// — what the general loop finds for such a token; `None` for any other token, which
/// the general loop reads instead.
#[inline]
fn plain_body(s: &[u8], body: usize) -> Option<(usize, u64, usize)> {
    let mut i = body;
    let mut m = 0u64;
    let mut digits = digit_run(s, &mut i, &mut m);
    let mut after_point = 0;
    if s.get(i) == Some(&b'.') {
        i += 1;
        after_point = digit_run(s, &mut i, &mut m);
        digits += after_point;
    }
    let ends = s.get(i).is_none_or(|&c| is_separator(c));
    (ends && (1..=19).contains(&digits)).then_some((i, m, after_point))
}

/// Moves `i` past the decimal digits of `s` from `i`, appending them to `m`; returns
/// how many there were. Wrapping: a token of more than 19 digits is refused by
/// [`plain_body`] whatever `m` became.
#[inline]
fn digit_run(s: &[u8], i: &mut usize, m: &mut u64) -> usize {
    let from = *i;
    while let Some(d) = s.get(*i).map(|c| c.wrapping_sub(b'0')).filter(|&d| d <= 9) {
        *m = m.wrapping_mul(10).wrapping_add(u64::from(d));
        *i += 1;
    }
    *i - from
}

/// The whitespace-separated tokens of one line.
#[derive(Clone)]
pub(crate) struct Tokens<'a> {
    s: &'a [u8],
    i: usize,
}

impl<'a> Tokens<'a> {
    pub(crate) fn new(s: &'a [u8]) -> Self {
        Tokens { s, i: 0 }
    }

    /// The next token and, in the same pass over its bytes, its split as a plain
    /// decimal (what [`crate::number::plain_decimal`] gives for it): range readings, most of a log's
    /// bytes, are read with one pass instead of two.
    #[inline]
    pub(crate) fn next_decimal(&mut self) -> Option<(&'a [u8], Option<DecimalSplit>)> {
        let s = self.s;
        let start = self.skip_separators()?;
        let mut i = start;
        let neg = s[i] == b'-';
        if neg || s[i] == b'+' {
            i += 1;
        }
        let body = i;
        if let Some((end, m, k)) = plain_body(s, body) {
            self.i = end;
            return Some((&s[start..end], Some((neg, m, k))));
        }
        let (mut m, mut digits, mut frac, mut plain) = (0u64, 0usize, None, true);
        while i < s.len() && !is_separator(s[i]) {
            let c = s[i];
            if plain {
                match c {
                    b'0'..=b'9' if digits < 19 => {
                        m = m * 10 + (c - b'0') as u64;
                        digits += 1;
                    }
                    b'.' if frac.is_none() => frac = Some(i - body),
                    _ => plain = false,
                }
            }
            i += 1;
        }
        self.i = i;
        let len = i - body;
        let split = (plain && digits > 0 && len <= 20).then(|| {
            let k = frac.map_or(0, |f| len - f - 1);
            (neg, m, k)
        });
        Some((&s[start..i], split))
    }

    /// Moves past separators to the start of the next token and returns it; `None`
    /// (at the end) when only separators are left.
    #[inline]
    fn skip_separators(&mut self) -> Option<usize> {
        while self.i < self.s.len() && is_separator(self.s[self.i]) {
            self.i += 1;
        }
        (self.i < self.s.len()).then_some(self.i)
    }

    /// The byte offset in the line where the search for the next token starts.
    #[inline]
    pub(crate) fn position(&self) -> usize {
        self.i
    }

    /// Moves the search for the next token to byte offset `i` of the line (a
    /// [`Tokens::position`] of the same line).
    #[inline]
    pub(crate) fn resume_at(&mut self, i: usize) {
        self.i = i.min(self.s.len());
    }

    /// How many tokens are left (used only to explain an error).
    pub(crate) fn count_remaining(&self) -> usize {
        self.clone().count()
    }
}

impl<'a> Iterator for Tokens<'a> {
    type Item = &'a [u8];

    #[inline]
    fn next(&mut self) -> Option<&'a [u8]> {
        let s = self.s;
        let start = self.skip_separators()?;
        let mut i = start;
        while i < s.len() && !is_separator(s[i]) {
            i += 1;
        }
        self.i = i;
        Some(&s[start..i])
    }
}

/// A field that could not be read: what was expected and what was there.
#[derive(Debug)]
pub(crate) struct FieldError {
    pub(crate) expected: String,
    pub(crate) found: Option<String>,
}

impl FieldError {
    pub(crate) fn new(expected: impl Into<String>, found: Option<&[u8]>) -> Self {
        FieldError {
            expected: expected.into(),
            found: found.map(|t| format!("`{}`", crate::printable::printable(t, 40))),
        }
    }

    /// "expected X, found Y".
    pub(crate) fn describe(&self) -> String {
        match &self.found {
            Some(f) => format!("expected {}, found {f}", self.expected),
            None => format!("expected {}, found end of line", self.expected),
        }
    }
}

/// Typed reads from a token stream; each names the field it expects for the error.
pub(crate) struct Fields<'a> {
    pub(crate) tokens: Tokens<'a>,
}

impl<'a> Fields<'a> {
    /// The next token, whatever it is.
    #[inline]
    pub(crate) fn token(&mut self, what: &str) -> Result<&'a [u8], FieldError> {
        self.tokens
            .next()
            .ok_or_else(|| FieldError::new(what, None))
    }

    /// A float (any value, `inf` and `nan` included).
    #[inline]
    pub(crate) fn f64(&mut self, what: &str) -> Result<f64, FieldError> {
        let t = self.tokens.next();
        t.and_then(parse_f64)
            .ok_or_else(|| FieldError::new(format!("{what} (a number)"), t))
    }

    /// A finite float.
    #[inline]
    pub(crate) fn finite_f64(&mut self, what: &str) -> Result<f64, FieldError> {
        let t = self.tokens.next();
        t.and_then(parse_f64)
            .filter(|v| v.is_finite())
            .ok_or_else(|| FieldError::new(format!("{what} (a finite number)"), t))
    }

    /// A float stored as `f32` (a range reading; any value).
    #[inline]
    pub(crate) fn f32(&mut self, what: &str) -> Result<f32, FieldError> {
        match self.tokens.next_decimal() {
            Some((t, split)) => f32_of_token(t, split)
                .ok_or_else(|| FieldError::new(format!("{what} (a number)"), Some(t))),
            None => Err(FieldError::new(format!("{what} (a number)"), None)),
        }
    }

    /// A signed integer; an integral float such as `12.0` is accepted too.
    #[inline]
    pub(crate) fn i64(&mut self, what: &str) -> Result<i64, FieldError> {
        let t = self.tokens.next();
        t.and_then(|t| {
            parse_i64(t).or_else(|| {
                parse_f64(t)
                    .filter(|v| v.fract() == 0.0 && v.abs() < 9.0e15)
                    .map(|v| v as i64)
            })
        })
        .ok_or_else(|| FieldError::new(format!("{what} (an integer)"), t))
    }

    /// A 32-bit signed integer.
    #[inline]
    pub(crate) fn i32(&mut self, what: &str) -> Result<i32, FieldError> {
        let t = self.tokens.clone().next();
        let v = self.i64(what)?;
        i32::try_from(v).map_err(|_| FieldError::new(format!("{what} (a 32-bit integer)"), t))
    }

    /// A count (non-negative integer, at most [`MAX_COUNT`]).
    #[inline]
    pub(crate) fn count(&mut self, what: &str) -> Result<usize, FieldError> {
        let t = self.tokens.clone().next();
        let v = self.i64(what)?;
        usize::try_from(v)
            .ok()
            .filter(|&n| n <= MAX_COUNT)
            .ok_or_else(|| FieldError::new(format!("{what} (a count from 0 to {MAX_COUNT})"), t))
    }

    /// Nothing more on the line.
    #[inline]
    pub(crate) fn end(&mut self, after: &str) -> Result<(), FieldError> {
        match self.tokens.next() {
            None => Ok(()),
            Some(t) => Err(FieldError::new(
                format!("end of line after {after}"),
                Some(t),
            )),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::number::plain_decimal;
    use proptest::prelude::*;

    proptest! {
        #[test]
        fn one_pass_split_is_the_two_pass_one(
            line in "([ \t\r\x0b\x0c]{0,2}[-+]?[0-9.]{0,24}[-+0-9.eEa-z]{0,3}){0,12}[ \n]?"
        ) {
            let bytes = line.as_bytes();
            let mut one = Tokens::new(bytes);
            let two = Tokens::new(bytes);
            for t in two {
                let (u, split) = one.next_decimal().expect("as many tokens");
                prop_assert_eq!(u, t);
                prop_assert_eq!(split, plain_decimal(t), "{:?}", std::str::from_utf8(t));
            }
            prop_assert!(one.next_decimal().is_none());
        }
    }
}
