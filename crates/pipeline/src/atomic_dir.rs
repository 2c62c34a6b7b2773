//! Writing a directory of results as a whole: the files are written into a fresh
//! temporary directory beside the target (unpredictable name, created exclusively),
//! which is then swapped in with one rename. A reader, or a second run writing the
//! same directory at the same time, sees one run's complete set or the other's, never a
//! mix; a failed write (a full disk) leaves the old directory as it was and no
//! temporary behind. The old directory is replaced only when it holds nothing but
//! files this writer may replace ([`write_dir_atomically`]'s `replaceable`), so a
//! directory of other files (`--out .`) is refused instead of deleted.

use crate::atomic_file::{kind_of, parent_of};
use std::fs;
use std::io;
use std::path::Path;

/// An error of kind `InvalidInput` with `message`.
fn refused(message: String) -> io::Error {
    io::Error::new(io::ErrorKind::InvalidInput, message)
}

/// Fails unless `dir` does not exist, or is a directory whose entries are all regular
/// files named as `replaceable` accepts.
pub fn check_replaceable_dir(dir: &Path, replaceable: &dyn Fn(&str) -> bool) -> io::Result<()> {
    let meta = match fs::symlink_metadata(dir) {
        Ok(m) => m,
        Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(()),
        Err(e) => return Err(e),
    };
    if !meta.is_dir() {
        let what = if meta.file_type().is_symlink() {
            "a symbolic link"
        } else {
            kind_of(&meta)
        };
        return Err(refused(format!(
            "{} is {what}, not a directory: refusing to replace it (give a new or \
             results directory)",
            dir.display()
        )));
    }
    for entry in fs::read_dir(dir)? {
        let entry = entry?;
        let name = entry.file_name().to_string_lossy().into_owned();
        if !entry.file_type()?.is_file() || !replaceable(&name) {
            return Err(refused(format!(
                "{} holds {}, which odocal does not write: refusing to replace the \
                 directory (give a new or empty directory)",
                dir.display(),
                odocal_log::printable(name.as_bytes(), 80)
            )));
        }
    }
    Ok(())
}

/// Writes the directory `dir` as a whole: `fill` writes the files into the fresh
/// directory it is given, which then replaces `dir` (see the module).
pub fn write_dir_atomically(
    dir: &Path,
    replaceable: &dyn Fn(&str) -> bool,
    fill: impl FnOnce(&Path) -> io::Result<()>,
) -> io::Result<()> {
    check_replaceable_dir(dir, replaceable)?;
    let name = dir
        .file_name()
        .ok_or_else(|| refused(format!("{} names no directory", dir.display())))?;
    let parent = parent_of(dir);
    fs::create_dir_all(parent)?;
    let prefix = format!(".{}.", name.to_string_lossy());
    let mut builder = tempfile::Builder::new();
    builder.prefix(&prefix);
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        // As `create_dir` would make it (the umask applies), not the default 0700.
        builder.permissions(fs::Permissions::from_mode(0o777));
    }
    let fresh = builder.tempdir_in(parent)?;
    fill(fresh.path())?;
    // From here `fresh` names whatever must be removed: the new set before the swap,
    // the old directory after it.
    swap_in(fresh.path(), dir)?;
    fresh.close()
}

/// Moves the directory `fresh` to `dir`; an old `dir` ends up at `fresh`.
fn swap_in(fresh: &Path, dir: &Path) -> io::Result<()> {
    loop {
        match fs::symlink_metadata(dir) {
            Err(e) if e.kind() == io::ErrorKind::NotFound => match fs::rename(fresh, dir) {
                Ok(()) => return fs::create_dir(fresh),
                // Another run put its directory there in the meantime: swap with it.
                Err(e)
                    if matches!(
                        e.kind(),
                        io::ErrorKind::DirectoryNotEmpty | io::ErrorKind::AlreadyExists
                    ) =>
                {
                    continue
                }
                Err(e) => return Err(e),
            },
            Err(e) => return Err(e),
            Ok(_) => return exchange(fresh, dir),
        }
    }
}

/// Exchanges the directories `a` and `b` in one step (Linux `renameat2`).
#[cfg(target_os = "linux")]
fn exchange(a: &Path, b: &Path) -> io::Result<()> {
    use std::ffi::CString;
    use std::os::unix::ffi::OsStrExt;
    let c = |p: &Path| {
        CString::new(p.as_os_str().as_bytes())
            .map_err(|_| refused(format!("{} holds a NUL byte", p.display())))
    };
    let (ca, cb) = (c(a)?, c(b)?);
    // SAFETY: both are valid NUL-terminated paths that outlive the call.
    let rc = unsafe {
        libc::renameat2(
            libc::AT_FDCWD,
            ca.as_ptr(),
            libc::AT_FDCWD,
            cb.as_ptr(),
            libc::RENAME_EXCHANGE,
        )
    };
    if rc == 0 {
        Ok(())
    } else {
        Err(io::Error::last_os_error())
    }
}

/// Exchanges the directories `a` and `b`: `b` moved aside, `a` renamed to `b`, the old
/// `b` moved to `a` (not one step; no system call for it here).
#[cfg(not(target_os = "linux"))]
fn exchange(a: &Path, b: &Path) -> io::Result<()> {
    let aside: std::path::PathBuf = a.with_extension("old");
    fs::rename(b, &aside)?;
    fs::rename(a, b)?;
    fs::rename(&aside, a)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn results(name: &str) -> bool {
        name.starts_with("results") || name.ends_with(".svg")
    }

    fn scratch() -> tempfile::TempDir {
        tempfile::Builder::new()
            .prefix("odocal-atomic-dir-")
            .tempdir()
            .unwrap()
    }

    fn names(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> = fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    #[test]
    fn replaces_the_whole_set_or_nothing() {
        let root = scratch();
        let out = root.path().join("out");
        write_dir_atomically(&out, &results, |d| {
            fs::write(d.join("results.json"), "1")?;
            fs::write(d.join("a.svg"), "1")
        })
        .unwrap();
        assert_eq!(names(&out), ["a.svg", "results.json"]);
        // A failed second run leaves the first run's set, and no temporary.
        let e = write_dir_atomically(&out, &results, |d| {
            fs::write(d.join("results.json"), "2")?;
            Err(io::Error::other("disk full"))
        });
        assert!(e.is_err());
        assert_eq!(fs::read_to_string(out.join("results.json")).unwrap(), "1");
        assert_eq!(names(root.path()), ["out"]);
        // A successful one replaces the set: no a.svg from the first run remains.
        write_dir_atomically(&out, &results, |d| fs::write(d.join("results.json"), "3")).unwrap();
        assert_eq!(names(&out), ["results.json"]);
        assert_eq!(names(root.path()), ["out"]);
    }

    #[test]
    fn a_directory_of_other_files_is_refused() {
        let root = scratch();
        fs::write(root.path().join("notes.txt"), "mine").unwrap();
        let e = write_dir_atomically(root.path(), &results, |_| Ok(())).unwrap_err();
        assert!(e.to_string().contains("notes.txt"), "{e}");
        assert_eq!(names(root.path()), ["notes.txt"]);
    }
}
