//! Files written whole or not at all: every regular file the program writes
//! goes to a temporary file in the same folder first and takes its final
//! name only once it is complete, so an interrupted run or a failed write
//! never leaves a partial file that looks finished. A file replaced keeps
//! its mode, its owner and its group; one this user could not give back
//! its owner is refused, never silently taken over.
//!
//! What is not a regular file is written to as it is: `-` is standard
//! output; a device, a FIFO or a socket (`/dev/null`, `/dev/full`, a named
//! pipe), and any name that leads through `/proc` (`/dev/stdout`,
//! `/proc/self/fd/3`: names of files already open) are opened and written
//! directly, never replaced. A symbolic link is followed (its target is
//! written whole or not at all, and the link stays a link) unless it is
//! one the system itself would not follow: a link in a sticky folder that
//! anyone may write (`/tmp`), owned by neither this user nor the folder's
//! owner, is refused.
//!
//! Temporary files are named after the process that made them
//! (`.screensaver-PID-XXXXXX.part`) and registered while they exist, so
//! that a second signal, which ends the process at once, removes them
//! first ([`remove_temporaries`]); those a process ended by `kill -9` left
//! are removed by the next run that writes in their folder.

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
    // An error that says its own reason (a refused link, a file of another
    // user's) is passed on as it is.
    if e.get_ref().is_some() {
        return e.to_string();
    }
    let target = resolve(path).map_or_else(|_| path.to_path_buf(), |r| r.target);
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
            "the folder {} exists but does not take new files",
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

/// Whether `path` ends in a separator, and so names a folder.
fn names_a_folder(path: &Path) -> bool {
    let text = path.as_os_str().as_encoded_bytes();
    text.last()
        .is_some_and(|&c| std::path::is_separator(c as char))
        && text != b"-"
}

/// Most symbolic links followed in a row, as the system's own limit.
const MOST_LINKS: usize = 40;

/// Where a path leads once its symbolic links are followed.
struct Resolved {
    /// The file it names (`path` itself if it is not a link, or if the
    /// links go round); the target of a link to a file that does not exist
    /// yet is where that file will be made.
    target: PathBuf,
    /// Whether it led through `/proc` or `/dev/fd`: the name of a file
    /// already open (`/dev/stdout` -> `/proc/self/fd/1` -> the file).
    through_proc: bool,
}

/// Follows the links from `path`, refusing one the system would not
/// follow for this user ([`may_follow`]).
fn resolve(path: &Path) -> std::io::Result<Resolved> {
    let mut at = path.to_path_buf();
    let open_already = |at: &Path| at.starts_with("/proc") || at.starts_with("/dev/fd");
    let mut through_proc = open_already(path);
    for _ in 0..MOST_LINKS {
        let Ok(target) = std::fs::read_link(&at) else {
            return Ok(Resolved {
                target: at,
                through_proc,
            });
        };
        check_link(&at)?;
        at = folder(&at).join(target);
        through_proc |= open_already(&at);
    }
    Ok(Resolved {
        target: path.to_path_buf(),
        through_proc,
    })
}

/// Refuses the link at `link` where the system would: in a sticky folder
/// that anyone may write, a link owned by neither this user nor the
/// folder's owner (Linux's `fs.protected_symlinks`). The program follows
/// links itself to write their targets whole, so the system's own check
/// never sees them.
#[cfg(unix)]
fn check_link(link: &Path) -> std::io::Result<()> {
    use std::os::unix::fs::MetadataExt;
    let (Ok(meta), Ok(dir)) = (
        std::fs::symlink_metadata(link),
        std::fs::metadata(folder(link)),
    ) else {
        return Ok(());
    };
    let user = rustix::process::geteuid().as_raw();
    if may_follow(dir.mode(), dir.uid(), meta.uid(), user) {
        return Ok(());
    }
    Err(std::io::Error::new(
        std::io::ErrorKind::PermissionDenied,
        format!(
            "{} is a symbolic link in the shared folder {}, owned by another user \
             (uid {}); it is not followed (remove it, or name the file it points to)",
            link.display(),
            folder(link).display(),
            meta.uid()
        ),
    ))
}

#[cfg(not(unix))]
fn check_link(_: &Path) -> std::io::Result<()> {
    Ok(())
}

