//! Text from a file made safe to print: control characters (terminal escapes, NUL, …)
//! and bidirectional-text overrides (which reorder what a reader sees) are shown
//! escaped. [`printable`] escapes one value and cuts it; [`terminal_text`] escapes a
//! whole message (keeping its line breaks and tabs) and [`json_text`] a JSON document
//! (as JSON `\u` escapes), just before it reaches the terminal.

use std::borrow::Cow;

/// True for a character that must not reach a terminal raw: a control character
/// (C0, DEL, C1: `\x1b`, `\u{9b}`, …) or a bidirectional-text control (U+061C,
/// U+200E/F, U+202A–U+202E, U+2066–U+2069).
pub fn needs_escape(c: char) -> bool {
    c.is_control()
        || matches!(c, '\u{61c}' | '\u{200e}' | '\u{200f}' | '\u{202a}'..='\u{202e}' | '\u{2066}'..='\u{2069}')
}

/// `c` written as `\x1b` (below U+0100) or `\u{202e}`.
fn push_escaped(out: &mut String, c: char) {
    let code = c as u32;
    if code < 0x100 {
        out.push_str(&format!("\\x{code:02x}"));
    } else {
        out.push_str(&format!("\\u{{{code:x}}}"));
    }
}

/// `bytes` as text with every character of [`needs_escape`] escaped (`\x1b`,
/// `\u{202e}`) and invalid UTF-8 replaced, cut after `max_chars` characters (with `…`).
pub fn printable(bytes: &[u8], max_chars: usize) -> String {
    let text = String::from_utf8_lossy(bytes);
    let mut out = String::with_capacity(bytes.len().min(4 * max_chars));
    for (k, c) in text.chars().enumerate() {
        if k == max_chars {
            out.push('…');
            break;
        }
        if needs_escape(c) {
            push_escaped(&mut out, c);
        } else {
            out.push(c);
        }
    }
    out
}

/// `text` with every character of [`needs_escape`] but line feed and tab escaped as
/// [`printable`] does: a message (several lines) safe to print.
pub fn terminal_text(text: &str) -> Cow<'_, str> {
    let keep = |c: char| c == '\n' || c == '\t' || !needs_escape(c);
    if text.chars().all(keep) {
        return Cow::Borrowed(text);
    }
    let mut out = String::with_capacity(text.len() + 16);
    for c in text.chars() {
        if keep(c) {
            out.push(c);
        } else {
            push_escaped(&mut out, c);
        }
    }
    Cow::Owned(out)
}

/// A JSON document with every character of [`needs_escape`] but line feed written as
/// a JSON escape (`\u009b`, `\u202e`): the same document to a JSON reader (such
/// characters can only be inside strings, which serde already escapes for C0), safe
/// on a terminal.
pub fn json_text(json: &str) -> Cow<'_, str> {
    let keep = |c: char| c == '\n' || !needs_escape(c);
    if json.chars().all(keep) {
        return Cow::Borrowed(json);
    }
    let mut out = String::with_capacity(json.len() + 16);
    for c in json.chars() {
        if keep(c) {
            out.push(c);
        } else {
            let mut units = [0u16; 2];
            for u in c.encode_utf16(&mut units) {
                out.push_str(&format!("\\u{u:04x}"));
            }
        }
    }
    Cow::Owned(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn escapes_controls_and_cuts() {
        assert_eq!(printable(b"ab\x1b[2Jc", 40), "ab\\x1b[2Jc");
        assert_eq!(printable(b"\0\x7f", 40), "\\x00\\x7f");
        assert_eq!(printable("\u{9b}é".as_bytes(), 40), "\\x9bé");
        assert_eq!(printable(b"abcdef", 3), "abc…");
        assert_eq!(printable(b"\xff", 3), "\u{fffd}");
        assert_eq!(printable("a\u{202e}b".as_bytes(), 9), "a\\u{202e}b");
    }

    #[test]
    fn messages_keep_their_lines() {
        assert_eq!(terminal_text("a\tb\nc"), "a\tb\nc");
        assert_eq!(
            terminal_text("topic /x\x1b]0;pwned\x07\r\u{2067}\n"),
            "topic /x\\x1b]0;pwned\\x07\\x0d\\u{2067}\n"
        );
    }

    #[test]
    fn json_stays_the_same_document() {
        let value = serde_json::json!({"t": "a\u{1b}[31m\u{9b}\u{202e}z", "n": [1, 2]});
        let raw = serde_json::to_string_pretty(&value).unwrap();
        let safe = json_text(&raw);
        assert!(
            !safe.chars().any(|c| c != '\n' && needs_escape(c)),
            "{safe}"
        );
        assert_eq!(
            serde_json::from_str::<serde_json::Value>(&safe).unwrap(),
            value
        );
    }
}
