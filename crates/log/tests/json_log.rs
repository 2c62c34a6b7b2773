//! The original package's JSON logs, and format detection by `read_log`.

use odocal_log::{read_json_log_from, read_log, LogError, ReadOptions, ScanKind};
use std::path::PathBuf;

fn object(sec: u64, usec: u64, left: i64, right: i64) -> String {
    format!(
        "{{\"timestamp\": [{sec}, {usec}], \"readings\": [1.5, 0.0, null, 2.25], \
         \"theta\": [-0.3, -0.1, 0.1, 0.3], \"left\": {left}, \"right\": {right}, \
         \"leftTimestamp\": [{sec}, {usec}], \"rightTimestamp\": [{sec}, {}]}}",
        usec + 2
    )
}

#[test]
fn objects_sharing_a_line_are_all_read() {
    let text = format!(
        "{}\n{} {}\n{}{}\n",
        object(100, 0, 1, 2),
        object(100, 100000, 3, 4),
        object(100, 200000, 5, 6),
        object(100, 300000, 7, 8),
        object(100, 400000, 9, 10)
    );
    let log = read_json_log_from(text.as_bytes(), "j", &ReadOptions::default()).unwrap();
    assert_eq!(log.scans.len(), 5);
    assert_eq!(log.encoders.len(), 5);
    assert_eq!(log.scans.geometries.len(), 1);
    let s = log.scans.get(2).unwrap();
    assert_eq!(s.kind, ScanKind::Json);
    assert_eq!(s.t, 100.0 + 200000.0 * 1e-6);
    assert_eq!(s.geometry.angles[..], [-0.3, -0.1, 0.1, 0.3]);
    assert_eq!(s.ranges[0], 1.5);
    assert!(s.ranges[2].is_nan());
    // Encoder time is the mean of the left and right timestamps.
    assert_eq!(
        log.encoders[1].t,
        0.5 * ((100.0 + 0.1) + (100.0 + 100002.0 * 1e-6))
    );
    assert_eq!((log.encoders[4].left, log.encoders[4].right), (9, 10));
    assert_eq!(
        log.encoders.iter().map(|e| e.line).collect::<Vec<_>>(),
        vec![1, 2, 2, 3, 3]
    );
    // 0.0 and null are invalid in every scan.
    assert_eq!(log.stats.invalid_readings, 10);
    assert_eq!(log.stats.messages["JSON objects"], 5);
}

#[test]
fn json_errors_name_the_line() {
    let text = format!(
        "{}\n{}\n{{\"timestamp\": [1, 2], \"readings\": [1.0], \"theta\": [0.1, 0.2]}}\n",
        object(1, 0, 0, 0),
        object(2, 0, 0, 0)
    );
    let e = read_json_log_from(text.as_bytes(), "bad.json", &ReadOptions::default()).unwrap_err();
    assert_eq!(e.line(), Some(3), "{e}");
    assert!(
        e.to_string()
            .starts_with("bad.json:3: JSON: expected as many \"theta\""),
        "{e}"
    );
    let log = read_json_log_from(text.as_bytes(), "bad.json", &ReadOptions::lenient()).unwrap();
    assert_eq!(log.scans.len(), 2);
    assert_eq!(log.stats.skipped_lines, 1);

    let syntax = format!(
        "{}\n{{\"timestamp\": [1, 2], \"readings\": [1.0,, 2]}}\n",
        object(1, 0, 0, 0)
    );
    let e = read_json_log_from(syntax.as_bytes(), "s.json", &ReadOptions::lenient()).unwrap_err();
    assert!(matches!(e, LogError::Parse { line: 2, .. }), "{e}");
}

/// A file in the temporary directory, removed when dropped.
struct TempFile(PathBuf);

impl TempFile {
    fn new(name: &str, contents: &str) -> TempFile {
        let path = std::env::temp_dir().join(format!("odocal-log-{}-{name}", std::process::id()));
        std::fs::write(&path, contents).unwrap();
        TempFile(path)
    }
}

impl Drop for TempFile {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.0);
    }
}

#[test]
fn read_log_detects_the_format() {
    let json = TempFile::new("a.json", &format!("\n\n  {}\n", object(5, 0, 1, 1)));
    let log = read_log(&json.0, &ReadOptions::default()).unwrap();
    assert_eq!((log.scans.len(), log.encoders.len()), (1, 1));
    assert_eq!(log.encoders[0].line, 3);
    assert_eq!(log.stats.source, json.0.display().to_string());

    let carmen = TempFile::new("b.log", "\n# c\nENCODER 1 2 3.0 h 3.0\n");
    let log = read_log(&carmen.0, &ReadOptions::default()).unwrap();
    assert_eq!(log.encoders[0].line, 3);

    let missing = std::env::temp_dir().join("odocal-log-does-not-exist.log");
    let e = read_log(&missing, &ReadOptions::default()).unwrap_err();
    assert!(matches!(e, LogError::Io { .. }));
    assert!(
        e.to_string().starts_with(&missing.display().to_string()),
        "{e}"
    );
}