/// Whether `user` may follow a link owned by `link_owner` in a folder of
/// mode `dir_mode` owned by `dir_owner`: anywhere but in a sticky folder
/// that anyone may write; there, only a link of the user's own or of the
/// folder's owner.
#[cfg(unix)]
fn may_follow(dir_mode: u32, dir_owner: u32, link_owner: u32, user: u32) -> bool {
    const STICKY: u32 = 0o1000;
    const OTHERS_WRITE: u32 = 0o002;
    let shared = dir_mode & STICKY != 0 && dir_mode & OTHERS_WRITE != 0;
    !shared || link_owner == user || link_owner == dir_owner
}

/// How a path is written.
#[derive(Debug, PartialEq, Eq)]
enum Kind {
    /// Standard output (`-`).
    Stdout,
    /// Opened and written as it is: a device, a FIFO, a socket, or a name
    /// that leads through `/proc` to a file already open.
    Direct,
    /// A regular file (or a new one) at this path, links followed: written
    /// to a temporary file beside it and renamed over it when complete.
    Whole(PathBuf),
}

fn kind(path: &Path) -> std::io::Result<Kind> {
    if path.as_os_str() == "-" {
        return Ok(Kind::Stdout);
    }
    // The links first, each checked: a link another user planted to a
    // device or a FIFO is refused like any other.
    let resolved = resolve(path)?;
    if resolved.through_proc {
        return Ok(Kind::Direct);
    }
    Ok(match std::fs::metadata(&resolved.target) {
        Ok(m) if !m.is_file() && !m.is_dir() => Kind::Direct,
        _ => Kind::Whole(resolved.target),
    })
}

/// Which file a path names, so that two names of one file (`./a` and
/// `a`, a link and its target, two hard links) compare equal: for a
/// program that must not write one of its outputs over another file it
/// reads or writes.
///
/// ```
/// use screensaver::FileIdentity;
///
/// let a = FileIdentity::of("Cargo.toml".as_ref());
/// assert!(a.is_some());
/// assert_eq!(a, FileIdentity::of("./Cargo.toml".as_ref()));
/// assert_ne!(a, FileIdentity::of("README.md".as_ref()));
/// ```
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FileIdentity(Identity);

#[derive(Clone, Debug, PartialEq, Eq)]
enum Identity {
    /// A file that exists: its device and inode.
    #[cfg(unix)]
    Inode(u64, u64),
    /// A file not made yet, or on a system without inodes: its path with
    /// links followed (its folder's, for a file not made yet).
    Path(PathBuf),
}

impl FileIdentity {
    /// The file `path` names as a regular file, if it does: `None` for
    /// standard output, devices, FIFOs and sockets, which any number of
    /// outputs may share.
    pub fn of(path: &Path) -> Option<FileIdentity> {
        let Ok(Kind::Whole(target)) = kind(path) else {
            return None;
        };
        #[cfg(unix)]
        if let Ok(m) = std::fs::metadata(&target) {
            use std::os::unix::fs::MetadataExt;
            return Some(FileIdentity(Identity::Inode(m.dev(), m.ino())));
        }
        #[cfg(not(unix))]
        if let Ok(path) = std::fs::canonicalize(&target) {
            return Some(FileIdentity(Identity::Path(path)));
        }
        let folder = folder(&target);
        let folder = std::fs::canonicalize(folder).unwrap_or_else(|_| folder.to_path_buf());
        let path = folder.join(target.file_name()?);
        Some(FileIdentity(Identity::Path(path)))
    }

