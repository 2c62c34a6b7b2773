//! The memory and time budget of reading one bag, whatever its files declare.
//!
//! Every size a bag declares is checked against these caps (and, where the bytes are
//! stored as they are, against the file's size) before anything is allocated:
//! - one ROS 1 or MCAP chunk or record, decompressed: at most [`chunk_limit`] (64
//!   times the file's size, 16 MiB to [`MAX_CHUNK_BYTES`]); one zstd-compressed
//!   ROS 2 message: at most [`MAX_CHUNK_BYTES`];
//! - all chunks of a file together, decompressed: at most
//!   [`total_decompressed_limit`] (64 times the file's size, at least 1 GiB);
//! - one message sequence (ranges, joint names, positions, …): at most
//!   [`MAX_SEQUENCE_LEN`] elements, and never more than the bytes that follow;
//! - everything kept from the decoded messages (ranges, joint values, odometry): at
//!   most [`MAX_DECODED_BYTES`];
//! - `metadata.yaml`: at most [`MAX_METADATA_BYTES`];
//! - SQLite: blobs and strings at most [`MAX_CHUNK_BYTES`], and the queries stop after
//!   [`sqlite_time_limit`].

use std::time::Duration;

/// Largest decompressed chunk (ROS 1, MCAP), zstd frame or zstd-compressed file
/// accepted: 256 MiB (rosbag's default chunk is 768 KiB, MCAP's 4 MiB; a chunk holding
/// one large image is tens of MB).
pub const MAX_CHUNK_BYTES: u64 = 256 << 20;

/// Largest decompressed chunk or record accepted in a file of `file_len` bytes: 64
/// times the file's size (sensor data compresses 2 to 10 times), at least 16 MiB and
/// at most [`MAX_CHUNK_BYTES`]. A few-KB file cannot expand to hundreds of MB.
pub fn chunk_limit(file_len: u64) -> u64 {
    file_len.saturating_mul(64).clamp(16 << 20, MAX_CHUNK_BYTES)
}

/// Most bytes all chunks of a file of `file_len` bytes may decompress to together: 64
/// times the file's size, at least 1 GiB. Keeps the time bounded too: a file of many
/// small decompression bombs stops after a few seconds of decompressing.
pub fn total_decompressed_limit(file_len: u64) -> u64 {
    file_len.saturating_mul(64).max(1 << 30)
}

/// Most bytes kept from decoded messages over the whole bag: 1 GiB (an hour of a
/// 720-ray laser at 40 Hz is about 0.4 GiB).
pub const MAX_DECODED_BYTES: u64 = 1 << 30;

/// Most elements of one sequence in a message (ranges of a scan, joints of a
/// JointState): 2^20, ten times the densest 2-D laser.
pub const MAX_SEQUENCE_LEN: usize = 1 << 20;

/// Largest `metadata.yaml` read (real ones are a few KiB).
pub const MAX_METADATA_BYTES: u64 = 1 << 20;

/// How long the SQLite queries of a `.db3` file of `file_len` bytes may take: 20 s,
/// plus 20 s per GiB (a plain table scan reads well over 100 MiB/s).
pub fn sqlite_time_limit(file_len: u64) -> Duration {
    Duration::from_secs(20 + 20 * (file_len >> 30))
}
