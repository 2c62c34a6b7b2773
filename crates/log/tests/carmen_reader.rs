//! The Carmen-style reader on small hand-written logs: every message, every error kind
//! with its line number, wrap-around, CRLF, tabs, comments, unknown messages, FLASER
//! geometry, ordering, strict and lenient modes.

use odocal_log::{read_carmen_from, Log, LogError, Mode, ReadOptions, ScanKind, ValueSource};
use std::f64::consts::PI;

fn strict(text: &str) -> Result<Log, LogError> {
    read_carmen_from(text.as_bytes(), "test.log", &ReadOptions::default())
}

fn lenient(text: &str) -> Log {
    read_carmen_from(text.as_bytes(), "test.log", &ReadOptions::lenient()).unwrap()
}

/// The error of a strict read, with its line and text.
fn error_of(text: &str) -> (u64, String) {
    let e = strict(text).expect_err("a malformed log must be an error in strict mode");
    (e.line().expect("a parse error has a line"), e.to_string())
}

const RAW3: &str = "RAWLASER1 2 -0.5 1 0.5 4 0.01 0 3 1.5 2.5 3.5 0";

#[test]
fn spec_example_reads_with_exact_values() {
    let text = "# CARMEN Logfile\n\
        # message_name [message contents] timestamp hostname logger_timestamp\n\
        PARAM robot_wheel_ticks_per_revolution 2764.8 khepera 0.0\n\
        ENCODER -2 1 1190000000.017285 khepera 0.017285\n\
        ENCODER -8 8 1190000000.041045 khepera 0.041045\n\
        RAWLASER1 2 -2.086214 4.172428 0.00613592 4.000 0.010 0 3 0.512 0.515 1.203 0 1190000000.500000 khepera 0.500000\n";
    let log = strict(text).unwrap();
    assert_eq!(log.stats.lines, 6);
    assert_eq!(log.stats.comments, 2);
    assert_eq!(
        log.params.ticks_per_revolution,
        Some((2764.8, ValueSource::LogParam { line: 3 }))
    );
    assert_eq!(log.encoders.len(), 2);
    assert_eq!((log.encoders[0].left, log.encoders[0].right), (-2, 1));
    assert_eq!(log.encoders[1].t, 1190000000.041045);
    assert_eq!(log.encoders[1].line, 5);
    let s = log.scans.get(0).unwrap();
    assert_eq!(s.t, 1190000000.5);
    assert_eq!(s.ranges, &[0.512f32, 0.515, 1.203][..]);
    assert_eq!(s.kind, ScanKind::RawLaser1);
    assert_eq!(s.geometry.laser_type, 2);
    assert_eq!(
        s.geometry.angles[..],
        [
            -2.086214,
            -2.086214 + 0.00613592,
            -2.086214 + 2.0 * 0.00613592
        ]
    );
    assert_eq!(s.geometry.max_range, 4.0);
    assert_eq!(s.line, 6);
    assert_eq!(log.stats.messages["ENCODER"], 2);
    assert_eq!(log.stats.messages["PARAM"], 1);
    assert_eq!(log.stats.messages["RAWLASER1"], 1);
    assert_eq!(log.stats.skipped_lines, 0);
    let e = log.check_calibration_inputs().unwrap_err().to_string();
    assert!(e.contains("at least two"), "{e}");
}