    /// The regular file standard output is written to, if it is one (`>
    /// file`): a run must not replace it with one of its outputs, which
    /// would lose what it prints.
    pub fn of_stdout() -> Option<FileIdentity> {
        #[cfg(unix)]
        {
            use std::os::fd::AsFd;
            use std::os::unix::fs::MetadataExt;
            let stdout = std::io::stdout();
            let file = std::fs::File::from(stdout.as_fd().try_clone_to_owned().ok()?);
            let m = file.metadata().ok().filter(std::fs::Metadata::is_file)?;
            Some(FileIdentity(Identity::Inode(m.dev(), m.ino())))
        }
        #[cfg(not(unix))]
        None
    }
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

/// How the program's temporary files are named: the prefix, the making
/// process's id and a dash, random letters, the suffix.
const TEMPORARY_PREFIX: &str = ".screensaver-";
const TEMPORARY_SUFFIX: &str = ".part";

/// Gives the new file `temp` the mode, owner and group of the file `old` it
/// will replace, so that replacing a file never changes who may read it;
/// fails where this user cannot give it the owner back.
#[cfg(unix)]
fn adopt(temp: &std::fs::File, old: &std::fs::Metadata) -> std::io::Result<()> {
    use std::os::unix::fs::MetadataExt;
    let new = temp.metadata()?;
    if (new.uid(), new.gid()) != (old.uid(), old.gid()) {
        std::os::unix::fs::fchown(temp, Some(old.uid()), Some(old.gid())).map_err(|_| {
            std::io::Error::new(
                std::io::ErrorKind::PermissionDenied,
                format!(
                    "it belongs to another user or group (uid {}, gid {}), and replacing it \
                     would make it this user's; remove it first, or write elsewhere",
                    old.uid(),
                    old.gid()
                ),
            )
        })?;
    }
    temp.set_permissions(old.permissions())
}

#[cfg(not(unix))]
fn adopt(temp: &std::fs::File, old: &std::fs::Metadata) -> std::io::Result<()> {
    temp.set_permissions(old.permissions())
}

/// The id of this process (0 where there are none: WebAssembly).
fn process_id() -> u32 {
    match cfg!(all(target_arch = "wasm32", target_os = "unknown")) {
        true => 0,
        false => std::process::id(),
    }
}

/// How long a temporary file of a process that no longer runs is left
/// alone: a process of this user elsewhere (another host sharing the
/// folder, another process namespace) that is writing it keeps it newer.
#[cfg(target_os = "linux")]
const STALE_AFTER: std::time::Duration = std::time::Duration::from_secs(600);

/// Removes, once per folder and process, the temporary files that a
/// process of this program ended at once (`kill -9`, a crash) left in
/// `dir`: those of this user whose process no longer runs and that have
/// not changed for [`STALE_AFTER`]. Where the system cannot say which
/// processes run (no `/proc`), nothing is removed.
#[cfg(target_os = "linux")]
fn remove_stale_temporaries(dir: &Path) {
    use std::os::unix::fs::MetadataExt;
    /// The folders already cleared of stale temporary files.
    static SWEPT: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());
    if !Path::new("/proc/self").exists() {
        return;
    }
    let mut swept = SWEPT.lock().unwrap_or_else(|e| e.into_inner());
    let key = std::fs::canonicalize(dir).unwrap_or_else(|_| dir.to_path_buf());
    if swept.contains(&key) {
        return;
    }
    swept.push(key);
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    let user = rustix::process::geteuid().as_raw();
    for entry in entries.flatten() {
        let name = entry.file_name();
        let Some(pid) = name.to_str().and_then(temporary_pid) else {
            continue;
        };
        let old = |m: &std::fs::Metadata| {
            let age = m.modified().ok().and_then(|t| t.elapsed().ok());
            age.is_some_and(|age| age >= STALE_AFTER)
        };
        let ours = entry
            .metadata()
            .is_ok_and(|m| m.is_file() && m.uid() == user && old(&m));
        if ours && !Path::new("/proc").join(pid.to_string()).exists() {
            let _ = std::fs::remove_file(entry.path());
        }
    }
}

/// Elsewhere the system cannot say which processes run: nothing is
/// removed.
#[cfg(not(target_os = "linux"))]
fn remove_stale_temporaries(_: &Path) {}

