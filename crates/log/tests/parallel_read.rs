//! The Carmen reader parses scan readings ahead on every thread of the rayon pool it
//! runs in (`range_prescan`). Whatever the thread count, the log read — or the error,
//! with its line and wording — is the same as on one thread, where every line is
//! parsed in order.

use odocal_log::{read_carmen_from, Log, ReadOptions};
use proptest::prelude::*;
use std::path::Path;

/// Reads `text` on a pool of `threads` threads.
fn read_on(threads: usize, text: &[u8], opts: &ReadOptions) -> Result<Log, String> {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("thread pool")
        .install(|| read_carmen_from(text, "t", opts))
        .map_err(|e| e.to_string())
}

/// Strict and lenient reads on 2 and 3 threads equal the one-thread read.
fn assert_same_on_any_threads(text: &[u8]) {
    for opts in [ReadOptions::default(), ReadOptions::lenient()] {
        // Compared as printed: a NaN reading is equal to itself there.
        let one = format!("{:?}", read_on(1, text, &opts));
        for threads in [2, 3] {
            assert!(
                format!("{:?}", read_on(threads, text, &opts)) == one,
                "{threads} threads differ from one ({:?} mode)",
                opts.mode
            );
        }
    }
}

const TEMPLATES: [&str; 6] = [
    "RAWLASER1 2 -0.5 1 0.5 4 0.01 0 3 1.5 2.5 3.5 0 1190000000.5 khepera 0.5",
    "ROBOTLASER1 2 -0.5 1 0.5 4 0.01 1 2 1.5 2.5 1 7 0 0 0 0 0 0 0 0 0 0 0 2.0 h 2.0",
    "FLASER 2 1.5 2.5 0 0 0 0 0 0 3.0 h 3.0",
    "ENCODER -2 1 1190000000.017285 khepera 0.017285",
    "PARAM laser_front_laser_resolution 0.01",
    "RAWLASER1 2 -0.5 1 0.5 4 0.01 0 4 1.5 2.5 3.5 4.5 2 9 9 1190000001.5 khepera 1.5",
];

/// A scan line with some tokens dropped, duplicated or replaced.
fn line_strategy() -> impl Strategy<Value = String> {
    (
        0..TEMPLATES.len(),
        prop::collection::vec(
            (
                0u8..4,
                0usize..30,
                "[-+.0-9a-z]{0,5}|nan|-inf|1e999|200001|99999999999999999999",
            ),
            0..3,
        ),
    )
        .prop_map(|(k, edits)| {
            let mut toks: Vec<String> = TEMPLATES[k].split(' ').map(String::from).collect();
            for (op, at, text) in edits {
                let i = at % (toks.len() + 1);
                match op {
                    0 if i < toks.len() => {
                        toks.remove(i);
                    }
                    1 => toks.insert(i, text),
                    2 if i < toks.len() => toks[i] = text,
                    _ => {}
                }
            }
            toks.join(" ")
        })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    #[test]
    fn garbled_scan_lines_read_the_same_on_any_thread_count(
        lines in prop::collection::vec(line_strategy(), 0..40),
    ) {
        let text: String = lines.iter().map(|l| format!("{l}\n")).collect();
        assert_same_on_any_threads(text.as_bytes());
    }
}

/// The demo log (several batches of lines), as is and with malformed scan lines at a
/// batch's start, middle and end: the same log, or the same first error, on any
/// thread count; in lenient mode the same lines skipped.
#[test]
fn demo_log_and_its_corruptions_read_the_same_on_any_thread_count() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/demo.log");
    let Ok(text) = std::fs::read(&path) else {
        println!("notice: {} is missing; test skipped", path.display());
        return;
    };
    let log = read_on(2, &text, &ReadOptions::default()).expect("the demo log reads");
    assert!(log.scans.len() > 100);
    assert_same_on_any_threads(&text);

    let lines: Vec<&[u8]> = text.split_inclusive(|&b| b == b'\n').collect();
    let scan_lines: Vec<usize> = (0..lines.len())
        .filter(|&k| lines[k].starts_with(b"RAWLASER1"))
        .collect();
    let corrupt = |k: usize, edit: &dyn Fn(&str) -> String| -> Vec<u8> {
        let mut out = Vec::new();
        for (i, l) in lines.iter().enumerate() {
            if i == k {
                out.extend_from_slice(edit(std::str::from_utf8(l).unwrap()).as_bytes());
            } else {
                out.extend_from_slice(l);
            }
        }
        out
    };
    let edits: [&dyn Fn(&str) -> String; 4] = [
        // A reading that is not a number, in the middle of the readings.
        &|l| {
            let mut t: Vec<&str> = l.split(' ').collect();
            t[200] = "1.2.3";
            t.join(" ")
        },
        // One reading missing: the timestamp is read as a reading.
        &|l| {
            let mut t: Vec<&str> = l.split(' ').collect();
            t.remove(100);
            t.join(" ")
        },
        // num_readings one too large.
        &|l| {
            let mut t: Vec<String> = l.split(' ').map(String::from).collect();
            t[8] = (t[8].parse::<usize>().unwrap() + 1).to_string();
            t.join(" ")
        },
        // A non-finite start angle before good readings.
        &|l| l.replacen(' ', " nan ", 2).replacen(" nan ", " ", 1),
    ];
    for &k in [
        scan_lines[0],
        scan_lines[scan_lines.len() / 2],
        scan_lines[scan_lines.len() - 1],
    ]
    .iter()
    {
        for edit in edits {
            let bad = corrupt(k, edit);
            let strict = read_on(1, &bad, &ReadOptions::default());
            let e = strict.expect_err("a malformed scan line is refused");
            assert!(
                e.starts_with(&format!("t:{}:", k + 1)),
                "the error names line {}: {e}",
                k + 1
            );
            assert_same_on_any_threads(&bad);
        }
    }
}
