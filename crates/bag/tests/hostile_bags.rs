//! Hostile bags, built by hand: declared sizes and counts that would ask for GiBs,
//! decompression bombs, SQLite files that compute their rows, absurd LaserScan fields
//! and malformed scans among good ones. Each is a clear error (or a skipped and
//! counted message) within a bounded allocation and time, never an abort or a hang.

mod support;

use odocal_bag::{read_bag, scan_bag, BagOptions, DecodeFilter};
use std::time::{Duration, Instant};
use support::alloc_meter::{peak_of, Meter};
use support::ros1_writer::{self as w, SCAN};
use support::temp;

#[global_allocator]
static METER: Meter = Meter;

const MIB: usize = 1 << 20;

fn write(name: &str, bytes: &[u8]) -> std::path::PathBuf {
    let p = temp(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

#[test]
fn a_ros1_chunk_declaring_a_gib_is_refused_before_allocating_it() {
    // Before: the chunk's declared size (≤ 1 GiB) was reserved up front.
    let mut records = w::connection(0, "/joint_states", "sensor_msgs/JointState");
    records.extend(w::message(0, 1.0, &w::joint_state(1.0, &["a"], &[0.0])));
    let mut bag = w::bag_start();
    bag.extend(w::chunk("bz2", &records, Some(1 << 30)));
    let path = write("gib-chunk.bag", &bag);
    let (r, peak) = peak_of(|| scan_bag(&path, DecodeFilter::default()));
    let e = r.unwrap_err().to_string();
    assert!(e.contains("declares 1073741824 bytes"), "{e}");
    // The chunk follows the magic (13 bytes) and the bag header record (77).
    assert!(e.contains("(at byte 90)"), "{e}");
    assert!(peak < 32 * MIB, "peak {} MiB", peak / MIB);
    std::fs::remove_file(path).unwrap();
}

#[test]
fn a_bz2_bomb_of_joint_names_is_refused_within_a_bounded_allocation() {
    // 3 M empty joint names (12 MB of zeros) compress to a few KB. Before: 3 M names
    // became 48 MB of string slices and 72 MB of joint values per message.
    let n = 3_000_000u32;
    let mut body = Vec::new();
    body.extend([0u8; 12]);
    body.extend(4u32.to_le_bytes());
    body.extend(b"base");
    body.extend(n.to_le_bytes());
    body.resize(body.len() + 4 * n as usize, 0);
    body.extend([0u8; 12]); // position, velocity, effort: empty
    let mut records = w::connection(0, "/joint_states", "sensor_msgs/JointState");
    records.extend(w::message(0, 1.0, &body));
    let mut bag = w::bag_start();
    bag.extend(w::chunk("bz2", &records, None));
    assert!(bag.len() < 20_000, "{} bytes", bag.len());
    let path = write("names-bomb.bag", &bag);
    let (r, peak) = peak_of(|| scan_bag(&path, DecodeFilter::default()));
    let e = r.unwrap_err().to_string();
    assert!(e.contains("/joint_states"), "{e}");
    assert!(e.contains("field `name`"), "{e}");
    assert!(e.contains("more than the 1048576"), "{e}");
    assert!(e.contains("received at 1.000000000 s"), "{e}");
    assert!(peak < 48 * MIB, "peak {} MiB", peak / MIB);
    std::fs::remove_file(path).unwrap();
}

#[test]
fn a_bz2_bomb_of_rays_is_refused_by_its_declared_size() {
    // A scan of 20 M rays: an 80 MB chunk that bz2 packs into a few KB. Before: read and
    // kept (160 MB and more; 250 M rays aborted after 4.75 GiB).
    let mut records = w::connection(0, "/scan", "sensor_msgs/LaserScan");
    records.extend(w::message(
        0,
        1.1,
        &w::laser_scan(1.1, &SCAN, &vec![0.0; 20_000_000]),
    ));
    let mut bag = w::bag_start();
    bag.extend(w::chunk("bz2", &records, None));
    drop(records);
    assert!(bag.len() < 20_000, "{} bytes", bag.len());
    let path = write("rays-bomb.bag", &bag);
    let (r, peak) = peak_of(|| scan_bag(&path, DecodeFilter::default()));
    let e = r.unwrap_err().to_string();
    assert!(e.contains("a chunk declares 80000"), "{e}");
    assert!(peak < 32 * MIB, "peak {} MiB", peak / MIB);
    std::fs::remove_file(path).unwrap();
}

#[test]
fn many_small_bombs_stop_at_the_total_decompression_limit() {
    // 80 chunks of 15 MiB of zeros (an uncounted topic: never decoded) in a few KB.
    // Before: all decompressed (1.2 GB; a bag of thousands of them took hours).
    let mut first = w::connection(0, "/blob", "std_msgs/String");
    let message = w::message(0, 1.0, &vec![0u8; 15 << 20]);
    first.extend(&message);
    let mut bag = w::bag_start();
    bag.extend(w::chunk("bz2", &first, None));
    let next = w::chunk("bz2", &message, None);
    drop(message);
    for _ in 0..79 {
        bag.extend(&next);
    }
    assert!(bag.len() < 100_000, "{} bytes", bag.len());
    let path = write("many-bombs.bag", &bag);
    let started = Instant::now();
    let (r, peak) = peak_of(|| scan_bag(&path, DecodeFilter::default()));
    let e = r.unwrap_err().to_string();
    assert!(e.contains("the chunks up to here decompress to"), "{e}");
    assert!(peak < 48 * MIB, "peak {} MiB", peak / MIB);
    eprintln!("refused after {:?}", started.elapsed());
    std::fs::remove_file(path).unwrap();
}

#[test]
fn a_tiny_mcap_declaring_a_gib_record_allocates_little() {
    // Magic, then a record of opcode 0x80 declaring 1 GiB, then nothing. Before: the
    // reader's buffer was grown to the declared length (1 GiB) before reading.
    let mut b = b"\x89MCAP0\r\n".to_vec();
    b.push(0x80);
    b.extend((1u64 << 30).to_le_bytes());
    b.extend([0u8; 200]);
    let path = write("gib-record.mcap", &b);
    let (r, peak) = peak_of(|| scan_bag(&path, DecodeFilter::default()));
    let e = r.unwrap_err().to_string();
    assert!(e.contains("gib-record.mcap"), "{e}");
    assert!(peak < 32 * MIB, "peak {} MiB", peak / MIB);
    std::fs::remove_file(path).unwrap();
}

#[test]
fn an_mcap_schema_declaring_a_huge_string_allocates_little() {
    // A schema record whose `encoding` string declares 3 GiB (found by the fuzz loop
    // in the fixture's summary section). Before: parsed by the mcap crate, which
    // reserved the declared length: 3.2 GiB.
    let mut schema = Vec::new();
    schema.extend(1u16.to_le_bytes()); // id
    let name = "sensor_msgs/msg/LaserScan";
    schema.extend((name.len() as u32).to_le_bytes());
    schema.extend(name.as_bytes());
    schema.extend(0xc000_0000u32.to_le_bytes()); // encoding: 3 GiB
    schema.extend([0u8; 16]);
    let mut b = b"\x89MCAP0\r\n".to_vec();
    b.push(0x03); // schema
    b.extend((schema.len() as u64).to_le_bytes());
    b.extend(&schema);
    let path = write("huge-string.mcap", &b);
    let (r, peak) = peak_of(|| scan_bag(&path, DecodeFilter::default()));
    let e = r.unwrap_err().to_string();
    assert!(e.contains("huge-string.mcap"), "{e}");
    assert!(peak < 32 * MIB, "peak {} MiB", peak / MIB);
    std::fs::remove_file(path).unwrap();
}

/// A `.db3` with a `topics` table and `messages` made by `messages_sql`.
fn db3(name: &str, messages_sql: &str) -> std::path::PathBuf {
    let path = temp(name);
    let _ = std::fs::remove_file(&path);
    let db = rusqlite::Connection::open(&path).unwrap();
    db.execute_batch(&format!(
        "CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT, type TEXT, \
         serialization_format TEXT, offered_qos_profiles TEXT);
         INSERT INTO topics VALUES (1, '/scan', 'sensor_msgs/msg/LaserScan', 'cdr', '');
         {messages_sql}"
    ))
    .unwrap();
    path
}

/// Reads `path` on another thread; `None` when it takes longer than `limit`.
fn read_within(path: &std::path::Path, limit: Duration) -> Option<Result<(), String>> {
    let p = path.to_path_buf();
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let r = scan_bag(&p, DecodeFilter::default())
            .map(|_| ())
            .map_err(|e| e.to_string());
        let _ = tx.send(r);
    });
    rx.recv_timeout(limit).ok()
}