#[test]
fn every_error_kind_names_file_line_message_and_expectation() {
    let good = "PARAM robot_wheel_ticks_per_revolution 100 h 0\nENCODER 1 2 10.0 h 10.0\n";
    let cases: &[(&str, &str, &[&str])] = &[
        (
            "ENCODER 1.5 2 11.0 h 11.0",
            "ENCODER",
            &["left_ticks (an integer)", "`1.5`"],
        ),
        (
            "ENCODER 1 x 11.0 h 11.0",
            "ENCODER",
            &["right_ticks", "`x`"],
        ),
        (
            "ENCODER 1 2 11.0 h",
            "ENCODER",
            &["logger_timestamp", "end of line"],
        ),
        (
            "ENCODER 1 2 11.0 h 11.0 extra",
            "ENCODER",
            &["end of line after logger_timestamp", "`extra`"],
        ),
        (
            "ENCODER 1 2 nan h 11.0",
            "ENCODER",
            &["timestamp (a finite number)", "`nan`"],
        ),
        (
            "ENCODER 1 2 inf h 11.0",
            "ENCODER",
            &["timestamp (a finite number)"],
        ),
        (
            "RAWLASER1 2 -0.5 1 0.5 4 0.01 0 3 1.5 2.5 0 11.0 h 11.0",
            "RAWLASER1",
            &["num_readings = 3"],
        ),
        (
            "RAWLASER1 2 -0.5 1 0.5 4 0.01 0 2 1.5 2.5 3.5 0 11.0 h 11.0",
            "RAWLASER1",
            &["num_readings = 2"],
        ),
        (
            "RAWLASER1 2 -0.5 1 0.5 4 0.01 0 3 1.5 2..5 3.5 0 11.0 h 11.0",
            "RAWLASER1",
            &["range reading", "`2..5`"],
        ),
        (
            "RAWLASER1 x -0.5 1 0.5 4 0.01 0 3 1.5 2.5 3.5 0 11.0 h 11.0",
            "RAWLASER1",
            &["laser_type (an integer)"],
        ),
        (
            "RAWLASER1 2 -0.5 1 0.5 4 0.01 0 -3 11.0 h 11.0",
            "RAWLASER1",
            &["num_readings (a count"],
        ),
        (
            "ROBOTLASER1 2 -0.5 1 0.5 4 0.01 0 3 1.5 2.5 3.5 0 0 0 0 0 0 0 11.0 h 11.0",
            "ROBOTLASER1",
            &["num_readings = 3"],
        ),
        ("FLASER 3 1 2 11.0 h 11.0", "FLASER", &["num_readings = 3"]),
        (
            "ODOM 0 0 0 0 0 11.0 h 11.0",
            "ODOM",
            &["expected 9 fields (x y theta", "found 8"],
        ),
        (
            "PARAM robot_wheel_ticks_per_revolution -5",
            "PARAM",
            &["ticks per revolution (a positive number)", "`-5`"],
        ),
        (
            "PARAM laser_front_laser_fov 0",
            "PARAM",
            &["field of view (a positive number, rad)", "`0`"],
        ),
        (
            "PARAM laser_front_laser_min_range abc",
            "PARAM",
            &["minimum range", "`abc`"],
        ),
        (
            "RAWLASER1 2 nan 1 0.5 4 0.01 0 3 1.5 2.5 3.5 0 11.0 h 11.0",
            "RAWLASER1",
            &["start_angle (a finite number)", "`nan`"],
        ),
        (
            "RAWLASER1 2 -0.5 1 0.5 nan 0.01 0 3 1.5 2.5 3.5 0 11.0 h 11.0",
            "RAWLASER1",
            &["maximum_range"],
        ),
        (
            "RAWLASER1 2 -0.5 1 0.5 4 0.01 0 3 1.5 2.5 3.5 1 11.0 h 11.0",
            "RAWLASER1",
            &["num_readings = 3, num_remissions = 1", "timestamp"],
        ),
        (
            "FLASER 2 1 2 0 0 0 0 0 11.0 h 11.0",
            "FLASER",
            &["num_readings = 2"],
        ),
        (
            "PARAM robot_encoder_modulus 65536.5",
            "PARAM",
            &["encoder modulus"],
        ),
    ];
    for &(bad, msg, needles) in cases {
        let text = format!("{good}# comment\n\n{bad}\nENCODER 3 4 12.0 h 12.0\n");
        let (line, err) = error_of(&text);
        assert_eq!(line, 5, "{bad} → {err}");
        let prefix = format!("test.log:5: {msg}: expected ");
        assert!(err.starts_with(&prefix), "{bad} → {err}");
        for n in needles {
            assert!(err.contains(n), "{bad} → {err} (missing {n:?})");
        }
        // Lenient: the line is skipped, the rest is read, the skip is reported.
        let log = lenient(&text);
        assert_eq!(log.stats.skipped_lines, 1, "{bad}");
        assert_eq!(log.stats.first_skipped[0].0, 5, "{bad}");
        let skipped = &log.stats.first_skipped[0].1;
        assert!(
            skipped.starts_with(msg) && err.ends_with(skipped.as_str()),
            "{skipped}"
        );
        assert_eq!(log.encoders.len(), 2, "{bad}");
    }
    // A PARAM without a value.
    let (line, err) = error_of("PARAM robot_wheel_ticks_per_revolution\n");
    assert_eq!(line, 1);
    assert!(
        err.contains("PARAM: expected parameter value, found end of line"),
        "{err}"
    );
}

