//! Files written whole or not at all: every regular file the program writes
//! goes to a temporary file in the same folder first and takes its final
//! name only once it is complete, so an interrupted run or a failed write
//! never leaves a partial file that looks finished.
//!
//! What is not a regular file is written to as it is: `-` is standard
//! output; a device, a FIFO or a socket (`/dev/null`, `/dev/full`, a named
//! pipe), and any path under `/dev` or `/proc` (`/dev/stdout`,
//! `/proc/self/fd/3`: names of files already open) are opened and written
//! directly, never replaced. A symbolic link is followed: its target is
//! written whole or not at all, and the link stays a link.
//!
//! Temporary files are registered while they exist, so that a second
//! signal, which ends the process at once, removes them first
//! ([`remove_temporaries`]).

use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard};

/// A file that could not be written, and why.
#[derive(Debug, thiserror::Error)]
#[error("{}: cannot write: {}", path.display(), describe(path, source))]
pub struct OutputError {
    /// The file's name as given.
    pub path: PathBuf,
    /// What the system said.
    pub source: std::io::Error,
}

impl OutputError {
    /// Why the file could not be written.
    pub fn reason(&self) -> String {
        describe(&self.path, &self.source)
    }

    fn new(path: &Path, source: std::io::Error) -> OutputError {
        OutputError {
            path: path.to_path_buf(),
            source,
        }
    }
}

/// The system's reason, with the folder named when it is missing, or when
/// it exists but refuses new files (as `/proc` does, with "not found").
fn describe(path: &Path, e: &std::io::Error) -> String {
    let target = resolve(path);
    if e.kind() == std::io::ErrorKind::PermissionDenied && !target.exists() {
        return format!(
            "this user may not make files in the folder {} (permission denied)",
            folder(&target).display()
        );
    }
    if e.kind() != std::io::ErrorKind::NotFound {
        return e.to_string();
    }
    let folder = folder(&target);
    if folder.is_dir() {
        format!(
            "the folder {} exists but does not take new files ({e})",
            folder.display()
        )
    } else {
        format!("the folder {} does not exist", folder.display())
    }
}

/// The folder a file goes in (`.` for a bare name).
fn folder(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

/// Most symbolic links followed in a row, as the system's own limit.
const MOST_LINKS: usize = 40;

/// The file `path` names once symbolic links are followed (`path` itself
/// if it is not a link, or if the links go round); the target of a link
/// to a file that does not exist yet is where that file will be made.
fn resolve(path: &Path) -> PathBuf {
    let mut at = path.to_path_buf();
    for _ in 0..MOST_LINKS {
        match std::fs::read_link(&at) {
            Ok(target) => at = folder(&at).join(target),
            Err(_) => return at,
        }
    }
    path.to_path_buf()
}

/// How a path is written.
#[derive(Debug, PartialEq, Eq)]
enum Kind {
    /// Standard output (`-`).
    Stdout,
    /// Opened and written as it is: a device, a FIFO, a socket, or a name
    /// under `/dev` or `/proc` for a file already open.
    Direct,
    /// A regular file (or a new one) at this path, links followed: written
    /// to a temporary file beside it and renamed over it when complete.
    Whole(PathBuf),
}

fn kind(path: &Path) -> Kind {
    if path.as_os_str() == "-" {
        return Kind::Stdout;
    }
    if path.starts_with("/dev") || path.starts_with("/proc") {
        return Kind::Direct;
    }
    match std::fs::metadata(path) {
        Ok(m) if !m.is_file() && !m.is_dir() => Kind::Direct,
        _ => Kind::Whole(resolve(path)),
    }
}

/// Which file a path names, so that two names of one file (`./a` and
/// `a`, a link and its target, two hard links) compare equal.
#[cfg(any(test, feature = "window"))]
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) enum FileIdentity {
    /// A file that exists: its device and inode.
    #[cfg(unix)]
    Inode(u64, u64),
    /// A file not made yet, or on a system without inodes: its path with
    /// links followed (its folder's, for a file not made yet).
    Path(PathBuf),
}

