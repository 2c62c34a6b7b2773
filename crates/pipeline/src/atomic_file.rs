//! Writing a file so that it is either the old file or the whole new one, and so that
//! nothing but that file is ever replaced: the bytes go to a temporary file with an
//! unpredictable name, created exclusively beside the target (`O_CREAT | O_EXCL`, so
//! a planted symlink is never followed), which is then renamed over the target. The
//! target must be a regular file or not exist: a device (`/dev/null`, `/dev/full`), a
//! FIFO or a directory is refused. An interrupted or failed write (a full disk) leaves
//! the old file and no temporary behind.

use std::fs::{self, File, Permissions};
use std::io::{self, BufWriter, Write};
use std::path::Path;

/// Mode asked of new files (then reduced by the umask, as `File::create` does).
#[cfg(unix)]
fn new_file_permissions() -> Permissions {
    use std::os::unix::fs::PermissionsExt;
    Permissions::from_mode(0o666)
}

/// The directory `path` is in (`.` for a bare name).
pub(crate) fn parent_of(path: &Path) -> &Path {
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    }
}

/// What kind of thing `meta` describes, for an error message.
pub(crate) fn kind_of(meta: &fs::Metadata) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        let t = meta.file_type();
        if t.is_char_device() || t.is_block_device() {
            return "a device";
        }
        if t.is_fifo() {
            return "a FIFO (named pipe)";
        }
        if t.is_socket() {
            return "a socket";
        }
    }
    if meta.is_dir() {
        "a directory"
    } else if meta.is_file() {
        "a regular file"
    } else {
        "not a regular file"
    }
}

/// Fails unless `path` does not exist or is (or links to) a regular file.
pub fn check_replaceable_file(path: &Path) -> io::Result<()> {
    let meta = match fs::metadata(path) {
        Ok(m) => m,
        // Nothing there, or a dangling symlink (the rename replaces the link only).
        Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(()),
        Err(e) => return Err(e),
    };
    if meta.is_file() {
        return Ok(());
    }
    Err(io::Error::new(
        io::ErrorKind::InvalidInput,
        format!(
            "{} is {}, not a regular file: refusing to replace it (give the path of a new \
             or regular file)",
            path.display(),
            kind_of(&meta)
        ),
    ))
}

/// Writes `path` through `fill`, atomically (exclusive temporary file, flush, sync,
/// rename); refuses a target that is not a regular file (see the module).
pub fn write_atomically(
    path: &Path,
    fill: impl FnOnce(&mut BufWriter<File>) -> io::Result<()>,
) -> io::Result<()> {
    check_replaceable_file(path)?;
    let name = path.file_name().ok_or_else(|| {
        io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("{} names no file", path.display()),
        )
    })?;
    let prefix = format!(".{}.", name.to_string_lossy());
    let mut builder = tempfile::Builder::new();
    builder.prefix(&prefix).suffix(".tmp");
    #[cfg(unix)]
    builder.permissions(new_file_permissions());
    // The temporary is removed when `tmp_path` is dropped on any error below.
    let (file, tmp_path) = builder.tempfile_in(parent_of(path))?.into_parts();
    let mut w = BufWriter::new(file);
    fill(&mut w)?;
    let file = w.into_inner().map_err(|e| e.into_error())?;
    file.sync_all()?;
    drop(file);
    tmp_path.persist(path).map_err(|e| e.error)
}

/// Writes `bytes` to `path` atomically.
pub fn write_bytes_atomically(path: &Path, bytes: &[u8]) -> io::Result<()> {
    write_atomically(path, |w| w.write_all(bytes))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A fresh empty directory for one test.
    fn scratch(tag: &str) -> tempfile::TempDir {
        tempfile::Builder::new()
            .prefix(&format!("odocal-atomic-{tag}-"))
            .tempdir()
            .unwrap()
    }

    /// The names in `dir`, sorted.
    fn names(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> = fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    #[test]
    fn replaces_whole_or_not_at_all() {
        let dir = scratch("whole");
        let p = dir.path().join("r.json");
        write_bytes_atomically(&p, b"old").unwrap();
        let e = write_atomically(&p, |w| {
            w.write_all(b"half")?;
            Err(io::Error::other("disk full"))
        });
        assert!(e.is_err());
        assert_eq!(fs::read(&p).unwrap(), b"old");
        assert_eq!(names(dir.path()), ["r.json"], "no temporary left behind");
        write_bytes_atomically(&p, b"new").unwrap();
        assert_eq!(fs::read(&p).unwrap(), b"new");
    }

    #[cfg(unix)]
    #[test]
    fn a_planted_symlink_is_not_followed() {
        let dir = scratch("symlink");
        let victim = dir.path().join("victim");
        fs::write(&victim, b"precious").unwrap();
        // The name the old writer used, and a few others: none is used now.
        for name in [".r.html.tmp", ".r.html.", ".r.html..tmp"] {
            std::os::unix::fs::symlink(&victim, dir.path().join(name)).unwrap();
        }
        write_bytes_atomically(&dir.path().join("r.html"), b"report").unwrap();
        assert_eq!(fs::read(&victim).unwrap(), b"precious");
        assert_eq!(fs::read(dir.path().join("r.html")).unwrap(), b"report");
    }

    #[cfg(unix)]
    #[test]
    fn devices_and_directories_are_refused() {
        let dir = scratch("kinds");
        for target in [Path::new("/dev/null"), dir.path()] {
            let e = write_bytes_atomically(target, b"x").unwrap_err();
            assert_eq!(e.kind(), io::ErrorKind::InvalidInput, "{e}");
            assert!(e.to_string().contains("refusing"), "{e}");
        }
        assert!(names(dir.path()).is_empty());
    }

    #[cfg(unix)]
    #[test]
    fn new_files_get_the_umask_mode_not_0600() {
        use std::os::unix::fs::PermissionsExt;
        let dir = scratch("mode");
        let p = dir.path().join("r.json");
        write_bytes_atomically(&p, b"x").unwrap();
        let via_create = dir.path().join("c");
        File::create(&via_create).unwrap();
        let mode = |p: &Path| fs::metadata(p).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode(&p), mode(&via_create));
    }
}