#[test]
fn lenient_mode_counts_skips_and_keeps_the_first_few_line_numbers() {
    let mut text = String::from("ENCODER 0 0 1.0 h 1.0\n");
    for i in 0..8 {
        text.push_str(&format!(
            "ENCODER broken {i}\nENCODER {i} {i} {}.5 h 0\n",
            i + 1
        ));
    }
    let log = lenient(&text);
    assert_eq!(log.stats.skipped_lines, 8);
    let lines: Vec<u64> = log.stats.first_skipped.iter().map(|(l, _)| *l).collect();
    assert_eq!(lines, vec![2, 4, 6, 8, 10]);
    assert_eq!(log.encoders.len(), 9);
    assert_eq!(log.stats.messages["ENCODER"], 9);
    assert_eq!(strict(&text).unwrap_err().line(), Some(2));
    let opts = ReadOptions {
        mode: Mode::Lenient,
        ..ReadOptions::default()
    };
    assert_eq!(opts, ReadOptions::lenient());
}

#[test]
fn encoder_counters_are_unwrapped_with_the_modulus() {
    let text = "PARAM robot_encoder_modulus 65536 h 0\n\
        ENCODER 65530 3 1 h 1\n\
        ENCODER 65535 1 2 h 2\n\
        ENCODER 4 65533 3 h 3\n\
        ENCODER 10 65530 4 h 4\n\
        ENCODER 40000 4 5 h 5\n\
        ENCODER 32000 32000 6 h 6\n";
    let log = strict(text).unwrap();
    let ticks: Vec<(i64, i64)> = log.encoders.iter().map(|e| (e.left, e.right)).collect();
    assert_eq!(
        ticks,
        vec![
            (65530, 3),
            (65535, 1),
            (65540, -3),
            (65546, -6),
            (40000, 4),
            (32000, 32000)
        ]
    );
    assert_eq!(log.stats.encoder_wraps, 4);
    assert_eq!(log.params.encoder_modulus, Some(65536.0));

    // Without a modulus nothing is unwrapped; the command line can supply it.
    let no_param: String = text.lines().skip(1).map(|l| format!("{l}\n")).collect();
    let raw = strict(&no_param).unwrap();
    assert_eq!(raw.encoders[2].left, 4);
    assert_eq!(raw.stats.encoder_wraps, 0);
    let opts = ReadOptions {
        encoder_modulus: Some(65536.0),
        ..ReadOptions::default()
    };
    let cli = read_carmen_from(no_param.as_bytes(), "x", &opts).unwrap();
    assert_eq!(
        cli.encoders,
        log.encoders
            .iter()
            .map(|e| {
                let mut e = *e;
                e.line -= 1;
                e
            })
            .collect::<Vec<_>>()
    );

    // A 32-bit counter crossing zero in signed form.
    let signed = "PARAM robot_encoder_modulus 4294967296\n\
        ENCODER 2147483646 -2147483647 1 h 1\n\
        ENCODER -2147483646 2147483645 2 h 2\n";
    let log = strict(signed).unwrap();
    assert_eq!(log.encoders[1].left, 2147483650);
    assert_eq!(log.encoders[1].right, -2147483651);
}

