//! End to end on the fixture bags of fixtures/bags/ (written by the Python `rosbags`
//! library from simulated runs, see make_bags.py): each calibrates back to its ground
//! truth within the bounds of the Carmen logs (0.35 % for r_L, r_R, b; 1.5 mm; 0.2°;
//! 4σ) — ROS 1 lz4 / bz2 / uncompressed with a clockwise laser, MCAP, db3 with
//! velocity-only joint states, a ROS 2 bag directory, odometry only, and wheel positions
//! wrapped to (−π, π] (unwrapped, with a note); none with a two-halves warning (one
//! robot throughout). Plus bad input:
//! each a clear error naming the file and what to do.

mod common;

use odocal_bag::{read_bag, BagOptions, TopicChoice};
use odocal_log::{encoders_from_odometry, NominalWheels, ValueSource, WHEEL_TICKS_PER_REVOLUTION};
use odocal_pipeline::{calibrate_log, FindingKind, NoProgress, Options, Severity};
use odocal_report::build_report;
use std::path::{Path, PathBuf};

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("fixtures/bags")
        .join(name)
}

fn truth(name: &str) -> (Vec<f64>, Vec<f64>) {
    let stem = name.split('.').next().unwrap();
    let text = std::fs::read_to_string(fixture(&format!("{stem}.truth.json"))).unwrap();
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    let get = |k: &str| -> Vec<f64> {
        ["r_l", "r_r", "b", "l_x", "l_y", "l_theta"]
            .iter()
            .map(|n| v[k][n].as_f64().unwrap())
            .collect()
    };
    (get("params"), get("nominal"))
}

fn check(name: &str) -> odocal_report::Report {
    let path = fixture(name);
    let (truth, nominal) = truth(name);
    let bag = read_bag(&path, &BagOptions::default()).expect("the fixture bag reads");
    let mut log = bag.log;
    if log.encoders.is_empty() {
        let wheels = NominalWheels {
            r_l: nominal[0],
            r_r: nominal[1],
            b: nominal[2],
        };
        log.encoders = encoders_from_odometry(&log.odom, wheels).unwrap();
        log.params.ticks_per_revolution =
            Some((WHEEL_TICKS_PER_REVOLUTION, ValueSource::Convention));
    }
    let opts = Options::default();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap();
    let outcome = pool
        .install(|| calibrate_log(&log, &opts, &NoProgress))
        .expect("calibration succeeds");
    let report = build_report(&path, &log, &opts, &outcome);
    let est = report.values();
    let bounds = common::bounds(&truth);
    let mut failures = Vec::new();
    for i in 0..6 {
        let err = est[i] - truth[i];
        println!(
            "{name}: param {i} error {err:+.3e} ({:+.2}σ)",
            err / report.sigma[i]
        );
        // Within the bound, or where the data fix a parameter less tightly than the
        // bound (ℓθ of the short Khepera bags: σ ≈ 0.21°), within 2σ; and the σ
        // itself at most twice the bound.
        let sigma = report.sigma[i];
        if err.is_nan()
            || err.abs() > bounds[i].max(2.0 * sigma)
            || err.abs() > 4.0 * sigma
            || sigma > 2.0 * bounds[i]
        {
            failures.push(format!(
                "param {i}: error {err:.3e}, σ {:.3e}",
                report.sigma[i]
            ));
        }
    }
    assert!(
        report.samples_used >= 40,
        "{name}: {} samples",
        report.samples_used
    );
    assert!(failures.is_empty(), "{name}: {}", failures.join("; "));
    // One robot throughout: the two-halves check may find the halves too short to
    // compare, but never a disagreement (short halves on a mirror or undetermined
    // solution used to give χ² in the tens of thousands here).
    for check in &report.checks {
        assert!(
            check.kind != FindingKind::TwoHalves || check.severity != Severity::Warning,
            "{name}: {}",
            check.message
        );
    }
    report
}

#[test]
fn ros1_lz4_with_extra_joints_in_changing_order_calibrates() {
    check("khepera_ros1_lz4.bag");
}

#[test]
fn ros1_uncompressed_with_a_clockwise_laser_calibrates() {
    check("khepera_ros1_plain_cw.bag");
}

#[test]
fn ros1_bz2_odometry_only_calibrates() {
    check("khepera_ros1_bz2_odom.bag");
}

#[test]
fn mcap_calibrates() {
    check("khepera_mcap.mcap");
}

#[test]
fn db3_with_velocity_only_joint_states_calibrates() {
    check("khepera_db3_velocity.db3");
}

#[test]
fn turtlebot_lds_360_degree_sweeping_laser_calibrates() {
    check("turtlebot_lds.bag");
}

#[test]
fn pioneer_sick_181_rays_clockwise_ros1_bz2_calibrates() {
    check("pioneer_sick_bz2.bag");
}

#[test]
fn ros2_bag_directory_calibrates() {
    check("khepera_ros2_dir");
}

