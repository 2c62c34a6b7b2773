//! MCAP chunks compressed with zstd and lz4 (the fixture MCAP rewritten by Foxglove's
//! own writer, an implementation independent of the reader's decoding path) read to the
//! same messages as the uncompressed original; and no byte damage to a bag makes the
//! reader panic (proptest over truncations and byte flips of every fixture format).

use odocal_bag::{read_bag, scan_bag, BagOptions, DecodeFilter};
use proptest::prelude::*;
use std::path::{Path, PathBuf};

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/bags")
        .join(name)
}

fn temp(name: &str) -> PathBuf {
    std::env::temp_dir().join(format!("odocal-bag-test-{}-{name}", std::process::id()))
}

/// Rewrites the fixture MCAP with `compression` chunks into a temporary file.
fn rewrite(compression: mcap::Compression, name: &str) -> PathBuf {
    let bytes = std::fs::read(fixture("khepera_mcap.mcap")).unwrap();
    let path = temp(name);
    let file = std::io::BufWriter::new(std::fs::File::create(&path).unwrap());
    let mut w = mcap::WriteOptions::new()
        .compression(Some(compression))
        .chunk_size(Some(64 * 1024))
        .create(file)
        .unwrap();
    for m in mcap::MessageStream::new(&bytes).unwrap() {
        w.write(&m.unwrap()).unwrap();
    }
    w.finish().unwrap();
    drop(w);
    path
}

#[test]
fn zstd_and_lz4_chunks_read_the_same_as_uncompressed() {
    let original = read_bag(&fixture("khepera_mcap.mcap"), &BagOptions::default()).unwrap();
    for (c, name) in [
        (mcap::Compression::Zstd, "zstd.mcap"),
        (mcap::Compression::Lz4, "lz4.mcap"),
    ] {
        let path = rewrite(c, name);
        let copy = read_bag(&path, &BagOptions::default()).unwrap();
        assert_eq!(copy.log.scans, original.log.scans, "{name}");
        assert_eq!(copy.log.encoders, original.log.encoders, "{name}");
        assert!(
            copy.bytes_read < original.bytes_read,
            "{name} is compressed"
        );
        // A flipped byte inside a compressed chunk fails its CRC or its decompression.
        let mut bytes = std::fs::read(&path).unwrap();
        let n = bytes.len();
        bytes[n / 2] ^= 0x5a;
        std::fs::write(&path, &bytes).unwrap();
        let e = read_bag(&path, &BagOptions::default())
            .unwrap_err()
            .to_string();
        assert!(e.contains(&path.display().to_string()), "{e}");
        let _ = std::fs::remove_file(path);
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]
    #[test]
    fn damaged_bags_are_errors_not_panics(
        which in 0usize..4,
        cut in 0.0f64..1.0,
        flips in proptest::collection::vec((0.0f64..1.0, any::<u8>()), 0..4),
    ) {
        let names = [
            "khepera_ros1_lz4.bag",
            "khepera_ros1_bz2_odom.bag",
            "khepera_mcap.mcap",
            "khepera_db3_velocity.db3",
        ];
        let mut bytes = std::fs::read(fixture(names[which])).unwrap();
        for (at, x) in flips {
            let i = (at * bytes.len() as f64) as usize % bytes.len();
            bytes[i] ^= x;
        }
        let keep = ((cut * 1.2).min(1.0) * bytes.len() as f64) as usize;
        bytes.truncate(keep);
        let path = temp(&format!("fuzz-{which}-{}", names[which]));
        std::fs::write(&path, &bytes).unwrap();
        // Either outcome is fine; a panic is not.
        let _ = scan_bag(&path, DecodeFilter::default());
        let _ = read_bag(&path, &BagOptions::default());
        let _ = std::fs::remove_file(path);
    }
}