#[test]
fn crlf_tabs_and_runs_of_spaces_are_accepted() {
    let text = "PARAM\trobot_wheel_ticks_per_revolution \t 2764.8\r\n\
        ENCODER  -2\t\t1   5.5 host 5.5 \r\n\
        \r\n\
        \t# indented comment\r\n\
        RAWLASER1\t2 -0.5 1 0.5 4 0.01 0 3 1.5 2.5 3.5 0\t6.0\thost\t6.0\r\n";
    let log = strict(text).unwrap();
    assert_eq!(log.params.ticks_per_revolution.unwrap().0, 2764.8);
    assert_eq!(
        (
            log.encoders[0].left,
            log.encoders[0].right,
            log.encoders[0].t
        ),
        (-2, 1, 5.5)
    );
    assert_eq!(log.scans.get(0).unwrap().ranges, &[1.5f32, 2.5, 3.5][..]);
    assert_eq!(log.stats.blank, 1);
    assert_eq!(log.stats.comments, 1);
    assert_eq!(log.stats.lines, 5);
}

#[test]
fn a_last_line_without_newline_is_read() {
    let log = strict("ENCODER 1 2 1.0 h 1.0\nENCODER 3 4 2.0 h 2.0").unwrap();
    assert_eq!(log.encoders.len(), 2);
    assert_eq!(log.stats.lines, 2);
}

#[test]
fn unknown_messages_are_counted_by_name_and_never_errors() {
    let text = "SYNC 1 2 3\nTRUEPOS 1 2 3 4 5 6 1.0 h 1.0\nSYNC\nNMEAGGA x\n\
        RAWLASER2 garbage\nencoder 1 2 3 h 4\nENCODER 1 2 1.0 h 1.0\n";
    for log in [strict(text).unwrap(), lenient(text)] {
        let unknown: Vec<(&str, u64)> = log
            .stats
            .unknown
            .iter()
            .map(|(k, v)| (k.as_str(), *v))
            .collect();
        assert_eq!(
            unknown,
            vec![
                ("NMEAGGA", 1),
                ("RAWLASER2", 1),
                ("SYNC", 2),
                ("TRUEPOS", 1),
                ("encoder", 1)
            ]
        );
        assert_eq!(log.encoders.len(), 1);
        assert_eq!(log.stats.skipped_lines, 0);
    }
}