#[test]
fn sqlite_views_and_generated_columns_are_refused_at_once() {
    let cases = [
        (
            "recursive.db3",
            "CREATE VIEW messages AS WITH RECURSIVE c(x) AS (SELECT 1 UNION ALL SELECT x + 1 \
             FROM c) SELECT x AS id, 1 AS topic_id, x AS timestamp, x'00' AS data FROM c;",
            "is a view",
        ),
        (
            "zeroblob.db3",
            "CREATE VIEW messages AS SELECT 1 AS id, 1 AS topic_id, 0 AS timestamp, \
             zeroblob(2000000000) AS data;",
            "is a view",
        ),
        (
            "generated.db3",
            "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER, timestamp \
             INTEGER, data BLOB AS (zeroblob(1000000000)) VIRTUAL); \
             INSERT INTO messages(id, topic_id, timestamp) VALUES (1, 1, 0);",
            "generated or hidden column `data`",
        ),
    ];
    for (name, sql, why) in cases {
        let path = db3(name, sql);
        let started = Instant::now();
        let r = read_within(&path, Duration::from_secs(10))
            .unwrap_or_else(|| panic!("{name}: still reading after 10 s"));
        let e = r.unwrap_err();
        assert!(e.contains(why), "{name}: {e}");
        assert!(started.elapsed() < Duration::from_secs(5), "{name}");
        std::fs::remove_file(path).unwrap();
    }
}

