//! Where a result came from: the command line, the odocal version, the input's
//! SHA-256 and the time the whole run took — so a report can be traced to its log.

use serde::Serialize;
use sha2::{Digest, Sha256};
use std::fs::File;
use std::io::{self, Read};
use std::path::Path;

/// The run behind a report.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Provenance {
    /// The command line, arguments joined by spaces.
    pub command_line: String,
    /// The odocal version.
    pub version: String,
    /// SHA-256 of the input log, lower-case hex (of a directory such as a ROS 2 bag:
    /// see [`sha256_of_input`]).
    pub input_sha256: String,
    /// Size of the input log (bytes; of a directory, its files').
    pub input_bytes: u64,
    /// Wall time of the whole run up to the report (s).
    pub wall_time_s: f64,
}

/// SHA-256 (lower-case hex) and size of the input at `path`: a file's bytes, or for
/// a directory (a ROS 2 bag: `metadata.yaml` and its storage files) its regular files
/// in name order, each hashed as its name, a NUL byte, its size (8 bytes,
/// little-endian) and its bytes; the size is then the files' total. Sub-directories
/// are not entered (a bag directory has none).
pub fn sha256_of_input(path: &Path) -> io::Result<(String, u64)> {
    let mut hasher = Sha256::new();
    let bytes = if path.is_dir() {
        let mut files = Vec::new();
        for entry in std::fs::read_dir(path)? {
            let entry = entry?;
            if entry.file_type()?.is_file() {
                files.push(entry.path());
            }
        }
        files.sort();
        let mut total = 0;
        for file in &files {
            let name = file.file_name().unwrap_or_default();
            hasher.update(name.as_encoded_bytes());
            hasher.update([0u8]);
            hasher.update(std::fs::metadata(file)?.len().to_le_bytes());
            total += hash_file(file, &mut hasher)?;
        }
        total
    } else {
        hash_file(path, &mut hasher)?
    };
    Ok((hex(hasher.finalize().as_slice()), bytes))
}

/// Feeds the file at `path` to `hasher`; returns its size.
fn hash_file(path: &Path, hasher: &mut Sha256) -> io::Result<u64> {
    let mut reader = Sha256Reader {
        inner: File::open(path)?,
        hasher: std::mem::take(hasher),
        bytes: 0,
    };
    io::copy(&mut reader, &mut io::sink())?;
    *hasher = reader.hasher;
    Ok(reader.bytes)
}

/// A reader that computes the SHA-256 and size of everything read through it: the
/// checksum of an input read once (a pipe, standard input) while it is parsed.
pub struct Sha256Reader<R> {
    inner: R,
    hasher: Sha256,
    bytes: u64,
}

impl<R: Read> Sha256Reader<R> {
    /// Wraps `inner`.
    pub fn new(inner: R) -> Self {
        Sha256Reader {
            inner,
            hasher: Sha256::new(),
            bytes: 0,
        }
    }

    /// Reads the rest of the input, then returns the SHA-256 (lower-case hex) and size
    /// of all of it, as [`sha256_of_input`] gives for a file.
    pub fn finish(mut self) -> io::Result<(String, u64)> {
        io::copy(&mut self, &mut io::sink())?;
        Ok((hex(self.hasher.finalize().as_slice()), self.bytes))
    }
}

impl<R: Read> Read for Sha256Reader<R> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        let n = self.inner.read(buf)?;
        self.hasher.update(&buf[..n]);
        self.bytes += n as u64;
        Ok(n)
    }
}

/// `bytes` as lower-case hex.
fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sha256_matches_the_standard_test_vector() {
        let path = std::env::temp_dir().join(format!("odocal-sha-{}", std::process::id()));
        std::fs::write(&path, b"abc").unwrap();
        let (hex, n) = sha256_of_input(&path).unwrap();
        std::fs::remove_file(&path).unwrap();
        assert_eq!(n, 3);
        assert_eq!(
            hex,
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
        );
    }

    #[test]
    fn a_stream_hashes_as_the_same_bytes_in_a_file() {
        let path = std::env::temp_dir().join(format!("odocal-sha-s-{}", std::process::id()));
        std::fs::write(&path, b"abcdef").unwrap();
        let of_file = sha256_of_input(&path).unwrap();
        std::fs::remove_file(&path).unwrap();
        let mut r = Sha256Reader::new(&b"abcdef"[..]);
        let mut first = [0u8; 2];
        r.read_exact(&mut first).unwrap();
        assert_eq!(r.finish().unwrap(), of_file);
    }

    #[test]
    fn a_directory_hashes_its_files_in_name_order_with_their_names() {
        let dir = std::env::temp_dir().join(format!("odocal-sha-dir-{}", std::process::id()));
        std::fs::create_dir_all(dir.join("sub")).unwrap();
        std::fs::write(dir.join("b.db3"), b"bb").unwrap();
        std::fs::write(dir.join("a.yaml"), b"a").unwrap();
        let (hex, n) = sha256_of_input(&dir).unwrap();
        let mut expected = Sha256::new();
        for (name, body) in [("a.yaml", &b"a"[..]), ("b.db3", &b"bb"[..])] {
            expected.update(name.as_bytes());
            expected.update([0u8]);
            expected.update((body.len() as u64).to_le_bytes());
            expected.update(body);
        }
        let expected: String = expected
            .finalize()
            .iter()
            .map(|b| format!("{b:02x}"))
            .collect();
        // Renaming a file changes the checksum; the sub-directory is not entered.
        std::fs::rename(dir.join("b.db3"), dir.join("c.db3")).unwrap();
        let (renamed, _) = sha256_of_input(&dir).unwrap();
        std::fs::remove_dir_all(&dir).unwrap();
        assert_eq!((hex.as_str(), n), (expected.as_str(), 3));
        assert_ne!(renamed, hex);
    }
}