#[test]
fn flaser_geometry_comes_from_params_with_a_centred_pi_default() {
    let text = "FLASER 5 1 2 3 4 5 0 0 0 0 0 0 1.0 h 1.0\n";
    let log = strict(text).unwrap();
    let s = log.scans.get(0).unwrap();
    assert_eq!(s.kind, ScanKind::FLaser);
    let expected = [-PI / 2.0, -PI / 4.0, 0.0, PI / 4.0, PI / 2.0];
    for (a, e) in s.geometry.angles.iter().zip(expected) {
        assert!((a - e).abs() < 1e-15, "{a} vs {e}");
    }
    assert_eq!(s.geometry.fov, PI);
    assert_eq!(s.ranges, &[1.0f32, 2.0, 3.0, 4.0, 5.0][..]);

    let text = "PARAM laser_front_laser_fov 1.0 h 0\n\
        PARAM laser_front_laser_resolution 0.25 h 0\n\
        PARAM laser_front_laser_max_range 4.5 h 0\n\
        FLASER 5 1 2 3 4 5 0 0 0 0 0 0 1.0 h 1.0\n\
        FLASER 5 1 2 3 4.5 0 0.1 0.2 0.3 0 0 0 2.0 h 2.0\n";
    let log = strict(text).unwrap();
    assert_eq!(log.scans.geometries.len(), 1);
    let s = log.scans.get(1).unwrap();
    assert_eq!(s.geometry.angles[..], [-0.5, -0.25, 0.0, 0.25, 0.5]);
    assert_eq!(s.geometry.max_range, 4.5);
    // 5 (> max range), 4.5 (= max range) and 0 are invalid.
    assert_eq!(log.stats.invalid_readings, 3);
    assert!(log.stats.warnings.is_empty());

    // Resolution disagreeing with the field of view: the resolution wins, warned once.
    let text = "PARAM laser_front_laser_fov 3.0 h 0\nPARAM laser_front_laser_resolution 0.5 h 0\n\
        FLASER 3 1 2 3 0 0 0 0 0 0 1.0 h 1.0\nFLASER 3 1 2 3 0 0 0 0 0 0 2.0 h 2.0\n";
    let log = strict(text).unwrap();
    assert_eq!(
        log.scans.get(0).unwrap().geometry.angles[..],
        [-0.5, 0.0, 0.5]
    );
    assert_eq!(log.stats.warnings.len(), 1);
    assert!(
        log.stats.warnings[0].contains("FLASER"),
        "{:?}",
        log.stats.warnings
    );
}

#[test]
fn fov_disagreeing_with_resolution_is_warned_once_and_the_resolution_used() {
    let text = "RAWLASER1 2 -0.5 3.0 0.5 4 0.01 0 3 1.5 2.5 3.5 0 1 h 1\n\
        RAWLASER1 2 -0.5 3.0 0.5 4 0.01 0 3 1.5 2.5 3.5 0 2 h 2\n";
    let log = strict(text).unwrap();
    assert_eq!(log.stats.warnings.len(), 1, "{:?}", log.stats.warnings);
    assert!(log.stats.warnings[0].contains("line 1"));
    assert_eq!(
        log.scans.get(1).unwrap().geometry.angles[..],
        [-0.5, 0.0, 0.5]
    );
    assert_eq!(log.scans.geometries.len(), 1);
}

#[test]
fn invalid_readings_are_counted_with_the_min_range_param_or_option() {
    // min range 0.02 by default: 0, 0.01, 0.02, 4 (= max), inf, nan are invalid.
    let text = "RAWLASER1 2 -1 2 0.25 4 0.01 0 9 0 0.01 0.02 0.021 3.999 4 inf nan 1 0 1 h 1\n";
    let log = strict(text).unwrap();
    assert_eq!(log.stats.invalid_readings, 6);
    let s = log.scans.get(0).unwrap();
    assert!(s.ranges[6].is_infinite() && s.ranges[7].is_nan());
    let with_param = format!("PARAM laser_front_laser_min_range 0.5 h 0\n{text}");
    assert_eq!(strict(&with_param).unwrap().stats.invalid_readings, 7);
    let opts = ReadOptions {
        min_range: Some(0.0),
        ..ReadOptions::default()
    };
    let log = read_carmen_from(with_param.as_bytes(), "x", &opts).unwrap();
    assert_eq!(log.params.laser_min_range, 0.0);
    assert_eq!(log.scans.get(0).unwrap().geometry.min_range, 0.0);
    assert_eq!(log.stats.invalid_readings, 4);
}