#[test]
fn a_sqlite_value_of_the_wrong_type_is_named() {
    // Before: "SQLite: Invalid column type Text at index: 2, name: data".
    let path = db3(
        "text-data.db3",
        "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER, timestamp INTEGER, \
         data BLOB); INSERT INTO messages VALUES (7, 1, 5, 'not a blob');",
    );
    let e = scan_bag(&path, DecodeFilter::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("message id 7 of topic /scan"), "{e}");
    assert!(e.contains("column `data` is text, expected a blob"), "{e}");
    std::fs::remove_file(path).unwrap();
}

#[test]
fn one_malformed_scan_is_skipped_and_counted() {
    // Scan 3 has 5 ranges where its angles make 11 (the mines bag's 36-for-361).
    let bag = w::small_bag(40, &|k, t| {
        (k == 3).then(|| w::laser_scan(t, &SCAN, &[1.0; 5]))
    });
    let path = write("one-bad-scan.bag", &bag);
    let b = read_bag(&path, &BagOptions::default()).unwrap();
    assert_eq!(b.log.scans.len(), 39);
    let warning = b
        .log
        .stats
        .warnings
        .iter()
        .find(|w| w.contains("malformed"))
        .expect("a warning");
    assert!(
        warning.contains("topic /scan: 1 malformed scan message(s) skipped"),
        "{warning}"
    );
    assert!(
        warning.contains("message 3, received at 100.300000000 s"),
        "{warning}"
    );
    assert!(warning.contains("5 ranges"), "{warning}");
    std::fs::remove_file(path).unwrap();
}

#[test]
fn a_truncated_scan_is_skipped_and_counted() {
    let bag = w::small_bag(40, &|k, t| {
        (k == 7).then(|| w::laser_scan(t, &SCAN, &[1.0; 11])[..40].to_vec())
    });
    let path = write("cut-scan.bag", &bag);
    let b = read_bag(&path, &BagOptions::default()).unwrap();
    assert_eq!(b.log.scans.len(), 39);
    let w = b.log.stats.warnings.join("\n");
    assert!(
        w.contains("1 malformed scan message(s) skipped, the first (message 7"),
        "{w}"
    );
    assert!(w.contains("cannot be decoded"), "{w}");
    std::fs::remove_file(path).unwrap();
}

#[test]
fn absurd_scan_fields_are_refused_by_name_not_blamed_on_timing() {
    let mut cases: Vec<(&str, w::Scan)> = Vec::new();
    let mut s = SCAN;
    s.time_increment = f32::NAN;
    cases.push(("time_increment NaN", s));
    s = SCAN;
    s.time_increment = 1e3;
    cases.push(("time_increment 1000", s));
    s = SCAN;
    s.range_min = f32::INFINITY;
    cases.push(("range_min inf", s));
    s = SCAN;
    s.range_max = f32::NAN;
    cases.push(("range_max NaN", s));
    s = SCAN;
    s.angle_min = -1e30;
    cases.push(("angle_min -1000000000000000000000000000000", s));
    for (what, fields) in cases {
        let bag = w::small_bag(20, &|_, t| Some(w::laser_scan(t, &fields, &[1.0; 11])));
        let path = write("absurd.bag", &bag);
        let e = read_bag(&path, &BagOptions::default())
            .unwrap_err()
            .to_string();
        assert!(e.contains(what), "{what}: {e}");
        assert!(e.contains("20 malformed scan message(s)"), "{what}: {e}");
        assert!(e.contains("no usable scan remains"), "{what}: {e}");
        std::fs::remove_file(path).unwrap();
    }
}

#[test]
fn a_file_shorter_than_the_ros1_magic_names_what_was_expected() {
    // Before: "failed to fill whole buffer".
    let path = write("short.bag", b"#ROSBAG V2");
    let e = scan_bag(&path, DecodeFilter::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("#ROSBAG V2.0"), "{e}");
    assert!(!e.contains("fill whole buffer"), "{e}");
    std::fs::remove_file(path).unwrap();
}
