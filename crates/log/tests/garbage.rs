//! No input makes the reader panic; in lenient mode every line is accounted for.

use odocal_log::{read_carmen_from, read_json_log_from, read_tuples_from, ReadOptions};
use proptest::prelude::*;

const TEMPLATES: [&str; 9] = [
    "PARAM robot_wheel_ticks_per_revolution 2764.8 khepera 0.0",
    "PARAM robot_encoder_modulus 65536",
    "PARAM laser_front_laser_resolution 0.01",
    "ENCODER -2 1 1190000000.017285 khepera 0.017285",
    "RAWLASER1 2 -0.5 1 0.5 4 0.01 0 3 1.5 2.5 3.5 0 1190000000.5 khepera 0.5",
    "ROBOTLASER1 2 -0.5 1 0.5 4 0.01 1 2 1.5 2.5 1 7 0 0 0 0 0 0 0 0 0 0 0 2.0 h 2.0",
    "FLASER 2 1.5 2.5 0 0 0 0 0 0 3.0 h 3.0",
    "ODOM 1 2 3 4 5 6 7.0 h 7.0",
    "# comment",
];

/// A line: a template with some tokens dropped, duplicated or replaced, or random text.
fn line_strategy() -> impl Strategy<Value = String> {
    let mutated = (
        0..TEMPLATES.len(),
        prop::collection::vec(
            (
                0u8..4,
                0usize..40,
                "[-+.0-9a-zA-Z\t ]{0,6}|nan|inf|1e999|99999999999999999999",
            ),
            0..4,
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
        });
    prop_oneof![
        4 => mutated,
        1 => "[ -~\t\r]{0,60}",
        1 => prop::collection::vec(any::<u8>(), 0..40).prop_map(|b| String::from_utf8_lossy(&b).into_owned()),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    #[test]
    fn garbled_logs_never_panic_and_lenient_accounts_for_every_line(lines in prop::collection::vec(line_strategy(), 0..30), crlf in any::<bool>()) {
        let end = if crlf { "\r\n" } else { "\n" };
        let text: String = lines.iter().map(|l| format!("{l}{end}")).collect();
        let n_lines = text.matches('\n').count() as u64;
        if let Some(nul) = text.find('\0') {
            // Binary data is refused even in lenient mode, at the line holding the
            // first NUL (strict mode may stop earlier, at a malformed line).
            let line = text[..nul].matches('\n').count() as u64 + 1;
            let e = read_carmen_from(text.as_bytes(), "g", &ReadOptions::lenient()).unwrap_err();
            prop_assert!(e.to_string().contains("not a text log"), "{}", e);
            prop_assert_eq!(e.line(), Some(line));
            let e = read_carmen_from(text.as_bytes(), "g", &ReadOptions::default()).unwrap_err();
            prop_assert!(e.line().is_some_and(|l| l <= line));
            return Ok(());
        }

        let log = read_carmen_from(text.as_bytes(), "g", &ReadOptions::lenient()).unwrap();
        let accepted: u64 = log.stats.messages.values().sum();
        let unknown: u64 = log.stats.unknown.values().sum();
        prop_assert_eq!(log.stats.lines, n_lines);
        prop_assert_eq!(
            log.stats.blank + log.stats.comments + unknown + accepted + log.stats.skipped_lines,
            n_lines
        );
        let scans = log.stats.messages.iter().filter(|(k, _)| k.contains("LASER")).map(|(_, v)| v).sum::<u64>();
        prop_assert_eq!(scans as usize, log.scans.len());
        prop_assert!(log.scans.iter().all(|s| s.ranges.len() == s.geometry.num_readings()));
        prop_assert!(log.encoders.windows(2).all(|w| w[0].t <= w[1].t));

        match read_carmen_from(text.as_bytes(), "g", &ReadOptions::default()) {
            Ok(strict) => {
                prop_assert_eq!(log.stats.skipped_lines, 0);
                prop_assert_eq!(strict.encoders.len(), log.encoders.len());
                prop_assert_eq!(strict.scans.len(), log.scans.len());
            }
            Err(e) => {
                let line = e.line().unwrap();
                prop_assert!(line >= 1 && line <= n_lines);
                prop_assert_eq!(log.stats.first_skipped[0].0, line);
            }
        }
        // The other readers survive the same bytes too.
        let _ = read_json_log_from(text.as_bytes(), "g", &ReadOptions::lenient());
        let _ = read_tuples_from(text.as_bytes(), "g");
    }
}