#[test]
fn out_of_order_records_are_reported_per_stream_and_sorted() {
    let text = format!(
        "ENCODER 1 1 1.0 h 1\n{RAW3} 5.0 h 5\nENCODER 3 3 3.0 h 3\nENCODER 2 2 2.0 h 2\n\
         {RAW3} 4.0 h 4\nODOM 0 0 0 0 0 0 1.0 h 1\nENCODER 4 4 4.0 h 4\n"
    );
    let log = strict(&text).unwrap();
    let ts: Vec<f64> = log.encoders.iter().map(|e| e.t).collect();
    assert_eq!(ts, vec![1.0, 2.0, 3.0, 4.0]);
    assert_eq!(log.encoders[1].line, 4);
    let st: Vec<f64> = log.scans.iter().map(|s| s.t).collect();
    assert_eq!(st, vec![4.0, 5.0]);
    assert_eq!(log.scans.get(0).unwrap().line, 5);
    assert_eq!(log.stats.out_of_order["encoder"], 1);
    assert_eq!(log.stats.out_of_order["laser"], 1);
    // The ODOM at t = 1 after a scan at t = 4 is in order within its own stream.
    assert!(!log.stats.out_of_order.contains_key("odom"));
    assert_eq!(log.stats.warnings.len(), 2);
    assert!(log
        .stats
        .warnings
        .iter()
        .any(|w| w.contains("first at line 4")));
}

#[test]
fn scans_share_one_geometry_per_distinct_sensor_setup() {
    let mut text = String::new();
    for i in 0..50 {
        text.push_str(&format!("{RAW3} {i} h {i}\n"));
        text.push_str(&format!(
            "RAWLASER1 2 -0.5 1 0.5 5 0.01 0 3 1 2 3 0 {i}.5 h 0\n"
        ));
    }
    let log = strict(&text).unwrap();
    assert_eq!(log.scans.len(), 100);
    assert_eq!(log.scans.geometries.len(), 2);
    assert_eq!(log.scans.ranges.len(), 300);
    assert_eq!(log.scans.get(99).unwrap().geometry.max_range, 5.0);
}

#[test]
fn odom_and_robotlaser1_and_remissions_are_read() {
    let text = "ODOM 1.5 -2 0.25 0.1 -0.2 0 7.0 h 7.0\n\
        ROBOTLASER1 2 -0.5 1 0.5 4 0.01 1 3 1.5 2.5 3.5 3 10 20 30 0.1 0.2 0.3 1 2 3 0.5 0.6 1 2 100000 8.0 h 8.0\n";
    let log = strict(text).unwrap();
    let o = log.odom[0];
    assert_eq!(
        (o.pose.x, o.pose.y, o.pose.theta, o.tv, o.rv, o.t),
        (1.5, -2.0, 0.25, 0.1, -0.2, 7.0)
    );
    let s = log.scans.get(0).unwrap();
    assert_eq!(s.kind, ScanKind::RobotLaser1);
    assert_eq!(s.remissions, &[10.0f32, 20.0, 30.0][..]);
    assert_eq!(s.geometry.remission_mode, 1);
    assert_eq!(log.stats.messages["ROBOTLASER1"], 1);
    assert_eq!(log.stats.messages["ODOM"], 1);
}

#[test]
fn params_override_in_order_and_the_command_line_overrides_params() {
    let text = "PARAM robot_wheel_ticks_per_revolution 100 h 0\n\
        PARAM robot_wheel_ticks_per_revolution 2764.8 1190000000.0 khepera 0.0\n\
        PARAM some_other_param hello\n";
    let log = strict(text).unwrap();
    assert_eq!(
        log.params.ticks_per_revolution,
        Some((2764.8, ValueSource::LogParam { line: 2 }))
    );
    assert_eq!(log.params.all["some_other_param"], "hello");
    assert_eq!(log.params.all["robot_wheel_ticks_per_revolution"], "2764.8");
    let opts = ReadOptions {
        ticks_per_revolution: Some(512.0),
        ..ReadOptions::default()
    };
    let log = read_carmen_from(text.as_bytes(), "x", &opts).unwrap();
    assert_eq!(
        log.params.ticks_per_revolution,
        Some((512.0, ValueSource::CommandLine))
    );
    let bad = ReadOptions {
        ticks_per_revolution: Some(-1.0),
        ..ReadOptions::default()
    };
    let e = read_carmen_from(text.as_bytes(), "x", &bad).unwrap_err();
    assert!(e.to_string().contains("ticks per revolution"), "{e}");
}