/// The id of the process that made the temporary file named `name`, if it
/// is one of this program's.
#[cfg(any(test, target_os = "linux"))]
fn temporary_pid(name: &str) -> Option<u32> {
    let rest = name.strip_prefix(TEMPORARY_PREFIX)?;
    rest.strip_suffix(TEMPORARY_SUFFIX)?;
    let (pid, _) = rest.split_once('-')?;
    pid.parse().ok()
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
        if names_a_folder(path) {
            return Err(fail(std::io::Error::other(
                "a file's name cannot end in a separator (that names a folder)",
            )));
        }
        let (sink, target) = match kind(path).map_err(fail)? {
            Kind::Stdout => (Sink::Stdout(std::io::stdout()), path.to_path_buf()),
            Kind::Direct => {
                let file = std::fs::OpenOptions::new()
                    .write(true)
                    .open(path)
                    .map_err(fail)?;
                (Sink::File(file), path.to_path_buf())
            }
            Kind::Whole(target) => {
                remove_stale_temporaries(folder(&target));
                let mut builder = tempfile::Builder::new();
                let prefix = format!("{TEMPORARY_PREFIX}{}-", process_id());
                builder.prefix(&prefix).suffix(TEMPORARY_SUFFIX);
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
                // Listed only once it is to be kept (a file that cannot
                // take the old one's owner is removed as it drops).
                if let Ok(old) = std::fs::metadata(&target) {
                    adopt(temp.as_file(), &old).map_err(fail)?;
                }
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

/// Checks, before a long run, that `path` can be written: a regular file's
/// folder exists and takes new files; anything else opens for writing (a
/// FIFO is not opened: that would wait for a reader). Nothing is left
/// behind.
pub fn check_writable(path: &Path) -> Result<(), OutputError> {
    if is_fifo(path) && !names_a_folder(path) {
        return Ok(());
    }
    OutputFile::create(path).map(drop)
}

#[cfg(unix)]
fn is_fifo(path: &Path) -> bool {
    use std::os::unix::fs::FileTypeExt;
    std::fs::metadata(path).is_ok_and(|m| m.file_type().is_fifo())
}

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
        let id = |name: &str| FileIdentity::of(&dir.path().join(name));
        assert!(id("a").is_some());
        for other in ["./a", "link", "hard", "sub/../a"] {
            assert_eq!(id(other), id("a"), "{other}");
        }
        assert_eq!(id("new"), id("sub/../new"));
        assert_ne!(id("new"), id("a"));
        assert_ne!(id("new"), id("other"));
        assert_eq!(FileIdentity::of(Path::new("/dev/null")), None);
        assert_eq!(FileIdentity::of(Path::new("-")), None);
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

    /// Whether this process runs as root, which alone can make a file
    /// another user's (the tests of other users' links and files).
    #[cfg(unix)]
    fn root() -> bool {
        let root = rustix::process::geteuid().is_root();
        // CI runs as root; a developer's run as another user cannot make
        // another user's link, and says so rather than pass.
        assert!(
            root || std::env::var_os("CI").is_none(),
            "CI runs these tests as root"
        );
        root
    }

    /// The rule on links: anywhere but a sticky folder anyone may write, any
    /// link; there, only the user's own or the folder owner's.
    #[cfg(unix)]
    #[test]
    fn links_in_shared_folders_are_followed_as_the_system_would() {
        let (user, other, dir_owner) = (1000, 1001, 0);
        assert!(may_follow(0o40755, dir_owner, other, user));
        assert!(may_follow(0o40777, dir_owner, other, user), "not sticky");
        assert!(may_follow(0o41755, dir_owner, other, user), "not shared");
        assert!(!may_follow(0o41777, dir_owner, other, user), "/tmp");
        assert!(may_follow(0o41777, dir_owner, user, user));
        assert!(may_follow(0o41777, dir_owner, dir_owner, user));
    }

    /// A link another user planted in a sticky folder anyone may write is
    /// refused by name, and its target is left as it was; the same link of
    /// the user's own is followed.
    #[cfg(unix)]
    #[test]
    fn another_users_link_in_a_shared_folder_is_refused() {
        use std::os::unix::fs::PermissionsExt;
        if !root() {
            return;
        }
        let dir = tempfile::tempdir().unwrap();
        let shared = dir.path().join("tmp");
        std::fs::create_dir(&shared).unwrap();
        std::fs::set_permissions(&shared, std::fs::Permissions::from_mode(0o1777)).unwrap();
        let victim = dir.path().join("victim");
        std::fs::write(&victim, b"precious").unwrap();
        std::fs::set_permissions(&victim, std::fs::Permissions::from_mode(0o600)).unwrap();
        let link = shared.join("out.state");
        std::os::unix::fs::symlink(&victim, &link).unwrap();
        std::os::unix::fs::lchown(&link, Some(65534), Some(65534)).unwrap();
        let err = write_file(&link, b"rows").unwrap_err().to_string();
        assert!(
            err.contains("is a symbolic link in the shared folder"),
            "{err}"
        );
        assert!(err.contains("owned by another user (uid 65534)"), "{err}");
        assert!(check_writable(&link).is_err());
        assert_eq!(std::fs::read(&victim).unwrap(), b"precious");
        // A dangling one makes nothing either.
        let dangling = shared.join("later");
        std::os::unix::fs::symlink(dir.path().join("made"), &dangling).unwrap();
        std::os::unix::fs::lchown(&dangling, Some(65534), Some(65534)).unwrap();
        assert!(write_file(&dangling, b"rows").is_err());
        assert!(!dir.path().join("made").exists());
        // The user's own link is followed.
        std::os::unix::fs::lchown(&link, Some(0), Some(0)).unwrap();
        write_file(&link, b"rows").unwrap();
        assert_eq!(std::fs::read(&victim).unwrap(), b"rows");
    }

    /// A file replaced keeps its mode, owner and group.
    #[cfg(unix)]
    #[test]
    fn a_replaced_file_keeps_its_mode_and_owner() {
        use std::os::unix::fs::{MetadataExt, PermissionsExt};
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("kept");
        std::fs::write(&path, b"old").unwrap();
        std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o640)).unwrap();
        let owner = if root() {
            65534
        } else {
            std::fs::metadata(&path).unwrap().uid()
        };
        if root() {
            std::os::unix::fs::chown(&path, Some(owner), Some(owner)).unwrap();
        }
        write_file(&path, b"new").unwrap();
        let m = std::fs::metadata(&path).unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"new");
        assert_eq!(m.mode() & 0o7777, 0o640);
        assert_eq!(m.uid(), owner);
    }

    /// A regular file under `/dev` (a tmpfs such as `/dev/shm`) is replaced
    /// whole like any other, never written over in place; a name that
    /// leads through `/proc` is written where it leads.
    #[cfg(target_os = "linux")]
    #[test]
    fn a_regular_file_under_dev_is_replaced_whole() {
        let Ok(dir) = tempfile::tempdir_in("/dev/shm") else {
            panic!("/dev/shm takes new files on Linux");
        };
        let path = dir.path().join("x");
        std::fs::write(&path, b"a much longer old text").unwrap();
        write_file(&path, b"new").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"new");
        let new = dir.path().join("y");
        write_file(&new, b"made").unwrap();
        assert_eq!(std::fs::read(&new).unwrap(), b"made");
        assert_eq!(kind(Path::new("/dev/stdout")).unwrap(), Kind::Direct);
        assert_eq!(kind(Path::new("/proc/self/fd/1")).unwrap(), Kind::Direct);
        assert_eq!(kind(Path::new("/dev/fd/1")).unwrap(), Kind::Direct);
    }

    /// A name that ends in a separator names a folder, and is refused
    /// before anything is written, whether or not the folder exists.
    #[test]
    fn a_name_ending_in_a_separator_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("newdir/");
        let err = check_writable(&path).unwrap_err().to_string();
        assert!(err.contains("cannot end in a separator"), "{err}");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
        assert!(!names_a_folder(Path::new("-")));
        assert!(!names_a_folder(Path::new("a/b")));
    }

    /// The temporary files a killed process left are removed by the next
    /// run that writes in their folder; a running process's are kept, and
    /// so are files that only look alike.
    #[cfg(target_os = "linux")]
    #[test]
    fn stale_temporaries_are_removed() {
        let dir = tempfile::tempdir().unwrap();
        // No process has an id this large (the system's most is 2^22).
        let dead = dir.path().join(".screensaver-999999999-abcdef.part");
        let alive = dir
            .path()
            .join(format!(".screensaver-{}-abcdef.part", std::process::id()));
        let other = dir.path().join(".screensaver-notes.part");
        let recent = dir.path().join(".screensaver-999999998-abcdef.part");
        let long_ago = std::time::SystemTime::now() - STALE_AFTER * 2;
        for path in [&dead, &alive, &other, &recent] {
            std::fs::write(path, b"x").unwrap();
            if path != &recent {
                let file = std::fs::File::options().write(true).open(path).unwrap();
                file.set_modified(long_ago).unwrap();
            }
        }
        write_file(&dir.path().join("out"), b"rows").unwrap();
        assert!(!dead.exists());
        assert!(
            recent.exists(),
            "changed lately: perhaps a process elsewhere"
        );
        assert!(alive.exists());
        assert!(other.exists());
        assert_eq!(temporary_pid(".screensaver-12-abc.part"), Some(12));
        assert_eq!(temporary_pid(".screensaver-12-abc"), None);
        assert_eq!(temporary_pid(".screensaver-x-abc.part"), None);
    }
}