/// The file `path` names as a regular file, if it does: `None` for
/// standard output, devices, FIFOs and sockets, which any number of
/// outputs may share.
#[cfg(any(test, feature = "window"))]
pub(crate) fn identity(path: &Path) -> Option<FileIdentity> {
    let Kind::Whole(target) = kind(path) else {
        return None;
    };
    #[cfg(unix)]
    if let Ok(m) = std::fs::metadata(&target) {
        use std::os::unix::fs::MetadataExt;
        return Some(FileIdentity::Inode(m.dev(), m.ino()));
    }
    #[cfg(not(unix))]
    if let Ok(path) = std::fs::canonicalize(&target) {
        return Some(FileIdentity::Path(path));
    }
    let folder = folder(&target);
    let folder = std::fs::canonicalize(folder).unwrap_or_else(|_| folder.to_path_buf());
    Some(FileIdentity::Path(folder.join(target.file_name()?)))
}

/// The temporary files that exist now, removed by [`remove_temporaries`].
static TEMPORARIES: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

fn temporaries() -> MutexGuard<'static, Vec<PathBuf>> {
    // A panic while the list was held leaves it whole: keep using it.
    TEMPORARIES.lock().unwrap_or_else(|e| e.into_inner())
}

#[cfg(feature = "signals")]
/// Removes every temporary file that exists now and keeps any more from
/// being made or renamed into place: for a process about to end at once
/// (a second signal). Does not return the lock, so call it only on the way
/// out.
pub fn remove_temporaries() {
    let list = temporaries();
    for path in list.iter() {
        let _ = std::fs::remove_file(path);
    }
    std::mem::forget(list);
}

/// Where an [`OutputFile`]'s bytes go.
enum Sink {
    Temporary(tempfile::NamedTempFile),
    File(std::fs::File),
    Stdout(std::io::Stdout),
}

/// A file being written: a regular file under a temporary name beside its
/// final one, which takes the final name on [`OutputFile::commit`] and is
/// removed if dropped before; or standard output, a device or a FIFO,
/// written as it goes.
pub struct OutputFile {
    sink: Sink,
    /// The name as given.
    path: PathBuf,
    /// The final name of a regular file (links followed).
    target: PathBuf,
}

impl std::fmt::Debug for OutputFile {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "OutputFile({})", self.path.display())
    }
}

impl OutputFile {
    /// Starts writing the file `path` names.
    pub fn create(path: &Path) -> Result<OutputFile, OutputError> {
        let fail = |source| OutputError::new(path, source);
        if path.is_dir() {
            return Err(fail(std::io::Error::other("it is a folder")));
        }
        let (sink, target) = match kind(path) {
            Kind::Stdout => (Sink::Stdout(std::io::stdout()), path.to_path_buf()),
            Kind::Direct => {
                let file = std::fs::OpenOptions::new()
                    .write(true)
                    .open(path)
                    .map_err(fail)?;
                (Sink::File(file), path.to_path_buf())
            }
            Kind::Whole(target) => {
                let mut builder = tempfile::Builder::new();
                builder.prefix(".screensaver-").suffix(".part");
                // Temporary files are private by default; the final file is
                // made as any new file is (read-write for all, less the
                // umask).
                #[cfg(unix)]
                {
                    use std::os::unix::fs::PermissionsExt;
                    builder.permissions(std::fs::Permissions::from_mode(0o666));
                }
                let mut list = temporaries();
                // The system's reason alone: the temporary file's name,
                // which tempfile adds, means nothing to the user.
                let temp = (builder.tempfile_in(folder(&target)))
                    .map_err(|e| fail(std::io::Error::from(e.kind())))?;
                list.push(temp.path().to_path_buf());
                (Sink::Temporary(temp), target)
            }
        };
        Ok(OutputFile {
            sink,
            path: path.to_path_buf(),
            target,
        })
    }

    /// The error for this file.
    pub fn error(&self, source: std::io::Error) -> OutputError {
        OutputError::new(&self.path, source)
    }