#[test]
fn missing_calibration_data_is_explained() {
    let scans = format!("{RAW3} 1 h 1\n{RAW3} 2 h 2\n");
    let no_encoders = strict(&format!(
        "PARAM robot_wheel_ticks_per_revolution 10\n{scans}"
    ))
    .unwrap();
    let e = no_encoders
        .check_calibration_inputs()
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("test.log: the log has no ENCODER records"),
        "{e}"
    );

    let one_scan = strict(&format!(
        "PARAM robot_wheel_ticks_per_revolution 10\nENCODER 1 1 1 h 1\n{RAW3} 1 h 1\n"
    ))
    .unwrap();
    let e = one_scan.check_calibration_inputs().unwrap_err().to_string();
    assert!(
        e.contains("1 laser scan(s)") && e.contains("at least two"),
        "{e}"
    );

    let no_ticks = strict(&format!("ENCODER 1 1 1 h 1\n{scans}")).unwrap();
    let e = no_ticks.check_calibration_inputs().unwrap_err().to_string();
    assert!(
        e.contains("--ticks-per-rev") && e.contains("PARAM robot_wheel_ticks_per_revolution"),
        "{e}"
    );

    let ok = strict(&format!(
        "PARAM robot_wheel_ticks_per_revolution 10\nENCODER 1 1 1 h 1\n{scans}"
    ))
    .unwrap();
    assert_eq!(ok.check_calibration_inputs().unwrap(), 10.0);
}

/// A log as another logger might write it: PARAMs with `timestamp hostname
/// logger_timestamp` trailers, tabs, ROBOTLASER1 with remissions, message kinds we do
/// not use, comments in the middle, a URG-04LX geometry written with few digits.
#[test]
fn a_log_from_another_writer_gives_exact_counts() {
    let res = 0.00613592;
    let ranges: Vec<String> = (0..681)
        .map(|i| format!("{:.3}", 0.5 + (i % 300) as f64 * 0.01))
        .collect();
    let ranges = ranges.join(" ");
    let mut text = String::from(
        "# CARMEN Logfile\n# file format is one of:\n#\n\
         PARAM robot_wheel_ticks_per_revolution 2764.8 1190000000.000000 khepera 0.000000\n\
         PARAM\trobot_encoder_modulus\t65536\t1190000000.000000\tkhepera\t0.000000\n\
         PARAM robot_use_sonar off 1190000000.000000 khepera 0.000000\n\
         PARAM laser_front_laser_min_range 0.02\n",
    );
    let mut t = 1190000000.0;
    let (mut l, mut r) = (65000i64, 100i64);
    let mut scans = 0;
    let mut enc = 0;
    for k in 0..200 {
        t += 0.02;
        l = (l + 7) % 65536;
        r = (r - 7).rem_euclid(65536);
        text.push_str(&format!(
            "ENCODER\t{l}\t{r}\t{t:.6}\tkhepera\t{:.6}\n",
            t - 1190000000.0
        ));
        enc += 1;
        if k % 5 == 0 {
            text.push_str(&format!(
                "ROBOTLASER1 2 -2.086214 4.172428 {res} 4.000 0.010 0 681 {ranges} 0 \
                 0.0 0.0 0.0 0.0 0.0 0.0 0.000 0.000 0.550 0.050 1000000.000 {t:.6} khepera {:.6}\n",
                t - 1190000000.0
            ));
            scans += 1;
        }
        if k % 10 == 0 {
            text.push_str(&format!(
                "ODOM 0.0 0.0 0.0 0.0 0.0 0.0 {t:.6} khepera 0.0\n"
            ));
            text.push_str(&format!("TRUEPOS 0 0 0 0 0 0 {t:.6} khepera 0.0\n"));
            text.push_str("# a comment\n");
        }
    }
    for log in [strict(&text).unwrap(), lenient(&text)] {
        assert_eq!(log.encoders.len(), enc);
        assert_eq!(log.scans.len(), scans);
        assert_eq!(log.odom.len(), 20);
        assert_eq!(log.stats.unknown["TRUEPOS"], 20);
        assert_eq!(log.stats.comments, 23);
        assert_eq!(log.stats.skipped_lines, 0);
        assert_eq!(log.scans.geometries.len(), 1);
        assert_eq!(log.scans.geometries[0].num_readings(), 681);
        assert_eq!(log.stats.encoder_wraps, 2);
        // Unwrapped ticks go up by exactly 7 per record on the left, down on the right.
        for w in log.encoders.windows(2) {
            assert_eq!(w[1].left - w[0].left, 7);
            assert_eq!(w[1].right - w[0].right, -7);
        }
        assert!(log.stats.warnings.iter().all(|w| !w.contains("out of")));
        assert_eq!(log.params.ticks_per_revolution.as_ref().unwrap().0, 2764.8);
        assert_eq!(log.check_calibration_inputs().unwrap(), 2764.8);
    }
}

