//! Fuzzing the log reader (and the pipeline behind it) with proptest: garbage bytes,
//! garbled lines among valid ones (and the data faults of issue 14: duplicated lines,
//! colliding timestamps, clock jumps, encoder spikes up to `i64::MAX`, frozen scans,
//! wrapping counters without the modulus, NUL and terminal-escape bytes), and mutated
//! JSON logs. Every input must give
//! `Ok` or an error — never a panic — in strict and in lenient mode; whatever reads
//! is then pushed through the whole pipeline, which must also answer without panic.
//! The hostile data of issue 22 (timestamps in ms/µs/ns or up to 1e300, counts scaled
//! by up to 1e12 or offset beyond 2^53) are among the edits, and properties check that
//! implausible timestamps and counts are refused by name.
//!
//! `cargo test` runs 300 cases per property (a few seconds); a longer run:
//! `ODOCAL_FUZZ_CASES=20000 cargo test --release --test fuzz_log_reader`.

mod common;

use odocal_log::{read_log, Mode, ReadOptions};
use odocal_pipeline::{calibrate_log, NoProgress, Options, PipelineError};
use proptest::prelude::*;
use std::path::PathBuf;
use std::sync::atomic::{AtomicUsize, Ordering};

static COUNTER: AtomicUsize = AtomicUsize::new(0);