    /// Finishes the file: a regular file is flushed to disk and given its
    /// final name, replacing any file of that name; anything else is
    /// flushed.
    pub fn commit(mut self) -> Result<(), OutputError> {
        let path = self.path.clone();
        let fail = |source| OutputError::new(&path, source);
        self.flush().map_err(fail)?;
        let sink = std::mem::replace(&mut self.sink, Sink::Stdout(std::io::stdout()));
        let Sink::Temporary(temp) = sink else {
            return Ok(());
        };
        temp.as_file().sync_all().map_err(fail)?;
        let mut list = temporaries();
        let name = temp.path().to_path_buf();
        list.retain(|p| *p != name);
        temp.persist(&self.target).map_err(|e| fail(e.error))?;
        Ok(())
    }
}

impl Drop for OutputFile {
    fn drop(&mut self) {
        if let Sink::Temporary(temp) = &self.sink {
            let name = temp.path().to_path_buf();
            // The file itself is removed as the sink drops.
            temporaries().retain(|p| *p != name);
        }
    }
}

impl Write for OutputFile {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        match &mut self.sink {
            Sink::Temporary(t) => t.write(buf),
            Sink::File(f) => f.write(buf),
            Sink::Stdout(s) => s.write(buf),
        }
    }

    fn flush(&mut self) -> std::io::Result<()> {
        match &mut self.sink {
            Sink::Temporary(t) => t.flush(),
            Sink::File(f) => f.flush(),
            Sink::Stdout(s) => s.flush(),
        }
    }
}

#[cfg(any(test, feature = "render"))]
/// Writes `bytes` to `path`, a regular file whole or not at all.
pub fn write_file(path: &Path, bytes: &[u8]) -> Result<(), OutputError> {
    let mut file = OutputFile::create(path)?;
    file.write_all(bytes).map_err(|e| file.error(e))?;
    file.commit()
}