/// Memory stays at about the size of the ranges: one geometry, no growth slack.
#[test]
fn stored_scans_cost_about_their_ranges() {
    let g = odocal_log::ScanGeometry::urg_04lx();
    let mut w = odocal_log::LogWriter::new(Vec::new(), "h");
    let ranges: Vec<f32> = (0..681).map(|i| 0.5 + i as f32 * 0.001).collect();
    for k in 0..300 {
        w.rawlaser1(k as f64 * 0.1, &g, &ranges).unwrap();
    }
    let text = w.into_inner();
    let log = read_carmen_from(&text[..], "m", &ReadOptions::default()).unwrap();
    assert_eq!(log.scans.geometries.len(), 1);
    assert_eq!(log.scans.ranges.len(), 300 * 681);
    assert_eq!(log.scans.ranges.capacity(), log.scans.ranges.len());
    let per_scan_overhead = std::mem::size_of::<odocal_log::ScanMeta>();
    assert!(
        per_scan_overhead * 10 < 681 * 4,
        "{per_scan_overhead} bytes per scan"
    );
    assert_eq!(log.scans.get(299).unwrap().ranges, &ranges[..]);
}

#[test]
fn time_increment_param_sets_every_geometry_and_round_trips() {
    let text = "RAWLASER1 2 -0.1 0.2 0.1 4.0 0.01 0 3 1.0 1.1 1.2 0 10.0 h 10.0\n\
                PARAM laser_front_laser_time_increment 9.765625e-5 h 0\n";
    let log = read_carmen_from(text.as_bytes(), "x", &ReadOptions::default()).unwrap();
    assert_eq!(log.params.laser_time_increment, Some(9.765625e-5));
    let g = log.scans.get(0).unwrap().geometry;
    assert_eq!(g.time_increment, 9.765625e-5);
    assert_eq!(g.ray_time_offset(2), 2.0 * 9.765625e-5);
    assert_eq!(g.sweep_duration(), 2.0 * 9.765625e-5);
    let mut out = Vec::new();
    odocal_log::write_log(&mut out, &log).unwrap();
    let again = read_carmen_from(out.as_slice(), "y", &ReadOptions::default()).unwrap();
    assert_eq!(
        again.scans.get(0).unwrap().geometry.time_increment,
        9.765625e-5
    );

    let opts = ReadOptions {
        time_increment: Some(2e-4),
        ..ReadOptions::default()
    };
    let cli = read_carmen_from(text.as_bytes(), "x", &opts).unwrap();
    assert_eq!(cli.scans.get(0).unwrap().geometry.time_increment, 2e-4);
    let bad = "PARAM laser_front_laser_time_increment nan h 0\n";
    let err = read_carmen_from(bad.as_bytes(), "x", &ReadOptions::default()).unwrap_err();
    assert!(err.to_string().contains("time between rays"), "{err}");
}
