//! zstd-compressed ROS 2 data (`ros2 bag record --compression-format zstd`): one
//! message's serialized data (`compression_mode: MESSAGE`) decompressed in memory, or
//! a whole `.db3.zstd`/`.mcap.zstd` file (`FILE`) into a temporary file that is
//! removed when dropped. Both are bounded whatever the frames declare.

use crate::error::BagError;
use crate::limits::MAX_CHUNK_BYTES;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// Decompresses one message's zstd frame, at most [`MAX_CHUNK_BYTES`].
pub(crate) fn decompress_message(body: &[u8]) -> Result<Vec<u8>, String> {
    let mut out = Vec::with_capacity(body.len().saturating_mul(4).min(1 << 20));
    let decoder =
        zstd::stream::read::Decoder::new(body).map_err(|e| format!("not a zstd frame: {e}"))?;
    decoder
        .take(MAX_CHUNK_BYTES + 1)
        .read_to_end(&mut out)
        .map_err(|e| format!("the message's zstd frame does not decompress: {e}"))?;
    if out.len() as u64 > MAX_CHUNK_BYTES {
        return Err(format!(
            "the message's zstd frame decompresses to more than {} MiB",
            MAX_CHUNK_BYTES >> 20
        ));
    }
    Ok(out)
}

/// Most bytes a compressed file may decompress to: 100 times its size, at least 1 GiB
/// and at most 64 GiB (real bags compress 2 to 10 times).
fn file_limit(compressed: u64) -> u64 {
    compressed.saturating_mul(100).clamp(1 << 30, 64 << 30)
}

/// A decompressed copy of a bag file, deleted when dropped.
#[derive(Debug)]
pub(crate) struct DecompressedFile {
    /// Where the copy is.
    pub(crate) path: PathBuf,
}

impl Drop for DecompressedFile {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.path);
    }
}

/// Decompresses the zstd file `path` into a new temporary file (never replacing one).
pub(crate) fn decompress_file(path: &Path) -> Result<DecompressedFile, BagError> {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let name = path.display().to_string();
    let input = std::fs::File::open(path).map_err(|e| BagError::io(&name, e))?;
    let len = input.metadata().map_err(|e| BagError::io(&name, e))?.len();
    let stem = path
        .file_name()
        .and_then(|n| n.to_str())
        .and_then(|n| n.strip_suffix(".zstd"))
        .unwrap_or("bag");
    let tmp = std::env::temp_dir().join(format!(
        "odocal-{}-{}-{stem}",
        std::process::id(),
        COUNTER.fetch_add(1, Ordering::Relaxed)
    ));
    let out = std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(&tmp)
        .map_err(|e| BagError::io(&tmp.display().to_string(), e))?;
    let copy = DecompressedFile { path: tmp };
    let limit = file_limit(len);
    let decoder = zstd::stream::read::Decoder::new(input).map_err(|e| BagError::io(&name, e))?;
    let mut writer = std::io::BufWriter::new(out);
    let written = std::io::copy(&mut decoder.take(limit + 1), &mut writer).map_err(|e| {
        BagError::format(
            &name,
            None,
            format!("the file does not decompress as zstd: {e}"),
            "the bag file is damaged or not zstd; `ros2 bag decompress` tells which",
        )
    })?;
    if written > limit {
        return Err(BagError::format(
            &name,
            None,
            format!(
                "the file decompresses to more than {} MiB ({}× its size)",
                limit >> 20,
                limit / len.max(1)
            ),
            "the bag file is damaged or hostile; decompress it yourself (`ros2 bag \
             decompress`) if you trust it",
        ));
    }
    std::io::Write::flush(&mut writer)
        .map_err(|e| BagError::io(&copy.path.display().to_string(), e))?;
    Ok(copy)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_message_frame_round_trips() {
        let data: Vec<u8> = (0..1000u32).flat_map(|v| v.to_le_bytes()).collect();
        let frame = zstd::stream::encode_all(&data[..], 3).unwrap();
        assert_eq!(decompress_message(&frame).unwrap(), data);
        assert!(decompress_message(&data[..100]).is_err());
    }

    #[test]
    fn a_message_bomb_stops_at_the_cap() {
        // 300 MiB of zeros compress to a few KB.
        let mut enc = zstd::stream::write::Encoder::new(Vec::new(), 19).unwrap();
        let block = vec![0u8; 1 << 20];
        for _ in 0..300 {
            std::io::Write::write_all(&mut enc, &block).unwrap();
        }
        let frame = enc.finish().unwrap();
        assert!(frame.len() < 100_000, "{}", frame.len());
        let err = decompress_message(&frame).unwrap_err();
        assert!(err.contains("more than 256 MiB"), "{err}");
    }
}
