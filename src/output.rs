//! Files written whole or not at all: every file the program writes goes to
//! a temporary file in the same folder first and takes its final name only
//! once it is complete, so an interrupted run or a failed write never
//! leaves a partial file that looks finished.

use std::io::Write;
use std::path::{Path, PathBuf};

/// A file that could not be written, and why.
#[derive(Debug, thiserror::Error)]
#[error("{}: cannot write: {}", path.display(), describe(path, source))]
pub struct OutputError {
    /// The file's final name.
    pub path: PathBuf,
    /// What the system said.
    pub source: std::io::Error,
}

impl OutputError {
    /// Why the file could not be written.
    pub fn reason(&self) -> String {
        describe(&self.path, &self.source)
    }
}

/// The system's reason, with the folder named when it is missing.
fn describe(path: &Path, e: &std::io::Error) -> String {
    if e.kind() == std::io::ErrorKind::NotFound {
        format!("the folder {} does not exist", folder(path).display())
    } else {
        e.to_string()
    }
}

/// The folder a file goes in (`.` for a bare name).
fn folder(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

/// A file being written under a temporary name beside its final one; it
/// takes the final name on [`AtomicFile::commit`] and is removed if dropped
/// before.
#[derive(Debug)]
pub struct AtomicFile {
    temp: tempfile::NamedTempFile,
    path: PathBuf,
}

impl AtomicFile {
    /// Starts writing the file that will be `path`.
    pub fn create(path: &Path) -> Result<AtomicFile, OutputError> {
        let mut builder = tempfile::Builder::new();
        builder.prefix(".screensaver-").suffix(".part");
        // Temporary files are private by default; the final file is made
        // as any new file is (read-write for all, less the umask).
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            builder.permissions(std::fs::Permissions::from_mode(0o666));
        }
        let temp = builder
            .tempfile_in(folder(path))
            .map_err(|source| OutputError {
                path: path.to_path_buf(),
                source,
            })?;
        Ok(AtomicFile {
            temp,
            path: path.to_path_buf(),
        })
    }

    /// The final name.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The error for this file.
    pub fn error(&self, source: std::io::Error) -> OutputError {
        OutputError {
            path: self.path.clone(),
            source,
        }
    }

    /// Flushes the file to disk and gives it its final name, replacing any
    /// file of that name.
    pub fn commit(mut self) -> Result<(), OutputError> {
        let path = self.path.clone();
        let fail = |source| OutputError {
            path: path.clone(),
            source,
        };
        self.temp.flush().map_err(fail)?;
        self.temp.as_file().sync_all().map_err(fail)?;
        self.temp
            .persist(&self.path)
            .map_err(|e| fail(e.error))
            .map(drop)
    }
}

impl Write for AtomicFile {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.temp.write(buf)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.temp.flush()
    }
}

/// Writes `bytes` to `path` whole or not at all.
pub fn write_file(path: &Path, bytes: &[u8]) -> Result<(), OutputError> {
    let mut file = AtomicFile::create(path)?;
    file.write_all(bytes).map_err(|e| file.error(e))?;
    file.commit()
}

/// Writes to `path` whatever `fill` writes, through a buffer, whole or not
/// at all; an error of `fill`'s is reported against `path`.
pub fn write_with(
    path: &Path,
    fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<(), OutputError> {
    let file = AtomicFile::create(path)?;
    let mut out = std::io::BufWriter::with_capacity(1 << 16, file);
    let written = fill(&mut out).and_then(|()| out.flush());
    let file = out.into_inner().map_err(|e| {
        let source = std::io::Error::new(e.error().kind(), e.error().to_string());
        OutputError {
            path: path.to_path_buf(),
            source,
        }
    })?;
    written.map_err(|e| file.error(e))?;
    file.commit()
}

/// Checks, before a long run, that `path` can be written: its folder
/// exists and takes new files. Nothing is left behind.
pub fn check_writable(path: &Path) -> Result<(), OutputError> {
    if path.is_dir() {
        return Err(OutputError {
            path: path.to_path_buf(),
            source: std::io::Error::other("it is a folder"),
        });
    }
    AtomicFile::create(path).map(drop)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_file_appears_only_when_committed() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.txt");
        let mut file = AtomicFile::create(&path).unwrap();
        file.write_all(b"half").unwrap();
        assert!(!path.exists());
        drop(file);
        assert!(!path.exists());
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
        write_file(&path, b"whole").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"whole");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn a_failed_fill_leaves_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.txt");
        let err = write_with(&path, |out| {
            out.write_all(b"part")?;
            Err(std::io::Error::other("disk gone"))
        })
        .unwrap_err();
        assert!(err.to_string().contains("out.txt: cannot write: disk gone"));
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    }

    #[test]
    fn a_missing_folder_is_named() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("nowhere/out.txt");
        let err = check_writable(&path).unwrap_err().to_string();
        assert!(err.contains("does not exist"), "{err}");
        assert!(err.contains("nowhere"), "{err}");
        let err = check_writable(dir.path()).unwrap_err().to_string();
        assert!(err.contains("is a folder"), "{err}");
    }
}
