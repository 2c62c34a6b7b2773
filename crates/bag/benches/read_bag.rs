//! Reading the committed fixture bags (fixtures/bags/, written by Python `rosbags`) into
//! the log model with `read_bag`: one streaming pass, the topic choice, the log. One
//! bag per container and chunk compression: ROS 1 uncompressed, lz4 and bz2 chunks,
//! MCAP, ROS 2 SQLite (`.db3`) and a ROS 2 bag directory. The files are read from the
//! page cache (warm after the first iteration). Throughput is bytes of bag per second.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use odocal_bag::{read_bag, BagOptions};
use std::hint::black_box;
use std::path::{Path, PathBuf};

/// The fixture bags: (benchmark name, path under fixtures/bags).
const BAGS: [(&str, &str); 6] = [
    ("ros1_uncompressed", "khepera_ros1_plain_cw.bag"),
    ("ros1_lz4", "khepera_ros1_lz4.bag"),
    ("ros1_bz2", "pioneer_sick_bz2.bag"),
    ("mcap", "khepera_mcap.mcap"),
    ("ros2_db3", "khepera_db3_velocity.db3"),
    ("ros2_directory", "khepera_ros2_dir"),
];

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/bags")
        .join(name)
}

/// Bytes of the file, or of every file in the directory.
fn size(path: &Path) -> u64 {
    if path.is_dir() {
        std::fs::read_dir(path)
            .expect("bag directory")
            .map(|e| e.expect("entry").metadata().expect("metadata").len())
            .sum()
    } else {
        path.metadata().expect("bag file").len()
    }
}

fn read(c: &mut Criterion) {
    let mut group = c.benchmark_group("read_bag");
    group.sample_size(20);
    for (name, file) in BAGS {
        let path = fixture(file);
        let bytes = size(&path);
        let log = read_bag(&path, &BagOptions::default())
            .expect("fixture bag reads")
            .log;
        eprintln!(
            "{file}: {bytes} bytes, {} scans, {} encoder records",
            log.scans.len(),
            log.encoders.len()
        );
        group.throughput(Throughput::Bytes(bytes));
        group.bench_function(name, |b| {
            b.iter(|| {
                let bag =
                    read_bag(black_box(&path), &BagOptions::default()).expect("fixture bag reads");
                assert!(!bag.log.scans.is_empty());
                bag
            })
        });
    }
    group.finish();
}

criterion_group!(benches, read);
criterion_main!(benches);
