//! Shared by the hostile-input tests: a counting allocator, fixture paths, and a
//! minimal ROS 1 bag writer for hand-built (hostile) bags.

#![allow(dead_code)]

pub mod alloc_meter;
pub mod ros1_writer;

use std::path::{Path, PathBuf};

/// A fixture bag of fixtures/bags/.
pub fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/bags")
        .join(name)
}

/// A temporary path unique to this process and `name`.
pub fn temp(name: &str) -> PathBuf {
    std::env::temp_dir().join(format!("odocal-hostile-{}-{name}", std::process::id()))
}
