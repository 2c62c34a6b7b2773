//! A ROS 2 bag directory's `metadata.yaml`: its data files in recording order
//! (`relative_file_paths`) and how they are compressed (`compression_mode`,
//! `compression_format`). Read with a size cap; every file it names must lie inside
//! the bag directory.

use crate::error::BagError;
use crate::limits::MAX_METADATA_BYTES;
use std::io::Read;
use std::path::{Component, Path, PathBuf};

/// How a ROS 2 bag's data is compressed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Compression {
    /// Not compressed.
    None,
    /// Each data file is one zstd stream (`NAME.db3.zstd`, `NAME.mcap.zstd`).
    File,
    /// Each message's serialized data is one zstd frame.
    Message,
}

/// What `metadata.yaml` says about the data.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Ros2Metadata {
    /// The data files, in recording order.
    pub(crate) files: Vec<PathBuf>,
    /// Their compression.
    pub(crate) compression: Compression,
}

/// Reads `dir/metadata.yaml`.
pub(crate) fn read_metadata(dir: &Path) -> Result<Ros2Metadata, BagError> {
    let meta = dir.join("metadata.yaml");
    let name = meta.display().to_string();
    let file = std::fs::File::open(&meta).map_err(|e| BagError::io(&name, e))?;
    let mut text = String::new();
    file.take(MAX_METADATA_BYTES + 1)
        .read_to_string(&mut text)
        .map_err(|e| BagError::io(&name, e))?;
    if text.len() as u64 > MAX_METADATA_BYTES {
        return Err(BagError::format(
            &name,
            Some(MAX_METADATA_BYTES),
            format!(
                "metadata.yaml is larger than {} KiB (real ones are a few KiB)",
                MAX_METADATA_BYTES >> 10
            ),
            "the bag directory is damaged; regenerate metadata.yaml with `ros2 bag reindex`",
        ));
    }
    let mut listed = Vec::new();
    let mut in_list: Option<usize> = None;
    let (mut mode, mut format) = (String::new(), String::new());
    for (k, line) in text.lines().enumerate() {
        let indent = line.len() - line.trim_start().len();
        let t = line.trim();
        if let Some(key_indent) = in_list {
            if let Some(item) = t.strip_prefix("- ") {
                if indent >= key_indent {
                    listed.push((k + 1, unquote(item).to_string()));
                    continue;
                }
            }
            if !t.is_empty() {
                in_list = None;
            }
        }
        if t == "relative_file_paths:" {
            in_list = Some(indent);
        } else if let Some(v) = t.strip_prefix("compression_mode:") {
            mode = unquote(v.trim()).to_string();
        } else if let Some(v) = t.strip_prefix("compression_format:") {
            format = unquote(v.trim()).to_string();
        }
    }
    let compression = match mode.to_ascii_uppercase().as_str() {
        "" | "NONE" => Compression::None,
        m @ ("FILE" | "MESSAGE") => {
            if format != "zstd" {
                return Err(BagError::format(
                    &name,
                    None,
                    format!("compression_format `{format}` (odocal reads zstd)"),
                    "decompress the bag first (`ros2 bag decompress`) and read the result",
                ));
            }
            if m == "FILE" {
                Compression::File
            } else {
                Compression::Message
            }
        }
        m => {
            return Err(BagError::format(
                &name,
                None,
                format!("compression_mode `{m}` is not one of NONE, FILE, MESSAGE"),
                "check the bag with `ros2 bag info`",
            ))
        }
    };
    if listed.is_empty() {
        return Err(BagError::format(
            &name,
            None,
            "metadata.yaml lists no files (no `relative_file_paths`)",
            "check that the directory is a complete ROS 2 bag (`ros2 bag info`)",
        ));
    }
    let root = dir.canonicalize().map_err(|e| BagError::io(&name, e))?;
    let mut files = Vec::new();
    for (line, item) in listed {
        let inside = |p: &Path| {
            p.components()
                .all(|c| matches!(c, Component::Normal(_) | Component::CurDir))
        };
        let rel = Path::new(&item);
        if !inside(rel) {
            return Err(BagError::format(
                &name,
                None,
                format!(
                    "line {line}: relative_file_paths names `{item}`, which is not a path \
                     inside the bag directory"
                ),
                "a bag directory may only name its own files; check where this bag came from",
            ));
        }
        let path = dir.join(rel);
        // A compressed bag may list the names before compression.
        let path = match (compression, path.is_file()) {
            (Compression::File, false) => {
                let mut z = path.clone().into_os_string();
                z.push(".zstd");
                PathBuf::from(z)
            }
            _ => path,
        };
        if !path.is_file() {
            return Err(BagError::format(
                &name,
                None,
                format!(
                    "line {line}: metadata.yaml lists {} which does not exist",
                    path.display()
                ),
                "copy the whole bag directory, every split file included",
            ));
        }
        let real = path.canonicalize().map_err(|e| BagError::io(&name, e))?;
        if !real.starts_with(&root) {
            return Err(BagError::format(
                &name,
                None,
                format!(
                    "line {line}: `{item}` leads outside the bag directory (to {})",
                    real.display()
                ),
                "a bag directory may only name its own files; check where this bag came from",
            ));
        }
        files.push(path);
    }
    Ok(Ros2Metadata { files, compression })
}

fn unquote(s: &str) -> &str {
    let s = s.trim();
    s.strip_prefix('"')
        .and_then(|s| s.strip_suffix('"'))
        .or_else(|| s.strip_prefix('\'').and_then(|s| s.strip_suffix('\'')))
        .unwrap_or(s)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bag_dir(tag: &str, yaml: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("odocal-meta-{tag}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("metadata.yaml"), yaml).unwrap();
        std::fs::write(dir.join("a.db3"), b"x").unwrap();
        dir
    }

    fn listing(item: &str) -> String {
        format!("rosbag2_bagfile_information:\n  relative_file_paths:\n    - {item}\n")
    }

    #[test]
    fn files_outside_the_directory_are_refused() {
        for (tag, item) in [
            ("abs", "/etc/passwd"),
            ("up", "../a.db3"),
            ("deep", "x/../../a.db3"),
        ] {
            let dir = bag_dir(tag, &listing(item));
            let err = read_metadata(&dir).unwrap_err().to_string();
            assert!(err.contains("inside the bag directory"), "{item}: {err}");
            std::fs::remove_dir_all(&dir).unwrap();
        }
    }

    #[cfg(unix)]
    #[test]
    fn a_symlink_leading_outside_is_refused() {
        let dir = bag_dir("link", &listing("link.db3"));
        std::os::unix::fs::symlink("/etc/hostname", dir.join("link.db3")).unwrap();
        let err = read_metadata(&dir).unwrap_err().to_string();
        assert!(err.contains("outside the bag directory"), "{err}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn an_own_file_is_accepted_with_its_compression() {
        let yaml = format!(
            "{}  compression_format: zstd\n  compression_mode: MESSAGE\n",
            listing("a.db3")
        );
        let dir = bag_dir("ok", &yaml);
        let m = read_metadata(&dir).unwrap();
        assert_eq!(m.files, vec![dir.join("a.db3")]);
        assert_eq!(m.compression, Compression::Message);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn an_oversized_metadata_file_is_refused_without_reading_it_whole() {
        let dir = bag_dir("big", "");
        let f = std::fs::File::create(dir.join("metadata.yaml")).unwrap();
        f.set_len(4 << 30).unwrap(); // sparse: 4 GiB declared, nothing written
        let err = read_metadata(&dir).unwrap_err().to_string();
        assert!(err.contains("larger than"), "{err}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
