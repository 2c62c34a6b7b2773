//! A deterministic mutational fuzz loop over every bag reader (ROS 1 plain, lz4, bz2;
//! MCAP; SQLite; ROS 2 directories, zstd FILE and MESSAGE): byte flips, truncations and
//! size fields inflated (a little-endian u32 or u64 set to a large value), from a fixed
//! seed. Each mutant must give `Ok` or `Err`: no panic, at most [`PEAK_BOUND`] bytes
//! held by the reading thread, and at most [`TIME_BOUND`] per read.
//!
//! `ODOCAL_BAG_FUZZ_ITERS` sets the mutants per reader (default 40, a few seconds in
//! all); `ODOCAL_BAG_FUZZ_SEED` the seed. docs/bag-limits.md has the longer run.

mod support;

use odocal_bag::{scan_bag, DecodeFilter};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};
use support::alloc_meter::{peak_of, Meter};
use support::{fixture, temp};

#[global_allocator]
static METER: Meter = Meter;

/// Most bytes one read may hold: the 256 MiB chunk cap is never reached by a
/// mutant of a fixture (they are under 1 MB: their chunks may expand to 64 MiB).
const PEAK_BOUND: usize = 192 << 20;
/// Longest one read may take.
const TIME_BOUND: Duration = Duration::from_secs(10);

/// A xorshift generator: the same mutants on every run of a seed.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        let mut x = self.0;
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        self.0 = x;
        x
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

fn env_or(name: &str, default: u64) -> u64 {
    std::env::var(name)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

/// One mutation of `b`: 1–4 byte flips, a truncation, or an inflated size field.
fn mutate(b: &mut Vec<u8>, rng: &mut Rng) {
    if b.is_empty() {
        return;
    }
    match rng.below(4) {
        0 => {
            for _ in 0..1 + rng.below(4) {
                let i = rng.below(b.len());
                b[i] ^= 1 + rng.below(255) as u8;
            }
        }
        1 => {
            let keep = rng.below(b.len());
            b.truncate(keep);
        }
        2 => {
            let i = rng.below(b.len().saturating_sub(4));
            let v: u32 = [0x7fff_ffff, 0xffff_ffff, 1 << 24, 1 << 28][rng.below(4)];
            if i + 4 <= b.len() {
                b[i..i + 4].copy_from_slice(&v.to_le_bytes());
            }
        }
        _ => {
            let i = rng.below(b.len().saturating_sub(8));
            let v: u64 = [u64::MAX, 1 << 30, 1 << 40, (b.len() as u64) << 8][rng.below(4)];
            if i + 8 <= b.len() {
                b[i..i + 8].copy_from_slice(&v.to_le_bytes());
            }
        }
    }
}

/// Reads `path` as a bag, checking the bounds; returns whether it was an error and
/// the most bytes held.
fn read_bounded(path: &Path, what: &str) -> (bool, usize) {
    let started = Instant::now();
    let (r, peak) =
        peak_of(|| std::panic::catch_unwind(|| scan_bag(path, DecodeFilter::default()).is_err()));
    let took = started.elapsed();
    let err = r.unwrap_or_else(|_| panic!("{what}: the reader panicked"));
    assert!(peak <= PEAK_BOUND, "{what}: held {} MiB", peak >> 20);
    assert!(took <= TIME_BOUND, "{what}: took {took:?}");
    (err, peak)
}

/// Fuzzes one file of `bag` (a file, or a directory whose file `inner` is mutated).
fn fuzz(bag: &str, inner: Option<&str>, salt: u64) {
    let iters = env_or("ODOCAL_BAG_FUZZ_ITERS", 40);
    let mut rng = Rng(env_or("ODOCAL_BAG_FUZZ_SEED", 0x0d0c_a15e) ^ salt.wrapping_mul(0x9e37_79b9));
    let src = fixture(bag);
    let work: PathBuf = temp(&format!("fuzz-{bag}"));
    let _ = std::fs::remove_dir_all(&work);
    let (target, original) = match inner {
        Some(file) => {
            std::fs::create_dir_all(&work).unwrap();
            for e in std::fs::read_dir(&src).unwrap() {
                let e = e.unwrap();
                std::fs::copy(e.path(), work.join(e.file_name())).unwrap();
            }
            (work.join(file), std::fs::read(src.join(file)).unwrap())
        }
        None => (work.clone(), std::fs::read(&src).unwrap()),
    };
    let read_path = if inner.is_some() {
        work.clone()
    } else {
        target.clone()
    };
    let (mut errors, mut most) = (0, 0);
    for k in 0..iters {
        let mut b = original.clone();
        for _ in 0..1 + rng.below(2) {
            mutate(&mut b, &mut rng);
        }
        std::fs::write(&target, &b).unwrap();
        let (err, peak) = read_bounded(&read_path, &format!("{bag} mutant {k}"));
        errors += usize::from(err);
        most = most.max(peak);
    }
    eprintln!(
        "{bag}: {iters} mutants, {errors} refused, at most {:.1} MiB held",
        most as f64 / (1 << 20) as f64
    );
    if inner.is_some() {
        std::fs::remove_dir_all(&work).unwrap();
    } else {
        std::fs::remove_file(&work).unwrap();
    }
}

#[test]
fn fuzz_ros1_plain() {
    fuzz("khepera_ros1_plain_cw.bag", None, 1);
}

#[test]
fn fuzz_ros1_lz4() {
    fuzz("khepera_ros1_lz4.bag", None, 2);
}

#[test]
fn fuzz_ros1_bz2() {
    fuzz("khepera_ros1_bz2_odom.bag", None, 3);
}

#[test]
fn fuzz_mcap() {
    fuzz("khepera_mcap.mcap", None, 4);
}

#[test]
fn fuzz_db3() {
    fuzz("khepera_db3_velocity.db3", None, 5);
}

#[test]
fn fuzz_ros2_directory_metadata() {
    fuzz("khepera_ros2_dir", Some("metadata.yaml"), 6);
}

#[test]
fn fuzz_zstd_file_bag() {
    fuzz(
        "khepera_db3_zstd_file",
        Some("khepera_db3_zstd_file.db3.zstd"),
        7,
    );
}

#[test]
fn fuzz_zstd_message_bag() {
    fuzz(
        "khepera_mcap_zstd_message",
        Some("khepera_mcap_zstd_message.mcap"),
        8,
    );
}
