//! Text from a file made safe to print: control bytes (terminal escapes, NUL, …) are
//! shown escaped, and long text is cut.

/// `bytes` as text with every control character escaped (`\x1b`, `\u{9b}`) and invalid
/// UTF-8 replaced, cut after `max_chars` characters (with `…`).
pub fn printable(bytes: &[u8], max_chars: usize) -> String {
    let text = String::from_utf8_lossy(bytes);
    let mut out = String::with_capacity(bytes.len().min(4 * max_chars));
    for (k, c) in text.chars().enumerate() {
        if k == max_chars {
            out.push('…');
            break;
        }
        if c.is_control() {
            let code = c as u32;
            if code < 0x100 {
                out.push_str(&format!("\\x{code:02x}"));
            } else {
                out.push_str(&format!("\\u{{{code:x}}}"));
            }
        } else {
            out.push(c);
        }
    }
    out
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
    }
}
