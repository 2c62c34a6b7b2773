//! ROS 2 bags recorded with `--compression-format zstd`: `compression_mode: FILE` (the
//! storage file is `NAME.db3.zstd`) and `MESSAGE` (each message a zstd frame), both
//! written by make_bags.py from one simulated run, read to the same log.

mod support;

use odocal_bag::{read_bag, BagFormat, BagOptions};
use support::fixture;

/// Held by the tests that read the file-compressed bag: its decompressed copy is a
/// temporary file named after the process, which the removal test would otherwise
/// see from the other test's read, running at the same time in another thread.
static FILE_COMPRESSED_READS: std::sync::Mutex<()> = std::sync::Mutex::new(());

#[test]
fn both_zstd_modes_read_to_the_same_log() {
    let _one_at_a_time = FILE_COMPRESSED_READS
        .lock()
        .unwrap_or_else(|e| e.into_inner());
    let file = read_bag(&fixture("khepera_db3_zstd_file"), &BagOptions::default()).unwrap();
    let message = read_bag(
        &fixture("khepera_mcap_zstd_message"),
        &BagOptions::default(),
    )
    .unwrap();
    assert_eq!(file.format, BagFormat::Ros2Directory);
    // 2 s at 10 Hz scans and 50 Hz wheel joints, as metadata.yaml counts them.
    assert_eq!(file.log.scans.len(), 20);
    assert_eq!(file.log.encoders.len(), 100);
    assert_eq!(file.log.scans, message.log.scans);
    assert_eq!(file.log.encoders, message.log.encoders);
    // The ranges are the simulator's: within the laser's limits, most of them hits.
    let hits = file
        .log
        .scans
        .ranges
        .iter()
        .filter(|r| r.is_finite() && **r > 0.02 && **r < 4.0)
        .count();
    assert!(hits > file.log.scans.ranges.len() / 2, "{hits}");
}

#[test]
fn the_decompressed_copy_of_a_file_compressed_bag_is_removed() {
    let _one_at_a_time = FILE_COMPRESSED_READS
        .lock()
        .unwrap_or_else(|e| e.into_inner());
    let before = odocal_temp_files();
    read_bag(&fixture("khepera_db3_zstd_file"), &BagOptions::default()).unwrap();
    let after = odocal_temp_files();
    let left: Vec<_> = after.difference(&before).collect();
    assert!(left.is_empty(), "{left:?}");
}

fn odocal_temp_files() -> std::collections::BTreeSet<String> {
    let own = format!("odocal-{}-", std::process::id());
    std::fs::read_dir(std::env::temp_dir())
        .unwrap()
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with(&own))
        .collect()
}

#[test]
fn a_damaged_zstd_message_names_topic_and_message() {
    let dir = support::temp("zstd-damaged");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let src = fixture("khepera_mcap_zstd_message");
    for e in std::fs::read_dir(&src).unwrap() {
        let e = e.unwrap();
        std::fs::copy(e.path(), dir.join(e.file_name())).unwrap();
    }
    // Every zstd frame starts 28 b5 2f fd: spoil the first one's magic.
    let mcap = dir.join("khepera_mcap_zstd_message.mcap");
    let mut bytes = std::fs::read(&mcap).unwrap();
    let at = bytes
        .windows(4)
        .position(|w| w == [0x28, 0xb5, 0x2f, 0xfd])
        .unwrap();
    bytes[at] = 0;
    std::fs::write(&mcap, &bytes).unwrap();
    let e = read_bag(&dir, &BagOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("message 0"), "{e}");
    assert!(e.contains("zstd"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}
