//! Which kind of bag a path is, by content: the first bytes of a file (ROS 1 `#ROSBAG
//! V2.0`, MCAP magic, SQLite header) or a ROS 2 bag directory (`metadata.yaml`).

use crate::{mcap_source, ros1, sqlite_source};
use std::io::Read;
use std::path::Path;

/// The bag formats this crate reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum BagFormat {
    /// ROS 1 bag, format 2.0.
    Ros1,
    /// One MCAP file.
    Mcap,
    /// One rosbag2 SQLite file.
    Db3,
    /// A ROS 2 bag directory (metadata.yaml and its files).
    Ros2Directory,
}

/// The format of the file or directory at `path`, `None` when it is not a bag (a Carmen
/// or JSON log, say). A directory without `metadata.yaml` is not a bag.
pub fn detect_bag(path: &Path) -> std::io::Result<Option<BagFormat>> {
    if path.is_dir() {
        return Ok(path
            .join("metadata.yaml")
            .is_file()
            .then_some(BagFormat::Ros2Directory));
    }
    let mut head = [0u8; 16];
    let mut f = std::fs::File::open(path)?;
    let mut n = 0;
    while n < head.len() {
        match f.read(&mut head[n..])? {
            0 => break,
            k => n += k,
        }
    }
    Ok(bag_format_of_head(&head[..n]))
}

/// The bag format announced by the first bytes of a file (16 are enough), `None` for
/// anything else: lets a caller that reads a stream once (a pipe) tell a bag apart.
pub fn bag_format_of_head(head: &[u8]) -> Option<BagFormat> {
    if head.starts_with(ros1::MAGIC) {
        Some(BagFormat::Ros1)
    } else if head.starts_with(mcap_source::MAGIC) {
        Some(BagFormat::Mcap)
    } else if head.starts_with(sqlite_source::MAGIC) {
        Some(BagFormat::Db3)
    } else if head.starts_with(b"#ROSBAG") {
        // Another ROS 1 version: the reader says which.
        Some(BagFormat::Ros1)
    } else {
        None
    }
}