#[test]
fn wheel_positions_wrapped_to_half_a_turn_calibrate_with_a_note() {
    let name = "khepera_ros1_wrapped.bag";
    // The fixture's wheel angles are wrapped: within ±π, with jumps of about 2π.
    let log = read_bag(&fixture(name), &BagOptions::default())
        .unwrap()
        .log;
    let half = WHEEL_TICKS_PER_REVOLUTION as i64 / 2;
    assert!(log
        .encoders
        .iter()
        .all(|e| e.left.abs() <= half && e.right.abs() <= half));
    let jumps: usize = log
        .encoders
        .windows(2)
        .map(|w| {
            usize::from((w[1].left - w[0].left).abs() > half)
                + usize::from((w[1].right - w[0].right).abs() > half)
        })
        .sum();
    assert!(jumps >= 10, "{jumps} wraps in the fixture");
    let report = check(name);
    let notes: Vec<_> = report
        .health
        .iter()
        .filter(|f| f.kind == FindingKind::WheelAngleWrap)
        .collect();
    assert_eq!(notes.len(), 1, "{:?}", report.health);
    assert_eq!(notes[0].severity, Severity::Info, "{}", notes[0]);
    assert_eq!(notes[0].count, jumps as u64, "{}", notes[0]);
}

/// A copy of a fixture, changed by `edit`, in a temporary file.
fn damaged(name: &str, edit: impl FnOnce(&mut Vec<u8>)) -> PathBuf {
    let mut bytes = std::fs::read(fixture(name)).unwrap();
    edit(&mut bytes);
    let path = std::env::temp_dir().join(format!("odocal-bag-{}-{name}", std::process::id()));
    std::fs::write(&path, bytes).unwrap();
    path
}

fn error_of(path: &Path, choice: TopicChoice) -> String {
    let opts = BagOptions {
        choice,
        ..BagOptions::default()
    };
    match read_bag(path, &opts) {
        Ok(_) => panic!("{} read without an error", path.display()),
        Err(e) => e.to_string(),
    }
}

#[test]
fn truncated_bags_are_refused_with_the_file_and_the_fix() {
    for name in ["khepera_ros1_lz4.bag", "khepera_mcap.mcap"] {
        let path = damaged(name, |b| b.truncate(b.len() / 2));
        let e = error_of(&path, TopicChoice::default());
        assert!(e.contains(&path.display().to_string()), "{e}");
        assert!(e.contains("truncated") || e.contains("damaged"), "{e}");
        let _ = std::fs::remove_file(path);
    }
}

#[test]
fn an_unknown_chunk_compression_is_named() {
    let path = damaged("khepera_ros1_lz4.bag", |b| {
        let at = b.windows(15).position(|w| w == b"compression=lz4").unwrap();
        b[at + 12..at + 15].copy_from_slice(b"xz9");
    });
    let e = error_of(&path, TopicChoice::default());
    assert!(
        e.contains("`xz9`") && e.contains("rosbag decompress"),
        "{e}"
    );
    let _ = std::fs::remove_file(path);
}

#[test]
fn an_mcap_chunk_with_a_bad_length_is_refused() {
    let path = damaged("khepera_mcap.mcap", |b| {
        // Walk the records (opcode u8, length u64) after the 8-byte magic to a chunk.
        let mut at = 8;
        while b[at] != 0x06 {
            let len = u64::from_le_bytes(b[at + 1..at + 9].try_into().unwrap());
            at += 9 + len as usize;
        }
        let len = u64::from_le_bytes(b[at + 1..at + 9].try_into().unwrap());
        b[at + 1..at + 9].copy_from_slice(&(len + 10_000_000).to_le_bytes());
    });
    let e = error_of(&path, TopicChoice::default());
    assert!(e.contains(&path.display().to_string()), "{e}");
    let _ = std::fs::remove_file(path);
}

#[test]
fn a_topic_of_the_wrong_type_lists_the_candidates() {
    let choice = TopicChoice {
        scan_topic: Some("/joint_states".into()),
        ..TopicChoice::default()
    };
    let e = error_of(&fixture("khepera_mcap.mcap"), choice);
    assert!(
        e.contains("--scan-topic") && e.contains("/scan") && e.contains("JointState"),
        "{e}"
    );
}

#[test]
fn unknown_wheel_joints_and_missing_wheels_are_explained() {
    let choice = TopicChoice {
        wheel_joints: Some(("left".into(), "right".into())),
        ..TopicChoice::default()
    };
    let e = error_of(&fixture("khepera_ros1_lz4.bag"), choice);
    assert!(
        e.contains("--wheel-joints") && e.contains("wheel_left_joint"),
        "{e}"
    );
    let choice = TopicChoice {
        odom_topic: Some("/odom".into()),
        ..TopicChoice::default()
    };
    let e = error_of(&fixture("khepera_ros1_lz4.bag"), choice);
    assert!(e.contains("--odom-topic /odom: no such topic"), "{e}");
}
