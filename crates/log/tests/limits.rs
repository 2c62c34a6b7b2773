//! Inputs that are not logs fail fast with bounded memory, and text from the file is
//! never echoed raw: `/dev/zero`, NUL bytes, over-long lines, absurd counts, terminal
//! escape bytes.

use odocal_log::{read_carmen_from, read_log, LogError, ReadOptions, MAX_COUNT, MAX_LINE_BYTES};
use std::path::Path;

#[test]
fn dev_zero_is_not_a_text_log() {
    let zero = Path::new("/dev/zero");
    if !zero.exists() {
        println!("skipped: no /dev/zero");
        return;
    }
    for opts in [ReadOptions::default(), ReadOptions::lenient()] {
        let e = read_log(zero, &opts).unwrap_err();
        assert!(matches!(e, LogError::NotText { line: 1, .. }), "{e}");
        assert!(e.to_string().contains("not a text log"), "{e}");
    }
}

#[test]
fn a_nul_byte_after_valid_lines_is_refused_at_its_line() {
    let mut text = b"ENCODER 1 2 3.0 h 3.0\nENCODER 1 2 3.1 h 3.1\n".to_vec();
    text.extend_from_slice(&[0u8; 5000]);
    let e = read_carmen_from(&text[..], "z.log", &ReadOptions::lenient()).unwrap_err();
    assert_eq!(e.to_string(), "z.log:3: not a text log: a NUL byte at column 1 (binary data; expected Carmen-style text or a JSON log)");
}

#[test]
fn an_over_long_line_is_an_error_or_skipped() {
    let mut text = b"ENCODER 1 2 3.0 h 3.0\nRAWLASER1 ".to_vec();
    text.extend(std::iter::repeat_n(b'7', MAX_LINE_BYTES + 100));
    text.extend_from_slice(b"\nENCODER 1 2 3.1 h 3.1\n");
    let e = read_carmen_from(&text[..], "long.log", &ReadOptions::default()).unwrap_err();
    assert_eq!(e.line(), Some(2));
    assert!(e.to_string().contains("at most 1048576 bytes"), "{e}");
    let log = read_carmen_from(&text[..], "long.log", &ReadOptions::lenient()).unwrap();
    assert_eq!(log.encoders.len(), 2);
    assert_eq!(log.stats.skipped_lines, 1);
}

#[test]
fn an_absurd_reading_count_is_refused() {
    let text = format!(
        "RAWLASER1 2 -0.5 1 0.5 4 0.01 0 {} 1.0 0 5.0 h 5.0\n",
        MAX_COUNT + 1
    );
    let e = read_carmen_from(text.as_bytes(), "c.log", &ReadOptions::default()).unwrap_err();
    assert!(e.to_string().contains("a count from 0 to 200000"), "{e}");
}

#[test]
fn terminal_escapes_are_shown_escaped() {
    let text = "ENCODER 1 \x1b[2J\x1b]0;pwned\x07 3.0 h 3.0\n\x1b[31mRED 1 2\n";
    let e = read_carmen_from(text.as_bytes(), "esc.log", &ReadOptions::default()).unwrap_err();
    let msg = e.to_string();
    assert!(!msg.contains('\x1b') && !msg.contains('\x07'), "{msg:?}");
    assert!(msg.contains("\\x1b[2J\\x1b]0;pwned\\x07"), "{msg}");
    let log = read_carmen_from(
        "\x1b[31mRED 1 2\n".as_bytes(),
        "esc.log",
        &ReadOptions::default(),
    )
    .unwrap();
    assert_eq!(log.stats.unknown.keys().next().unwrap(), "\\x1b[31mRED");
}
