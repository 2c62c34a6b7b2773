//! One bag, two lasers (`read_bag_lasers`): the two-lidar fixture read once gives one
//! log per scan topic, the same wheel data in both, each its own scans and sweep.

use odocal_bag::{read_bag, read_bag_lasers, BagOptions, TopicChoice};
use std::path::PathBuf;

fn fixture() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/bags/turtlebot_two_lidars.bag")
}

#[test]
fn each_scan_topic_is_its_own_log_with_the_same_wheels() {
    let topics = ["/scan_front".to_string(), "/scan_rear".to_string()];
    let logs = read_bag_lasers(&fixture(), &BagOptions::default(), &topics).unwrap();
    assert_eq!(logs.len(), 2);
    assert_eq!(logs[0].selection.scan_topic, "/scan_front");
    assert_eq!(logs[1].selection.scan_topic, "/scan_rear");
    assert_eq!(logs[0].log.encoders, logs[1].log.encoders);
    // Front at 5 Hz, rear at 10 Hz: each its own scans.
    let (front, rear) = (logs[0].log.scans.len(), logs[1].log.scans.len());
    assert!(front > 0 && rear > front, "front {front}, rear {rear}");
    // Each log is what reading the bag for that one topic gives.
    for (topic, log) in topics.iter().zip(&logs) {
        let opts = BagOptions {
            choice: TopicChoice {
                scan_topic: Some(topic.clone()),
                ..TopicChoice::default()
            },
            ..BagOptions::default()
        };
        let single = read_bag(&fixture(), &opts).unwrap();
        assert_eq!(single.log.scans.len(), log.log.scans.len());
        assert_eq!(single.log.encoders, log.log.encoders);
    }
}

#[test]
fn a_missing_scan_topic_is_named() {
    let topics = ["/scan_front".to_string(), "/scan_top".to_string()];
    let err = read_bag_lasers(&fixture(), &BagOptions::default(), &topics)
        .unwrap_err()
        .to_string();
    assert!(err.contains("/scan_top"), "{err}");
}

#[test]
fn without_a_scan_topic_the_two_lasers_are_ambiguous() {
    let err = read_bag(&fixture(), &BagOptions::default())
        .unwrap_err()
        .to_string();
    assert!(err.contains("--scan-topic"), "{err}");
}
