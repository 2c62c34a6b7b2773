//! The files a run reads, by identity (device and inode), so that no output replaces
//! them: not by name, not through a symlink or a hard link, not as a file of the
//! `--out` directory that is swapped in as a whole.

use std::fs;
use std::io;
use std::path::Path;

/// Device and inode of each file (and directory) that is the input.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct InputFiles(Vec<(u64, u64)>);

/// Device and inode of `meta`.
#[cfg(unix)]
fn identity(meta: &fs::Metadata) -> Option<(u64, u64)> {
    use std::os::unix::fs::MetadataExt;
    Some((meta.dev(), meta.ino()))
}

/// No identity to compare on this platform.
#[cfg(not(unix))]
fn identity(_meta: &fs::Metadata) -> Option<(u64, u64)> {
    None
}

/// The identity of what `path` names (following symlinks), if it exists.
fn identity_of(path: &Path) -> io::Result<Option<(u64, u64)>> {
    match fs::metadata(path) {
        Ok(m) => Ok(identity(&m)),
        Err(e) if e.kind() == io::ErrorKind::NotFound => Ok(None),
        Err(e) => Err(e),
    }
}

impl InputFiles {
    /// The input at `path`: the file, or a directory (a ROS 2 bag) and the files in it.
    /// `-` is standard input (what it is redirected from, when that is a file).
    pub fn of(path: &Path) -> io::Result<InputFiles> {
        let path = if path == Path::new("-") {
            Path::new("/dev/stdin")
        } else {
            path
        };
        let mut ids = Vec::new();
        ids.extend(identity_of(path)?);
        if path.is_dir() {
            for entry in fs::read_dir(path)? {
                ids.extend(identity_of(&entry?.path())?);
            }
        }
        Ok(InputFiles(ids))
    }

    /// True when `path` exists and is one of the input's files.
    pub fn contains(&self, path: &Path) -> io::Result<bool> {
        Ok(identity_of(path)?.is_some_and(|id| self.0.contains(&id)))
    }

    /// Fails when writing the file `output` would replace the input.
    pub fn refuse_as_output_file(&self, output: &Path, input: &Path) -> io::Result<()> {
        if self.contains(output)? {
            return Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                format!(
                    "{} is the input {}: refusing to overwrite it (give another output path)",
                    output.display(),
                    input.display()
                ),
            ));
        }
        Ok(())
    }

    /// Fails when replacing the directory `output` would replace the input: it is the
    /// input, or holds one of its files.
    pub fn refuse_as_output_dir(&self, output: &Path, input: &Path) -> io::Result<()> {
        self.refuse_as_output_file(output, input)?;
        if !output.is_dir() {
            return Ok(());
        }
        for entry in fs::read_dir(output)? {
            let file = entry?.path();
            if self.contains(&file)? {
                return Err(io::Error::new(
                    io::ErrorKind::InvalidInput,
                    format!(
                        "{} holds the input {} (as {}): refusing to replace it (give another \
                         output directory)",
                        output.display(),
                        input.display(),
                        file.display()
                    ),
                ));
            }
        }
        Ok(())
    }
}

#[cfg(all(test, unix))]
mod tests {
    use super::*;

    #[test]
    fn the_input_is_known_by_any_name() {
        let root = tempfile::tempdir().unwrap();
        let log = root.path().join("run.log");
        fs::write(&log, "PARAM x 1\n").unwrap();
        let link = root.path().join("link.log");
        std::os::unix::fs::symlink(&log, &link).unwrap();
        let hard = root.path().join("hard.log");
        fs::hard_link(&log, &hard).unwrap();
        let input = InputFiles::of(&link).unwrap();
        for out in [&log, &link, &hard] {
            assert!(input.refuse_as_output_file(out, &link).is_err(), "{out:?}");
        }
        assert!(input.refuse_as_output_dir(root.path(), &link).is_err());
        let other = root.path().join("r.html");
        assert!(input.refuse_as_output_file(&other, &link).is_ok());
        fs::write(&other, "x").unwrap();
        assert!(input.refuse_as_output_file(&other, &link).is_ok());
        assert!(input
            .refuse_as_output_dir(&root.path().join("new"), &link)
            .is_ok());
    }
}