/// Cases per property: `ODOCAL_FUZZ_CASES`, else 300.
fn cases() -> u32 {
    std::env::var("ODOCAL_FUZZ_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(300)
}

fn scratch_file(bytes: &[u8]) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("odocal-fuzz-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(format!("{}.log", COUNTER.fetch_add(1, Ordering::Relaxed)));
    std::fs::write(&path, bytes).unwrap();
    path
}

/// Messages never carry raw control bytes (terminal escapes, NUL, …) from the input.
fn assert_printable(message: &str) {
    assert!(
        !message.chars().any(|c| c.is_control()),
        "raw control bytes in {message:?}"
    );
}

/// Reads `bytes` as a log in both modes and, when it reads, calibrates it.
fn exercise(bytes: &[u8]) {
    let path = scratch_file(bytes);
    for mode in [Mode::Strict, Mode::Lenient] {
        let opts = ReadOptions {
            mode,
            ..ReadOptions::default()
        };
        match read_log(&path, &opts) {
            Ok(log) => {
                let calib = Options {
                    ticks_per_revolution: Some(1000.0),
                    ..Options::default()
                };
                // Ok or a clear error; the point is that nothing panics.
                match calibrate_log(&log, &calib, &NoProgress) {
                    Ok(o) => {
                        for f in &o.health {
                            assert_printable(&f.message);
                        }
                    }
                    Err(e) => assert_printable(&e.to_string()),
                }
            }
            Err(e) => assert_printable(&e.to_string()),
        }
    }
    let _ = std::fs::remove_file(&path);
}

/// A small valid Carmen log: PARAMs, encoders at 50 Hz, scans of 11 rays at 10 Hz.
fn valid_lines() -> Vec<String> {
    let mut lines = vec![
        "# CARMEN Logfile".to_string(),
        "PARAM robot_wheel_ticks_per_revolution 2764.8 host 0.0".to_string(),
        "PARAM robot_encoder_modulus 65536 host 0.0".to_string(),
    ];
    for k in 0..60 {
        let t = 100.0 + k as f64 * 0.02;
        lines.push(format!("ENCODER {} {} {t:.6} host {t:.6}", 3 * k, 5 * k));
        if k % 5 == 0 {
            let ranges: Vec<String> = (0..11)
                .map(|i| format!("{:.3}", 1.0 + 0.1 * i as f64 + 0.002 * k as f64))
                .collect();
            lines.push(format!(
                "RAWLASER1 2 -1.5 3.0 0.3 4.0 0.01 0 11 {} 0 {t:.6} host {t:.6}",
                ranges.join(" ")
            ));
        }
        if k % 7 == 0 {
            lines.push(format!("ODOM 0.1 0.2 0.3 0.0 0.0 0.0 {t:.6} host {t:.6}"));
        }
    }
    lines.push("FLASER 3 1.0 1.1 1.2 0 0 0 0 0 0 101.5 host 101.5".into());
    lines.push("SYNC 1 2 3".into());
    lines
}

/// Tokens that stress number parsing and counts.
fn nasty_token() -> impl Strategy<Value = String> {
    prop_oneof![
        Just("NaN".to_string()),
        Just("inf".to_string()),
        Just("-inf".to_string()),
        Just("1e400".to_string()),
        Just("-0".to_string()),
        Just("99999999999999999999999".to_string()),
        Just("4294967296".to_string()),
        Just("".to_string()),
        Just("{".to_string()),
        Just("\u{00e9}\u{2603}".to_string()),
        any::<i64>().prop_map(|v| v.to_string()),
        any::<f64>().prop_map(|v| v.to_string()),
        "[ -~]{0,12}",
    ]
}

#[derive(Debug, Clone)]
enum Edit {
    ReplaceToken(usize, usize, String),
    DeleteToken(usize, usize),
    InsertLine(usize, String),
    DeleteLine(usize),
    SwapLines(usize, usize),
    Truncate(usize, usize),
    // The data faults of issue 14.
    DuplicateLine(usize),
    SameTimestampAsPrevious(usize),
    ClockJump(usize, f64),
    EncoderSpike(usize, i64),
    FrozenScan(usize),
    WrapCounters(u32),
    InsertBytes(usize, Vec<u8>),
    // The hostile data of issue 22.
    ScaleTimestamps(f64),
    ScaleCounts(i64),
    OffsetCounts(i64),
}

fn edit() -> impl Strategy<Value = Edit> {
    prop_oneof![
        (any::<usize>(), any::<usize>(), nasty_token())
            .prop_map(|(l, t, s)| Edit::ReplaceToken(l, t, s)),
        (any::<usize>(), any::<usize>()).prop_map(|(l, t)| Edit::DeleteToken(l, t)),
        (any::<usize>(), "[ -~\t]{0,80}").prop_map(|(l, s)| Edit::InsertLine(l, s)),
        any::<usize>().prop_map(Edit::DeleteLine),
        (any::<usize>(), any::<usize>()).prop_map(|(a, b)| Edit::SwapLines(a, b)),
        (any::<usize>(), any::<usize>()).prop_map(|(l, c)| Edit::Truncate(l, c)),
        any::<usize>().prop_map(Edit::DuplicateLine),
        any::<usize>().prop_map(Edit::SameTimestampAsPrevious),
        (any::<usize>(), -20.0f64..20.0).prop_map(|(l, d)| Edit::ClockJump(l, d)),
        (
            any::<usize>(),
            prop_oneof![
                Just(i64::MAX),
                Just(i64::MIN),
                Just(1_000_000_000_000i64),
                any::<i64>()
            ]
        )
            .prop_map(|(l, v)| Edit::EncoderSpike(l, v)),
        any::<usize>().prop_map(Edit::FrozenScan),
        (8u32..20).prop_map(Edit::WrapCounters),
        (
            any::<usize>(),
            prop::collection::vec(
                prop_oneof![Just(0u8), Just(0x1b), Just(0x9b), Just(0x07), any::<u8>()],
                1..8
            )
        )
            .prop_map(|(l, b)| Edit::InsertBytes(l, b)),
        time_scale().prop_map(Edit::ScaleTimestamps),
        prop_oneof![Just(1_000i64), Just(1_000_000), Just(1_000_000_000_000)]
            .prop_map(Edit::ScaleCounts),
        prop_oneof![
            Just(1i64 << 53),
            Just(1i64 << 56),
            Just(1i64 << 62),
            Just(-(1i64 << 62))
        ]
        .prop_map(Edit::OffsetCounts),
    ]
}

/// Factors that turn seconds into another unit (or into nonsense).
fn time_scale() -> impl Strategy<Value = f64> {
    prop_oneof![Just(1e3), Just(1e6), Just(1e9), Just(1e290), 1e3f64..1e12]
}

/// Applies `f` to both timestamps of every message line.
fn map_timestamps(lines: &mut [String], f: impl Fn(f64) -> f64) {
    for line in lines.iter_mut() {
        with_tokens(line, |toks| {
            if let Some(i) = timestamp_index(toks) {
                for k in [i, i + 2] {
                    if let Some(t) = toks.get(k).and_then(|t| t.parse::<f64>().ok()) {
                        toks[k] = format!("{:e}", f(t));
                    }
                }
            }
        });
    }
}

/// Applies `f` to both counts of every ENCODER line.
fn map_counts(lines: &mut [String], f: impl Fn(i64) -> i64) {
    for line in lines.iter_mut().filter(|x| x.starts_with("ENCODER")) {
        with_tokens(line, |toks| {
            for k in [1, 2] {
                if let Some(v) = toks.get(k).and_then(|t| t.parse::<i64>().ok()) {
                    toks[k] = f(v).to_string();
                }
            }
        });
    }
}

/// The timestamp token (third from the end) of a message line, when it has one.
fn timestamp_index(toks: &[String]) -> Option<usize> {
    (toks.len() >= 4 && toks[0] != "PARAM" && !toks[0].starts_with('#')).then(|| toks.len() - 3)
}

/// Applies `f` to the tokens of line `l`.
fn with_tokens(line: &mut String, f: impl FnOnce(&mut Vec<String>)) {
    let mut toks: Vec<String> = line.split_whitespace().map(String::from).collect();
    f(&mut toks);
    *line = toks.join(" ");
}

fn edit_tokens(line: &mut String, t: usize, replacement: Option<&str>) {
    let mut toks: Vec<String> = line.split_whitespace().map(String::from).collect();
    if toks.is_empty() {
        return;
    }
    let k = t % toks.len();
    match replacement {
        Some(r) => toks[k] = r.to_string(),
        None => {
            toks.remove(k);
        }
    }
    *line = toks.join(" ");
}

fn apply(lines: &mut Vec<String>, e: &Edit) {
    if lines.is_empty() {
        return;
    }
    let n = lines.len();
    match e {
        Edit::ReplaceToken(l, t, s) => edit_tokens(&mut lines[l % n], *t, Some(s)),
        Edit::DeleteToken(l, t) => edit_tokens(&mut lines[l % n], *t, None),
        Edit::InsertLine(l, s) => lines.insert(l % (n + 1), s.clone()),
        Edit::DeleteLine(l) => {
            lines.remove(l % n);
        }
        Edit::SwapLines(a, b) => lines.swap(a % n, b % n),
        Edit::Truncate(l, c) => {
            let line = &mut lines[l % n];
            let mut cut = c % (line.len() + 1);
            while !line.is_char_boundary(cut) {
                cut -= 1;
            }
            line.truncate(cut);
        }
        Edit::DuplicateLine(l) => {
            let copy = lines[l % n].clone();
            lines.insert(l % n, copy);
        }
        Edit::SameTimestampAsPrevious(l) => {
            let k = l % n;
            let prev = (0..k).rev().find_map(|j| {
                let t: Vec<String> = lines[j].split_whitespace().map(String::from).collect();
                timestamp_index(&t).map(|i| t[i].clone())
            });
            if let Some(t) = prev {
                with_tokens(&mut lines[k], |toks| {
                    if let Some(i) = timestamp_index(toks) {
                        toks[i] = t;
                    }
                });
            }
        }
        Edit::ClockJump(l, d) => {
            for line in lines
                .iter_mut()
                .skip(l % n)
                .filter(|x| x.starts_with("RAWLASER1"))
            {
                with_tokens(line, |toks| {
                    if let Some(i) = timestamp_index(toks) {
                        if let Ok(t) = toks[i].parse::<f64>() {
                            toks[i] = format!("{:.6}", t + d);
                        }
                    }
                });
            }
        }
        Edit::EncoderSpike(l, v) => {
            if let Some(line) = lines
                .iter_mut()
                .skip(l % n)
                .find(|x| x.starts_with("ENCODER"))
            {
                // A line an earlier edit cut to its name keeps no count to replace.
                with_tokens(line, |toks| {
                    if let Some(t) = toks.get_mut(1) {
                        *t = v.to_string();
                    }
                });
            }
        }
        Edit::FrozenScan(l) => {
            let k = l % n;
            if let Some(a) = (k..n).find(|&j| lines[j].starts_with("RAWLASER1")) {
                if let Some(b) = (a + 1..n).find(|&j| lines[j].starts_with("RAWLASER1")) {
                    let t: Vec<String> = lines[b].split_whitespace().map(String::from).collect();
                    let mut frozen: Vec<String> =
                        lines[a].split_whitespace().map(String::from).collect();
                    if let (Some(i), Some(j)) = (timestamp_index(&t), timestamp_index(&frozen)) {
                        frozen[j] = t[i].clone();
                    }
                    lines[b] = frozen.join(" ");
                }
            }
        }
        Edit::WrapCounters(bits) => {
            lines.retain(|x| !x.starts_with("PARAM robot_encoder_modulus"));
            let m = 1i64 << bits;
            for line in lines.iter_mut().filter(|x| x.starts_with("ENCODER")) {
                with_tokens(line, |toks| {
                    for k in [1, 2] {
                        if let Some(v) = toks.get(k).and_then(|t| t.parse::<i64>().ok()) {
                            toks[k] = v.rem_euclid(m).to_string();
                        }
                    }
                });
            }
        }
        Edit::InsertBytes(l, bytes) => {
            let line = &mut lines[l % n];
            let at = line.len() / 2;
            let mut cut = at;
            while !line.is_char_boundary(cut) {
                cut -= 1;
            }
            line.insert_str(cut, &String::from_utf8_lossy(bytes));
        }
        Edit::ScaleTimestamps(f) => map_timestamps(lines, |t| t * f),
        Edit::ScaleCounts(f) => map_counts(lines, |v| v.saturating_mul(*f)),
        Edit::OffsetCounts(d) => map_counts(lines, |v| v.saturating_add(*d)),
    }
}

/// Reads the valid log after `edit_lines` (written as `name` in the scratch folder)
/// and calibrates it.
fn calibrate_lines(
    name: &str,
    edit_lines: impl FnOnce(&mut Vec<String>),
) -> Result<(), PipelineError> {
    let mut lines = valid_lines();
    lines.retain(|l| !l.starts_with("FLASER"));
    edit_lines(&mut lines);
    let path = scratch_file(lines.join("\n").as_bytes()).with_file_name(name);
    std::fs::write(&path, lines.join("\n")).expect("write the log");
    let log = read_log(&path, &ReadOptions::default()).expect("the edited log reads");
    let _ = std::fs::remove_file(&path);
    calibrate_log(&log, &Options::default(), &NoProgress).map(|_| ())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: cases(), ..ProptestConfig::default() })]

    #[test]
    fn garbage_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..3000)) {
        exercise(&bytes);
    }

    #[test]
    fn garbled_carmen_lines_never_panic(edits in proptest::collection::vec(edit(), 0..12)) {
        let mut lines = valid_lines();
        for e in &edits {
            apply(&mut lines, e);
        }
        exercise(lines.join("\n").as_bytes());
    }

    #[test]
    fn garbled_json_logs_never_panic(
        edits in proptest::collection::vec((any::<usize>(), "[ -~]{0,6}"), 0..6),
        n in 0usize..12,
    ) {
        let mut text = String::new();
        for k in 0..n {
            text += &format!(
                "{{\"timestamp\": [100, {}], \"readings\": [1.0, 1.1, 1.2], \"theta\": [-0.1, 0.0, 0.1], \
                 \"left\": {}, \"right\": {}, \"leftTimestamp\": [100, {}], \"rightTimestamp\": [100, {}]}}\n",
                k * 100_000, 3 * k, 4 * k, k * 100_000, k * 100_000
            );
        }
        let mut bytes = text.into_bytes();
        for (pos, ins) in &edits {
            let p = if bytes.is_empty() { 0 } else { pos % bytes.len() };
            bytes.splice(p..p, ins.bytes());
        }
        exercise(&bytes);
    }

    #[test]
    fn timestamps_in_another_unit_are_refused_by_name(scale in time_scale()) {
        let err = calibrate_lines("units.log", |l| map_timestamps(l, |t| t * scale)).unwrap_err();
        prop_assert!(matches!(err, PipelineError::Implausible(_)), "{}", err);
        prop_assert!(err.to_string().contains("write the timestamps in seconds"), "{}", err);
    }

    #[test]
    fn counts_no_wheel_can_make_are_refused_by_name(factor in 1_000_000i64..1_000_000_000_000) {
        let err = calibrate_lines("scaled.log", |l| map_counts(l, |v| v * factor)).unwrap_err();
        prop_assert!(matches!(err, PipelineError::Implausible(_)), "{}", err);
        prop_assert!(err.to_string().contains("revolutions per second"), "{}", err);
    }

    #[test]
    fn json_timestamps_in_another_unit_are_refused(step in prop_oneof![Just(1_000u64), Just(1_000_000), Just(1_000_000_000)]) {
        let mut text = String::new();
        for k in 0..20u64 {
            text += &format!(
                "{{\"timestamp\": [{s}, 0], \"readings\": [1.0, 1.1, {r}], \"theta\": [-0.1, 0.0, 0.1], \
                 \"left\": {}, \"right\": {}, \"leftTimestamp\": [{s}, 0], \"rightTimestamp\": [{s}, 0]}}\n",
                3 * k, 4 * k, s = 100 + k * step, r = 1.2 + 0.01 * k as f64
            );
        }
        let path = scratch_file(text.as_bytes());
        let log = read_log(&path, &ReadOptions::default()).expect("the JSON log reads");
        let _ = std::fs::remove_file(&path);
        let opts = Options { ticks_per_revolution: Some(1000.0), ..Options::default() };
        let err = calibrate_log(&log, &opts, &NoProgress).map(|_| ()).unwrap_err();
        prop_assert!(matches!(err, PipelineError::Implausible(_)), "{}", err);
    }
}

#[test]
fn the_unedited_fixture_reads() {
    // The generator above makes a readable log: the fuzzing starts from valid input.
    let text = valid_lines().join("\n");
    let path = scratch_file(text.as_bytes());
    let log = read_log(&path, &ReadOptions::default()).expect("valid fixture");
    assert_eq!(log.encoders.len(), 60);
    assert_eq!(log.scans.len(), 13);
    let _ = std::fs::remove_file(&path);
}
