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
    /// SHA-256 of the input log, lower-case hex.
    pub input_sha256: String,
    /// Size of the input log (bytes).
    pub input_bytes: u64,
    /// Wall time of the whole run up to the report (s).
    pub wall_time_s: f64,
}

/// SHA-256 (lower-case hex) and size of the file at `path`.
pub fn sha256_of_file(path: &Path) -> io::Result<(String, u64)> {
    let mut file = File::open(path)?;
    let mut hasher = Sha256::new();
    let mut buf = vec![0u8; 1 << 16];
    let mut bytes = 0u64;
    loop {
        let n = file.read(&mut buf)?;
        if n == 0 {
            break;
        }
        hasher.update(&buf[..n]);
        bytes += n as u64;
    }
    let hex = hasher
        .finalize()
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect();
    Ok((hex, bytes))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sha256_matches_the_standard_test_vector() {
        let path = std::env::temp_dir().join(format!("odocal-sha-{}", std::process::id()));
        std::fs::write(&path, b"abc").unwrap();
        let (hex, n) = sha256_of_file(&path).unwrap();
        std::fs::remove_file(&path).unwrap();
        assert_eq!(n, 3);
        assert_eq!(
            hex,
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
        );
    }
}