/// Writes to `path` whatever `fill` writes, through a buffer, a regular
/// file whole or not at all; an error of `fill`'s is reported against
/// `path`.
pub fn write_with(
    path: &Path,
    fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<(), OutputError> {
    let file = OutputFile::create(path)?;
    let mut out = std::io::BufWriter::with_capacity(1 << 16, file);
    let written = fill(&mut out).and_then(|()| out.flush());
    let file = out.into_inner().map_err(|e| {
        let source = std::io::Error::new(e.error().kind(), e.error().to_string());
        OutputError::new(path, source)
    })?;
    written.map_err(|e| file.error(e))?;
    file.commit()
}

#[cfg(any(test, feature = "window"))]
/// Checks, before a long run, that `path` can be written: a regular file's
/// folder exists and takes new files; anything else opens for writing (a
/// FIFO is not opened: that would wait for a reader). Nothing is left
/// behind.
pub fn check_writable(path: &Path) -> Result<(), OutputError> {
    if is_fifo(path) {
        return Ok(());
    }
    OutputFile::create(path).map(drop)
}

#[cfg(any(test, feature = "window"))]
#[cfg(unix)]
fn is_fifo(path: &Path) -> bool {
    use std::os::unix::fs::FileTypeExt;
    std::fs::metadata(path).is_ok_and(|m| m.file_type().is_fifo())
}

#[cfg(any(test, feature = "window"))]
#[cfg(not(unix))]
fn is_fifo(_: &Path) -> bool {
    false
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two names of one file are one identity: `./a` and `a`, a link and
    /// its target, two hard links, a file not made yet by either name of
    /// its folder; other files and devices are not.
    #[cfg(unix)]
    #[test]
    fn names_of_one_file_are_one_identity() {
        let dir = tempfile::tempdir().unwrap();
        let a = dir.path().join("a");
        std::fs::write(&a, b"x").unwrap();
        std::os::unix::fs::symlink(&a, dir.path().join("link")).unwrap();
        std::fs::hard_link(&a, dir.path().join("hard")).unwrap();
        std::fs::create_dir(dir.path().join("sub")).unwrap();
        let id = |name: &str| identity(&dir.path().join(name));
        assert!(id("a").is_some());
        for other in ["./a", "link", "hard", "sub/../a"] {
            assert_eq!(id(other), id("a"), "{other}");
        }
        assert_eq!(id("new"), id("sub/../new"));
        assert_ne!(id("new"), id("a"));
        assert_ne!(id("new"), id("other"));
        assert_eq!(identity(Path::new("/dev/null")), None);
        assert_eq!(identity(Path::new("-")), None);
    }

    /// A folder that refuses new files is named, never the temporary file
    /// that was refused (which tempfile names in its own error).
    #[test]
    fn a_refused_file_names_its_folder() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.state");
        let denied = OutputError::new(&path, std::io::ErrorKind::PermissionDenied.into());
        let text = denied.to_string();
        assert_eq!(
            text,
            format!(
                "{}: cannot write: this user may not make files in the folder {} (permission denied)",
                path.display(),
                dir.path().display()
            )
        );
        assert!(!text.contains(".part"), "{text}");
    }

    #[test]
    fn a_file_appears_only_when_committed() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.txt");
        let mut file = OutputFile::create(&path).unwrap();
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

    #[cfg(target_os = "linux")]
    #[test]
    fn a_folder_that_refuses_files_is_not_called_missing() {
        let err = check_writable(Path::new("/proc/x.ckpt"))
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("the folder /proc exists but does not take new files"),
            "{err}"
        );
    }

    #[cfg(unix)]
    #[test]
    fn a_link_is_followed_and_stays_a_link() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("target.txt");
        let link = dir.path().join("link");
        std::fs::write(&target, b"old").unwrap();
        std::os::unix::fs::symlink("target.txt", &link).unwrap();
        write_file(&link, b"new").unwrap();
        assert!(std::fs::symlink_metadata(&link)
            .unwrap()
            .file_type()
            .is_symlink());
        assert_eq!(std::fs::read(&target).unwrap(), b"new");
        // A link to a file not made yet makes it.
        let dangling = dir.path().join("later");
        std::os::unix::fs::symlink("made.txt", &dangling).unwrap();
        write_file(&dangling, b"made").unwrap();
        assert_eq!(std::fs::read(dir.path().join("made.txt")).unwrap(), b"made");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 4);
    }

    #[cfg(unix)]
    #[test]
    fn devices_are_written_to_not_replaced() {
        use std::os::unix::fs::FileTypeExt;
        write_file(Path::new("/dev/null"), b"gone").unwrap();
        let null = std::fs::metadata("/dev/null").unwrap();
        assert!(null.file_type().is_char_device());
        let err = write_file(Path::new("/dev/full"), b"too much")
            .unwrap_err()
            .to_string();
        assert!(err.starts_with("/dev/full: cannot write: "), "{err}");
        assert!(std::fs::metadata("/dev/full")
            .unwrap()
            .file_type()
            .is_char_device());
    }

    #[cfg(unix)]
    #[test]
    fn a_fifo_is_written_to_not_replaced() {
        use std::os::unix::fs::FileTypeExt;
        let dir = tempfile::tempdir().unwrap();
        let fifo = dir.path().join("pipe");
        let made = std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .expect("mkfifo runs");
        assert!(made.success());
        check_writable(&fifo).unwrap();
        let reader = {
            let fifo = fifo.clone();
            std::thread::spawn(move || std::fs::read(fifo).unwrap())
        };
        write_file(&fifo, b"through").unwrap();
        assert_eq!(reader.join().unwrap(), b"through");
        assert!(std::fs::metadata(&fifo).unwrap().file_type().is_fifo());
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn temporaries_are_listed_while_they_exist() {
        let dir = tempfile::tempdir().unwrap();
        let listed = |dir: &Path| temporaries().iter().filter(|p| p.starts_with(dir)).count();
        let file = OutputFile::create(&dir.path().join("a")).unwrap();
        let other = OutputFile::create(&dir.path().join("b")).unwrap();
        assert_eq!(listed(dir.path()), 2);
        drop(file);
        assert_eq!(listed(dir.path()), 1);
        other.commit().unwrap();
        assert_eq!(listed(dir.path()), 0);
    }
}
